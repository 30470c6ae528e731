#!/usr/bin/env bash
# Records the SHA-256 of every committed result file of reference_scenes/<name> (or the names
# given) in a SHA256SUMS beside it: the scene folder (each frame's folder for a sequence) and
# its peers/ and limits/ (docs/file_formats.md, "Checksums"). The study checks them when it
# loads a scene; the update scripts call this after they change a scene's files.
#   scripts/update_checksums.sh                 # every scene
#   scripts/update_checksums.sh room flythrough # some
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PYTHONPATH="${AOLAB_BUILD_DIR:-$root/build}/python${PYTHONPATH:+:$PYTHONPATH}"
names=("$@")
. "$root/scripts/scene_list.sh"
/usr/bin/python3 - "$root/reference_scenes" "${names[@]}" <<'PY'
import sys
from pathlib import Path
from aolab import scenes
root = Path(sys.argv[1])
for name in sys.argv[2:]:
    folders = scenes.write_scene_checksums(root / name)
    print(f"{name}: SHA256SUMS in {len(folders)} folder(s)")
PY
