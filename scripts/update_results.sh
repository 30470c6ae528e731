#!/usr/bin/env bash
# Regenerates docs/results.md (the current results table and Pareto plots, with the
# hand-written paragraphs kept), docs/results_scenes.md and docs/results_sequences.md from a fresh run of the comparison study on the whole corpus
# (`aolab compare --corpus`: every scene, so that its means and intervals are over all 30
# stills, and the four sequences). Run it on a quiet machine; about 13 min on 2 cores. Extra
# arguments go to `aolab compare` (e.g. --sweep full for every setting: much longer).
#   scripts/update_results.sh [--sweep full] [...]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${AOLAB_RESULTS_OUT:-$root/out/results}"
# Build first: the package in the build is a copy, and `aolab tune` writes the checkout's
# tuned_presets.json, so a study run straight after tuning would score the old presets.
"$root/scripts/build.sh" >/dev/null
export PYTHONPATH="${AOLAB_BUILD_DIR:-$root/build}/python${PYTHONPATH:+:$PYTHONPATH}"
/usr/bin/python3 -m aolab compare --corpus --scenes-dir "$root/reference_scenes" --out "$out" "$@"
/usr/bin/python3 -m aolab.study.results_doc "$out/results.json" "$root/docs"
echo "update_results: docs/results*.md and docs/images/results_*.svg regenerated from $out"
