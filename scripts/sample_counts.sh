#!/usr/bin/env bash
# How far HBAO's samples get on each scene (docs/benchmarks.md, "What the scene costs HBAO"):
# builds the Python module with gcov's arc counters into build-cov/ (override with
# AOLAB_COV_BUILD_DIR; the counters are exact, the build's times are not meant to be read),
# runs HBAO `medium` without the blur on one thread on each 1280x720 scene at its own R and at
# 256 px on screen, with its SIMD kernel and with its scalar code, and prints per run how many
# samples (scalar code) or sample vectors (SIMD kernel) each phase of the per-sample test was
# given: the prefilter or sign test, the radius test, the exact tangent test, a sample
# counted. A vector goes on while any of its lanes does, so the SIMD rows are the
# kernel's costs, the scalar rows the samples' odds.
#
#   scripts/sample_counts.sh [SCENE ...]        (default: every 1280x720 still scene)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${AOLAB_COV_BUILD_DIR:-$root/build-cov}"
jobs="${AOLAB_JOBS:-$(nproc)}"
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 \
    -DAOLAB_BUILD_TESTS=OFF -DAOLAB_BUILD_BENCHMARKS=OFF -DCMAKE_CXX_FLAGS=--coverage \
    -DCMAKE_SHARED_LINKER_FLAGS=--coverage >/dev/null
fi
# The module and the package beside it, as scripts/build.sh lays them out.
cmake --build "$build" -j "$jobs" >/dev/null
export PYTHONPATH="$build/python"
exec /usr/bin/python3 "$root/scripts/sample_counts.py" "$build" "$root/core/methods/hbao" "$@"
