#!/usr/bin/env bash
# The benchmarks (not part of the tests; docs/benchmarks.md).
#   scripts/bench.sh            every method's scalar code against its SIMD kernel at the medium
#                               preset, in one run: scalar ms, SIMD ms on 1 and 2 threads,
#                               speed-up, samples per second, the shared blur apart (aolab
#                               bench-table; its options follow: --scaling for 3840x2160 and
#                               peak memory, --radii for R x 2, 4, 8, --profile DIR for perf,
#                               --preset low, --size 640x360, METHOD... for some methods)
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
