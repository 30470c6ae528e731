#!/usr/bin/env bash
# Configures (once) and builds the core, the Python module, the tests and the benchmarks
# into build/ (override with AOLAB_BUILD_DIR). The importable package is build/python/aolab.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${AOLAB_BUILD_DIR:-$root/build}"
jobs="${AOLAB_JOBS:-$(nproc)}"
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3
fi
cmake --build "$build" -j "$jobs"
