#!/usr/bin/env bash
# One command from a fresh Debian 12 or 13 clone to a working AO Lab:
# installs missing Debian packages, builds, makes `import aolab` work in /usr/bin/python3
# (and in Blender) from any folder, installs the `aolab` command, and runs the main job.
# scripts/uninstall.sh undoes the two files it puts under /usr/local.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${AOLAB_BUILD_DIR:-$root/build}"

"$root/scripts/install-deps.sh"
"$root/scripts/build.sh"
"$root/scripts/install.sh" "$build"
"$root/scripts/run.sh"
