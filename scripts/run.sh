#!/usr/bin/env bash
# The main job: the comparison study (docs/comparison.md). Every method at its quick presets
# (low, medium, high) on every committed reference scene, timed and scored against the Cycles
# 1024-spp reference; a few minutes on 2 cores. Report in out/compare/ (or $1):
# report.html, results.csv, results.json. Further arguments go to `aolab compare`
# (e.g. scripts/run.sh out/compare --sweep full).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/out/compare}"
shift || true
export PYTHONPATH="${AOLAB_BUILD_DIR:-$root/build}/python${PYTHONPATH:+:$PYTHONPATH}"
/usr/bin/python3 -m aolab compare --scenes-dir "$root/reference_scenes" --out "$out" "$@"
echo "run: open $out/report.html"
