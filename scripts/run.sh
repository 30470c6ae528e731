#!/usr/bin/env bash
# The main job, for now: HBAO on analytic G-buffers written as Blender-style EXRs, scored
# against their closed-form Cycles AO (BLENDER_FACTS.md). Outputs go to out/ (or $1).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/out}"
export PYTHONPATH="${AOLAB_BUILD_DIR:-$root/build}/python${PYTHONPATH:+:$PYTHONPATH}"
py=/usr/bin/python3
mkdir -p "$out"
for scene in wall crease ceiling; do
  $py -m aolab analytic "$scene" "$out/$scene.exr" --radius 2 --width 640 --height 360
  $py -m aolab run hbao "$out/$scene.exr" --out "$out/${scene}_hbao" --json "$out/${scene}_hbao.json"
done
$py -m aolab run hbao analytic:blocks --radius 0.5 --out "$out/blocks_hbao"
echo "run: results in $out"
