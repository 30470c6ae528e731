#!/usr/bin/env bash
# The benchmarks (not part of the tests; docs/benchmarks.md).
#   scripts/bench.sh            every method's medium preset on every 1280x720 reference scene
#                               at its R and at 16-256 px on screen (median and worst over
#                               scenes), on the 640x360 corpus at its R, HBAO 8x8's scalar code
#                               against its SIMD kernel; then every method's scalar code against
#                               its SIMD kernel on blocks (1 and 2 threads, speed-up, samples per
#                               second, the shared blur apart); last, where each target stands
#                               (aolab bench-table; its options follow: --scaling for 3840x2160
#                               and peak memory, --radii for R x 2, 4, 8 on blocks, --svg FILE
#                               for the curves, --scene NAME, --no-corpus, --no-scenes,
#                               --profile DIR for perf, --preset low, --size 640x360,
#                               METHOD... for some methods)
#   scripts/bench.sh --google [ARGS]
#                               the Google Benchmark programs: 5 repetitions, medians and
#                               spread; ARGS go to Google Benchmark, e.g.
#                               scripts/bench.sh --google --benchmark_filter=BM_Hbao/
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${AOLAB_BUILD_DIR:-$root/build}"
"$root/scripts/build.sh" >/dev/null
if [ "${1:-}" = "--google" ]; then
  shift
  exec "$build/aolab_bench" --benchmark_repetitions=5 \
    --benchmark_report_aggregates_only=true --benchmark_min_time=0.5 "$@"
fi
export PYTHONPATH="$build/python${PYTHONPATH:+:$PYTHONPATH}"
exec /usr/bin/python3 -m aolab bench-table "$@"
