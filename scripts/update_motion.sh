#!/usr/bin/env bash
# Adds motion vectors to the committed frames of the sequence scenes (every
# reference_scenes/<name> whose manifest names "frames", or the names given) without
# rendering their AO again: a G-buffer of Depth and Cycles' Vector pass is rendered per frame
# at 1 sample (aolab reference --spp 1 --passes depth,motion, cached; its 1-sample AO is
# thrown away), and its Motion pass is copied into frames/NNNN/reference.exr, every other
# channel left bit for bit, after checking it is the same scene, frame, camera and depth
# (aolab.bridge.motion.add_motion_pass). Seconds per frame.
#   scripts/update_motion.sh                 # all sequences
#   scripts/update_motion.sh flythrough      # some
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PYTHONPATH="${AOLAB_BUILD_DIR:-$root/build}/python${PYTHONPATH:+:$PYTHONPATH}"
names=("$@")
. "$root/scripts/scene_list.sh"
fresh="$(mktemp -d)"
trap 'rm -rf "$fresh"' EXIT
for name in "${names[@]}"; do
  dir="$root/reference_scenes/$name"
  if ! is_sequence "$dir"; then
    echo "$name: not a sequence scene, skipped"
    continue
  fi
  /usr/bin/python3 -m aolab reference "$dir" --spp 1 --passes depth,motion --out "$fresh/$name"
  /usr/bin/python3 - "$dir" "$fresh/$name" <<'PY'
import sys
from pathlib import Path
from aolab.bridge.motion import add_motion_pass
scene, fresh = Path(sys.argv[1]), Path(sys.argv[2])
for frame in sorted((fresh / "frames").iterdir()):
    target = scene / "frames" / frame.name / "reference.exr"
    side = add_motion_pass(target, frame / "reference.exr")
    print(f"{scene.name} frame {frame.name}: motion added (to frame "
          f"{side['motion_previous_frame']})")
PY
done
"$root/scripts/update_checksums.sh" "${names[@]}"
