#!/usr/bin/env bash
# Re-renders the committed references: every reference_scenes/<name> (or the names given)
# at its manifest's resolution, R and 1024 spp, into reference_scenes/<name>/reference.{exr,json},
# then its screen-space limits (aolab limits: reference_scenes/<name>/limits/, recomputed only
# when the reference changed). Cached renders are reused; pass --force to render again.
# ~6 min per small scene on 2 cores, plus the limits (minutes per scene).
#   scripts/update_references.sh                 # all scenes
#   scripts/update_references.sh analytic room   # some
#   scripts/update_references.sh --peers [names]  # the comparison peers instead: Cycles at
#       1/4/16/64/256 spp (seed 1) and EEVEE's GTAO under xvfb-run, into <name>/peers/
#       (~1/3 of a reference's time per scene); on a sequence, EEVEE's alone per frame, into
#       <name>/frames/NNNN/peers/
#   scripts/update_references.sh --limits [names] # only the screen-space limits (--force:
#       recompute them all, after a change to the screen_space_limit method)
#   scripts/update_references.sh --eevee-next [names] # on Blender 4.2+ (Debian 13): EEVEE
#       Next's AO pass alone, into <name>/peers/eevee_next.{exr,json} beside 3.4's peers
#       (~1 min per scene under llvmpipe)
#   scripts/update_references.sh --workers 2 --corpus # the corpus on the Dask farm: the
#       stills' references, then their limits, peers and meshes (docs/scale_out.md); with
#       --workers N every still of the names is rendered as one batch of jobs, each render
#       on a worker; --corpus names the corpus scenes (manifests with "uses")
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PYTHONPATH="${AOLAB_BUILD_DIR:-$root/build}/python${PYTHONPATH:+:$PYTHONPATH}"
force=()
names=()
peers=0
limits=0
eevee_next=0
workers=1
while [ $# -gt 0 ]; do
  case "$1" in
    --force) force=(--force) ;;
    --peers) peers=1 ;;
    --eevee-next) eevee_next=1; peers=1 ;;
    --limits) limits=1 ;;
    --workers) workers="${2:?--workers needs a number}"; shift ;;
    --corpus)
      for d in "$root"/reference_scenes/*/; do
        grep -q '"uses"' "$d/manifest.json" 2>/dev/null && names+=("$(basename "$d")")
      done ;;
    *) names+=("$1") ;;
  esac
  shift
done
. "$root/scripts/scene_list.sh"
if [ "$workers" != 1 ]; then
  # The farm: the stills' references as one batch of Dask jobs, then what each scene needs.
  stills=()
  for name in "${names[@]}"; do
    is_sequence "$root/reference_scenes/$name" || stills+=("$name")
  done
  dirs=("${stills[@]/#/$root/reference_scenes/}")
  # --out holds one folder per scene when several are rendered, the files themselves for one
  one=""; [ "${#stills[@]}" = 1 ] && one="/${stills[0]}"
  /usr/bin/python3 -m aolab reference "${dirs[@]}" --spp 1024 --workers "$workers" \
    --out "$root/reference_scenes$one" --quiet "${force[@]}"
  /usr/bin/python3 -m aolab limits "${stills[@]}"
  tmp="$(mktemp -d)"
  /usr/bin/python3 -m aolab reference "${dirs[@]}" --peers --workers "$workers" \
    --out "$tmp$one" --quiet "${force[@]}"
  for name in "${stills[@]}"; do
    mkdir -p "$root/reference_scenes/$name/peers"
    cp "$tmp/$name/"* "$root/reference_scenes/$name/peers/"
  done
  rm -rf "$tmp"
  "$root/scripts/update_meshes.sh" "${stills[@]}"
  "$root/scripts/update_checksums.sh" "${names[@]}"
  exit 0
fi
for name in "${names[@]}"; do
  if is_sequence "$root/reference_scenes/$name"; then
    # A sequence (manifest "frames"): one reference per frame into <name>/frames/NNNN/; the
    # study scores its frames and their flicker, without peers or screen-space limits.
    # With --peers: EEVEE's alone per frame into frames/NNNN/peers/ (the Cycles ladder per
    # frame would triple the sequence's render time for rungs the stills already score).
    if [ "$peers" = 1 ] && [ "$eevee_next" = 0 ]; then
      tmp="$(mktemp -d)"
      /usr/bin/python3 -m aolab reference "$root/reference_scenes/$name" --peers --ladder none \
        --out "$tmp" "${force[@]}"
      for f in "$tmp"/frames/*/; do
        mkdir -p "$root/reference_scenes/$name/frames/$(basename "$f")/peers"
        cp "$f"* "$root/reference_scenes/$name/frames/$(basename "$f")/peers/"
      done
      rm -rf "$tmp"
    elif [ "$limits" = 0 ] && [ "$peers" = 0 ]; then
      /usr/bin/python3 -m aolab reference "$root/reference_scenes/$name" --spp 1024 \
        --out "$root/reference_scenes/$name" "${force[@]}"
    else
      echo "$name: a sequence scene has no screen-space limits or EEVEE Next peers, skipped"
    fi
    continue
  fi
  if [ "$limits" = 1 ]; then
    /usr/bin/python3 -m aolab limits "$root/reference_scenes/$name" "${force[@]}"
    continue
  fi
  if [ "$eevee_next" = 1 ]; then
    tmp="$(mktemp -d)"
    /usr/bin/python3 -m aolab reference "$root/reference_scenes/$name" --peers --ladder none \
      --out "$tmp" "${force[@]}"
    grep -q '"name": "eevee_next"' "$tmp/peers.json" ||
      { echo "$name: this Blender's EEVEE is not EEVEE Next (Blender 4.2+ needed)" >&2; exit 2; }
    cp "$tmp/eevee_next.exr" "$root/reference_scenes/$name/peers/eevee_next.exr"
    cp "$tmp/peers.json" "$root/reference_scenes/$name/peers/eevee_next.json"
    rm -rf "$tmp"
    continue
  fi
  if [ "$peers" = 1 ]; then
    /usr/bin/python3 -m aolab reference "$root/reference_scenes/$name" --peers \
      --out "$root/reference_scenes/$name/peers" "${force[@]}"
    continue
  fi
  /usr/bin/python3 -m aolab reference "$root/reference_scenes/$name" --spp 1024 \
    --out "$root/reference_scenes/$name" "${force[@]}"
  /usr/bin/python3 -m aolab limits "$root/reference_scenes/$name"
done
# every file just written recorded in its folder's SHA256SUMS (docs/file_formats.md, "Checksums")
"$root/scripts/update_checksums.sh" "${names[@]}"
