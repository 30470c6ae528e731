#!/usr/bin/env bash
# Checks the habits the project declares, as CI runs them (scripts/test.sh calls this):
#   - every C++ file is formatted by .clang-format (fix with: scripts/lint.sh --fix), checked
#     with clang-format 14 (Debian 12's), the release the code is formatted with: other
#     releases lay out the same options differently (Debian 13's 19 moves lambdas passed as
#     arguments), so where clang-format is another release the check says so and is skipped;
#     CI and the developers' machines run Debian 12;
#   - flake8 (Debian's, configured in .flake8) passes over every Python file;
#   - no module of the aolab package is over 800 lines, no function over 80
#     (scripts/check_sizes.py).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
mapfile -t cxx < <(git ls-files -co --exclude-standard '*.cpp' '*.h')
if [ "${1:-}" = "--fix" ]; then
  clang-format -i "${cxx[@]}"   # with clang-format 14 (see above)
  echo "lint: formatted ${#cxx[@]} C++ files"
  exit 0
fi
status=0
formatted="${#cxx[@]} C++ files formatted"
format_major=14
major="$(clang-format --version | sed -n 's/.*clang-format version \([0-9]*\).*/\1/p')"
if [ "$major" != "$format_major" ]; then
  echo "lint: clang-format $major is not $format_major, the release the code is formatted with: format check skipped"
  formatted="C++ format not checked (clang-format $major)"
elif ! clang-format --dry-run --Werror "${cxx[@]}"; then
  echo "lint: C++ files differ from .clang-format: run scripts/lint.sh --fix" >&2
  status=1
fi
mapfile -t py < <(git ls-files -co --exclude-standard '*.py')
if ! /usr/bin/python3 -m flake8 "${py[@]}"; then
  echo "lint: flake8 found the problems above" >&2
  status=1
fi
if ! /usr/bin/python3 "$root/scripts/check_sizes.py"; then
  echo "lint: split the modules and functions above (scripts/check_sizes.py says why)" >&2
  status=1
fi
[ "$status" -eq 0 ] && echo "lint: $formatted, ${#py[@]} Python files clean"
exit "$status"
