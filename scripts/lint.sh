#!/usr/bin/env bash
# Checks the habits the project declares, as CI runs them (scripts/test.sh calls this):
#   - every C++ file is formatted by .clang-format (fix with: scripts/lint.sh --fix);
#   - flake8 (Debian's, configured in .flake8) passes over every Python file.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
mapfile -t cxx < <(git ls-files -co --exclude-standard '*.cpp' '*.h')
if [ "${1:-}" = "--fix" ]; then
  clang-format -i "${cxx[@]}"
  echo "lint: formatted ${#cxx[@]} C++ files"
  exit 0
fi
status=0
if ! clang-format --dry-run --Werror "${cxx[@]}"; then
  echo "lint: C++ files differ from .clang-format: run scripts/lint.sh --fix" >&2
  status=1
fi
mapfile -t py < <(git ls-files -co --exclude-standard '*.py')
if ! /usr/bin/python3 -m flake8 "${py[@]}"; then
  echo "lint: flake8 found the problems above" >&2
  status=1
fi
[ "$status" -eq 0 ] && echo "lint: ${#cxx[@]} C++ files formatted, ${#py[@]} Python files clean"
exit "$status"
