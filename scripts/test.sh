#!/usr/bin/env bash
# Builds and runs every test: the lint checks, the C++ suite (ctest) and the Python suite
# (pytest).
# Installs missing Debian packages first, so it works on a fresh machine.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${AOLAB_BUILD_DIR:-$root/build}"

"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"

echo "== Lint (clang-format, flake8)"
"$root/scripts/lint.sh"

echo "== C++ tests (ctest)"
ctest --test-dir "$build" --output-on-failure -j "$(nproc)"

echo "== Python tests (pytest)"
# The freshly built package comes first on the path, whatever a .pth file points at.
export PYTHONPATH="$build/python${PYTHONPATH:+:$PYTHONPATH}"
cd "$root"
/usr/bin/python3 -m pytest tests/python -q -p no:cacheprovider "$@"
