#!/usr/bin/env bash
# Screenshot of Blender's UI with the AO Lab panel and its results: docs/images/addon_panel.png
# (Blender 3.4; docs/images/addon_panel_blender4.png is the same on Blender 4.3); with MODE
# advise, the panel's Quick Compare and advice: docs/images/addon_advise.png (and
# addon_advise_blender4.png).
#
#   scripts/addon_screenshot.sh [OUT.png] [SCENE_BUILD.py] [compare|advise]
#
# Installs the add-on into temporary Blender user folders (your preferences are untouched),
# starts Blender's full UI under Xvfb (xvfb-run; Debian packages xvfb xauth, and x11-apps and
# imagemagick for the capture), builds the
# scene (default reference_scenes/room/build.py), and runs scripts/addon_screenshot.py: the
# real Preview / Render Reference (64 samples, 320x180, cached in $AOLAB_CACHE or
# ~/.cache/aolab/references) / Compare operators, then the screenshot. With PYTHONPATH set
# (e.g. to build/python), Blender uses that `aolab` instead of the one the .pth points at.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$(realpath -m "${1:-$root/docs/images/addon_panel.png}")"
scene="$(realpath "${2:-$root/reference_scenes/room/build.py}")"
mode="${3:-compare}"
case "$mode" in
  compare) screen=1920x1080 ;;
  advise) screen=1920x1440 ;;   # taller: the advice lies below the methods and the results
  *) echo "addon_screenshot: MODE must be compare or advise, got '$mode'" >&2; exit 2 ;;
esac
cache="${AOLAB_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/aolab/references}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
export BLENDER_USER_CONFIG="$tmp/config" BLENDER_USER_SCRIPTS="$tmp/scripts" \
  BLENDER_USER_EXTENSIONS="$tmp/extensions"
AOLAB_ADDON_ZIP="$tmp/aolab_addon.zip" "$root/scripts/install_addon.sh" >/dev/null
mkdir -p "$(dirname "$out")"
rm -f "$out"
# Blender in the background on Xvfb; once the panel shows the results it writes $tmp/ready,
# the X screen is captured here (xwd, converted by ImageMagick), and $tmp/ready.done lets
# Blender quit.
export AOLAB_SHOT_OUT="$out" AOLAB_SHOT_READY="$tmp/ready" AOLAB_SHOT_BLENDER="${AOLAB_BLENDER:-blender}"
export AOLAB_SHOT_ARGS="${PYTHONPATH:+--python-use-system-env}" AOLAB_SHOT_MODE="$mode"
xvfb-run -a -s "-screen 0 ${screen}x24" bash -c '
  "$AOLAB_SHOT_BLENDER" --factory-startup -noaudio --enable-event-simulate $AOLAB_SHOT_ARGS \
    --python-exit-code 1 --python "$0" -- "$1" "$2" "$AOLAB_SHOT_READY" "$AOLAB_SHOT_MODE" &
  pid=$!
  while kill -0 $pid 2>/dev/null && [ ! -f "$AOLAB_SHOT_READY" ]; do sleep 0.5; done
  if [ -f "$AOLAB_SHOT_READY" ]; then
    sleep 1   # the last redraw
    xwd -root -silent | /usr/bin/convert xwd:- "$AOLAB_SHOT_OUT"   # not another convert on PATH
    touch "$AOLAB_SHOT_READY.done"
  fi
  wait $pid' "$root/scripts/addon_screenshot.py" "$scene" "$cache"
[ -s "$out" ] || { echo "addon_screenshot: no screenshot written" >&2; exit 1; }
echo "addon_screenshot: $out"
