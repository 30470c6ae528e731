#!/usr/bin/env bash
# Builds the C++ tests with AddressSanitizer and UndefinedBehaviorSanitizer into build-asan/
# (override with AOLAB_ASAN_BUILD_DIR) and runs them; any finding fails the run. The Python
# module is not part of this build: an ASan module would need the runtime preloaded into
# the interpreter.
#
#   scripts/sanitize.sh [ctest arguments]      e.g. scripts/sanitize.sh -R Hbao
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${AOLAB_ASAN_BUILD_DIR:-$root/build-asan}"
jobs="${AOLAB_JOBS:-$(nproc)}"
"$root/scripts/install-deps.sh"
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAOLAB_SANITIZE=ON \
    -DAOLAB_BUILD_PYTHON=OFF -DAOLAB_BUILD_BENCHMARKS=OFF
fi
cmake --build "$build" -j "$jobs" --target aolab_tests
# detect_leaks: the tests own every allocation; halt_on_error: the first finding fails.
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" "$@"
