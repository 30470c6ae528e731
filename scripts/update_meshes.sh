#!/usr/bin/env bash
# Exports the committed scenes' geometry without rendering: every reference_scenes/<name> (or
# the names given) at its manifest's resolution and camera, into
# reference_scenes/<name>/reference.mesh + reference.mesh.json (aolab mesh; cached like the
# references, --force exports again), then checks that each mesh's scene_hash equals the
# committed reference.json's, so the mesh is the geometry that reference was rendered from.
# A few seconds per scene.
#   scripts/update_meshes.sh                 # all scenes
#   scripts/update_meshes.sh room street     # some
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PYTHONPATH="${AOLAB_BUILD_DIR:-$root/build}/python${PYTHONPATH:+:$PYTHONPATH}"
force=()
names=()
for a in "$@"; do
  case "$a" in
    --force) force=(--force) ;;
    *) names+=("$a") ;;
  esac
done
. "$root/scripts/scene_list.sh"
status=0
for name in "${names[@]}"; do
  dir="$root/reference_scenes/$name"
  if is_sequence "$dir"; then
    # A sequence's geometry moves with its frames: aolab reference --passes ...,mesh renders
    # it per frame beside each frame's reference; a mesh of the whole folder would be wrong.
    echo "$name: a sequence scene, skipped (render its frames with --passes depth,normal,mesh)"
    continue
  fi
  /usr/bin/python3 -m aolab mesh "$dir" --out "$dir" "${force[@]}"
  if [ -f "$dir/reference.json" ]; then
    # aolab.mesh_for_gbuffer's own check, on the sidecar alone (no EXR needs reading).
    /usr/bin/python3 - "$dir" <<'PY' || status=1
import json, sys
from pathlib import Path
d = Path(sys.argv[1])
mesh = json.loads((d / "reference.mesh.json").read_text())["scene_hash"]
ref = json.loads((d / "reference.json").read_text())["scene_hash"]
if mesh != ref:
    sys.exit(f"{d.name}: reference.mesh.json's scene_hash {mesh} differs from reference.json's "
             f"{ref}: the scene changed since the reference was rendered")
print(f"{d.name}: scene_hash matches reference.json")
PY
  fi
done
"$root/scripts/update_checksums.sh" "${names[@]}"
exit "$status"
