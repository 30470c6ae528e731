# Copies the report's plotly.js (core/web/node_modules, installed by scripts/install-deps.sh
# with `npm ci`) into the assembled package as aolab/study/vendor/plotly-basic.min.js, where
# aolab/study/report_files.py finds it; removes a stale copy when it is not installed (the
# report then says so and draws static plots). Run by CMakeLists.txt on every build:
#   cmake -DSOURCE=<core/web/node_modules/.../plotly-basic.min.js> -DDEST_DIR=<dir> -P this
if(EXISTS "${SOURCE}")
  file(MAKE_DIRECTORY "${DEST_DIR}")
  file(COPY_FILE "${SOURCE}" "${DEST_DIR}/plotly-basic.min.js" ONLY_IF_DIFFERENT)
else()
  file(REMOVE "${DEST_DIR}/plotly-basic.min.js")
endif()
