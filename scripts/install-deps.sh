#!/usr/bin/env bash
# Installs the Debian packages AO Lab needs (no PyPI), only those that are missing. (The
# comparison report's plotly.js is committed in core/web/vendor/: nothing downloads at build or
# run time, and set-up needs no registry but Debian's.)
# Usage: scripts/install-deps.sh        (as root, or with sudo available)
set -euo pipefail

PACKAGES=(
  # build, and the checks scripts/lint.sh runs
  cmake g++ make pkg-config clang-format flake8
  # C++ libraries
  libopenimageio-dev libopenexr-dev libglm-dev nlohmann-json3-dev pybind11-dev
  libgtest-dev libbenchmark-dev
  # Highway: portable SIMD with runtime dispatch (SSE4/AVX2/AVX-512/NEON), the fast kernels
  libhwy-dev
  # Intel Embree: the BVH and ray queries of rtao, the ray-traced peer and check of the references
  libembree-dev
  # perf: the profiles docs/benchmarks.md quotes (scripts/bench.sh --profile)
  linux-perf
  # Python (Debian's /usr/bin/python3, the one Blender embeds)
  python3 python3-dev python3-numpy python3-openimageio python3-pytest python3-hypothesis
  python3-skimage python3-tqdm python3-matplotlib python3-optuna
  # Pillow: the comparison report's WebP images
  python3-pil
  # SciPy: the Wilcoxon signed-rank test of the study's paired comparisons (aolab.study.stats)
  python3-scipy
  # Dask: `aolab reference`, `tune` and `compare` with --workers N or --scheduler ADDRESS
  # (docs/scale_out.md); psutil: the cluster tests find its worker processes
  python3-distributed python3-psutil
  # openssl: the TLS farm's certificates (docs/scale_out.md, "Security"), made by the tests too
  openssl
  # headless browser: tests/python/study/test_report.py opens the comparison report in it
  chromium
  # Blender (3.4 on Debian 12, 4.3 on Debian 13; its Python is /usr/bin/python3 on both, and
  # `import aolab` is tested inside it)
  blender
  # EEVEE (the comparison's GTAO peer) needs an OpenGL context: Xvfb + Mesa's llvmpipe
  xvfb xauth libgl1-mesa-dri
  # scripts/addon_screenshot.sh captures the Xvfb screen: xwd, and ImageMagick to write PNG
  x11-apps imagemagick
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
else
  echo "install-deps: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

