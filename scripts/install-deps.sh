#!/usr/bin/env bash
# Installs the Debian packages AO Lab needs (no PyPI), only those that are missing, and the
# comparison report's plotly.js from the npm registry (core/web/package-lock.json pins it;
# `npm ci` there, only when it is missing or another version: nothing downloads at build or
# run time).
# Usage: scripts/install-deps.sh        (as root, or with sudo available)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

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
  # headless browser: tests/python/test_report.py opens the comparison report in it
  chromium
  # Node.js: `node` reads core/web's lock below (npm comes with it, or as Debian's npm)
  nodejs
  # Blender (3.4 on Debian 12, 4.3 on Debian 13; its Python is /usr/bin/python3 on both, and
  # `import aolab` is tested inside it)
  blender
  # EEVEE (the comparison's GTAO peer) needs an OpenGL context: Xvfb + Mesa's llvmpipe
  xvfb xauth libgl1-mesa-dri
  # scripts/addon_screenshot.sh captures the Xvfb screen: xwd, and ImageMagick to write PNG
  x11-apps imagemagick
)

# npm: Debian's package, unless an npm is there already (a Node.js that bundles it, such as
# NodeSource's, conflicts with Debian's npm package)
command -v npm >/dev/null 2>&1 || PACKAGES+=(npm)

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

# The report's plotly.js: core/web/node_modules, at the version of core/web/package-lock.json
# (the build copies it into the package).
web="$root/core/web"
pin="plotly.js-basic-dist-min"
want="$(cd "$web" && node -p "require('./package-lock.json').packages['node_modules/$pin'].version")"
have="$(cd "$web" && node -p "try { require('./node_modules/$pin/package.json').version } catch (e) { '' }")"
if [ "$want" = "$have" ]; then
  echo "install-deps: $pin $have present"
else
  echo "install-deps: installing $pin $want (npm ci in core/web)"
  (cd "$web" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error)
fi
