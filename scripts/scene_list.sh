# Sourced by scripts/update_references.sh and scripts/update_meshes.sh: the scenes they work on
# and which of them are sequences. Expects $root (the checkout) and the array `names`.

# No names given: every reference_scenes/<name> with a manifest.json.
if [ ${#names[@]} -eq 0 ]; then
  for d in "$root"/reference_scenes/*/; do [ -f "$d/manifest.json" ] && names+=("$(basename "$d")"); done
fi

is_sequence() {  # a sequence scene: its manifest names "frames" (frames/NNNN/reference.*)
  /usr/bin/python3 -c 'import json, sys; sys.exit(0 if "frames" in json.load(open(sys.argv[1])) else 1)' "$1/manifest.json"
}
