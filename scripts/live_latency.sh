#!/usr/bin/env bash
# The add-on's Live preview, timed in Blender's full UI (Xvfb): per method at its medium
# preset, the time from a changed setting to the updated image, and how much of it is
# aolab.compute and how much the image update (docs/blender_addon.md, "Live preview").
#
#   scripts/live_latency.sh [SCALE] [REPEAT] [OUT.json] [SCENE_BUILD.py]
#
# SCALE % of the scene's size (default 50: 640x360 for the reference scenes' 1280x720).
# Installs the add-on into temporary Blender user folders; the G-buffer is cached in
# $AOLAB_CACHE or ~/.cache/aolab/references. With PYTHONPATH set (e.g. to build/python),
# Blender uses that `aolab`.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
scale="${1:-50}"
repeat="${2:-5}"
out="$(realpath -m "${3:-live_latency.json}")"
scene="$(realpath "${4:-$root/reference_scenes/room/build.py}")"
cache="${AOLAB_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/aolab/references}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
export BLENDER_USER_CONFIG="$tmp/config" BLENDER_USER_SCRIPTS="$tmp/scripts"
AOLAB_ADDON_ZIP="$tmp/aolab_addon.zip" "$root/scripts/install_addon.sh" >/dev/null
rm -f "$out"
xvfb-run -a -s "-screen 0 1280x720x24" "${AOLAB_BLENDER:-blender}" --factory-startup -noaudio \
  ${PYTHONPATH:+--python-use-system-env} --python-exit-code 1 \
  --python "$root/scripts/live_latency.py" -- "$scene" "$cache" "$out" "$scale" "$repeat"
/usr/bin/python3 - "$out" <<'PY'
import json, statistics, sys
r = json.load(open(sys.argv[1]))
if r["error"]:
    sys.exit("live_latency: " + r["error"])
keys = ["first_callback_ms", "wait_ms", "compute_ms", "rgba_ms", "poll_ms", "image_ms", "image_cpu_ms",
        "total_ms"]
print(f"Live at {r['size']}, median over the repeats (ms); the event loop called a 10 ms "
      f"timer back after {statistics.median(r['loop_ms']):.1f} ms (median)")
print(f"{'method':14s}" + "".join(f"{k[:-3][:10]:>11s}" for k in keys))
for m, rows in r["times"].items():
    print(f"{m:14s}" + "".join(f"{statistics.median(x[k] for x in rows):11.1f}" for k in keys))
c = r["converge"]
med = {k: statistics.median(x[k] for x in c["rows"][1:]) for k in ("compute_ms", "accumulate_ms", "poll_ms")}
print(f"converging at rest: {c['method']} frames {c['frames'][0]}..{c['frames'][-1]} in "
      f"{c['seconds']:.2f} s from the change; per frame (median) compute {med['compute_ms']:.1f}, "
      f"accumulate {med['accumulate_ms']:.1f}, poll {med['poll_ms']:.1f} ms")
PY
