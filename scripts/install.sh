#!/usr/bin/env bash
# Makes this checkout's build the system's AO Lab (scripts/setup.sh runs it after building):
#   <site>/aolab.pth        one line, the build's python folder, so `import aolab` works in
#                           /usr/bin/python3 from any folder and inside Blender;
#   /usr/local/bin/aolab    the command, `/usr/bin/python3 -m aolab`.
# Only one checkout can be installed at a time: installing another replaces it, and says so.
# Undo with scripts/uninstall.sh.
#
#   scripts/install.sh [BUILD_DIR]      (default: $AOLAB_BUILD_DIR or <checkout>/build)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$(cd "${1:-${AOLAB_BUILD_DIR:-$root/build}}" && pwd)"
. "$root/scripts/install_paths.sh"
[ -d "$build/python/aolab" ] || { echo "install: $build/python/aolab missing: run scripts/build.sh first" >&2; exit 2; }

if [ -f "$aolab_pth" ]; then
  previous="$(head -n 1 "$aolab_pth")"
  if [ "$previous" != "$build/python" ]; then
    echo "install: REPLACING the AO Lab installed from $previous"
    echo "install:   with this checkout's $build/python (scripts/install.sh in the other checkout switches back)"
  fi
fi
$AOLAB_SUDO mkdir -p "$aolab_site" "$(dirname "$aolab_command")"
echo "$build/python" | $AOLAB_SUDO tee "$aolab_pth" >/dev/null
printf '#!/bin/sh\n%s\n# from %s\nexec /usr/bin/python3 -m aolab "$@"\n' "$aolab_marker" "$root" |
  $AOLAB_SUDO tee "$aolab_command" >/dev/null
$AOLAB_SUDO chmod 755 "$aolab_command"
echo "install: aolab importable via $aolab_pth -> $build/python; command $aolab_command"
echo "install: undo with scripts/uninstall.sh"
