#!/usr/bin/env bash
# Undoes scripts/install.sh (and so the install step of scripts/setup.sh): removes the
# aolab.pth from Debian's Python site folder and the /usr/local/bin/aolab command. The
# checkout, its build folder, the Debian packages and the reference cache
# (~/.cache/aolab) are left alone; remove them by hand if you want them gone.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
. "$root/scripts/install_paths.sh"
removed=0
if [ -f "$aolab_pth" ]; then
  echo "uninstall: removing $aolab_pth (-> $(head -n 1 "$aolab_pth"))"
  $AOLAB_SUDO rm -f "$aolab_pth"
  removed=1
fi
if [ -f "$aolab_command" ]; then
  if sed -n 2p "$aolab_command" | grep -qxF "$aolab_marker"; then
    echo "uninstall: removing $aolab_command"
    $AOLAB_SUDO rm -f "$aolab_command"
    removed=1
  else
    echo "uninstall: leaving $aolab_command: it was not installed by AO Lab" >&2
  fi
fi
[ "$removed" -eq 1 ] || echo "uninstall: nothing of AO Lab's was installed"
