# Copies the report's plotly.js (core/web/vendor/plotly-basic.min.js, committed; see
# scripts/update_plotly.sh) into the assembled package as aolab/study/vendor/plotly-basic.min.js,
# where aolab/study/report_files.py finds it; removes a stale copy when the source is missing
# (the report then says so and draws static plots). Run by CMakeLists.txt on every build:
#   cmake -DSOURCE=<core/web/vendor/plotly-basic.min.js> -DDEST_DIR=<dir> -P this
if(EXISTS "${SOURCE}")
  file(MAKE_DIRECTORY "${DEST_DIR}")
  file(COPY_FILE "${SOURCE}" "${DEST_DIR}/plotly-basic.min.js" ONLY_IF_DIFFERENT)
else()
  file(REMOVE "${DEST_DIR}/plotly-basic.min.js")
endif()
