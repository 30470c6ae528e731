#!/usr/bin/env bash
# One command from a fresh Debian 12 clone to a working AO Lab:
# installs missing Debian packages, builds, makes `import aolab` work in /usr/bin/python3
# (and in Blender) from any folder, installs the `aolab` command, and runs the main job.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${AOLAB_BUILD_DIR:-$root/build}"

"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"

# A .pth in Debian's site directory reaches /usr/bin/python3, venvs made from it with
# --system-site-packages, and Blender's embedded Python.
site=/usr/local/lib/python3.11/dist-packages
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
$SUDO mkdir -p "$site"
echo "$build/python" | $SUDO tee "$site/aolab.pth" >/dev/null
printf '#!/bin/sh\nexec /usr/bin/python3 -m aolab "$@"\n' | $SUDO tee /usr/local/bin/aolab >/dev/null
$SUDO chmod 755 /usr/local/bin/aolab
echo "setup: aolab importable via $site/aolab.pth -> $build/python; command /usr/local/bin/aolab"

"$root/scripts/run.sh"
