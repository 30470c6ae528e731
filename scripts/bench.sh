#!/usr/bin/env bash
# Runs the C++ benchmarks (not part of the tests): 5 repetitions, medians and spread.
# Record the medians in docs/benchmarks.md. Extra arguments go to Google Benchmark,
# e.g. scripts/bench.sh --benchmark_filter=BM_Hbao/
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh" >/dev/null
"${AOLAB_BUILD_DIR:-$root/build}/aolab_bench" --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true --benchmark_min_time=0.5 "$@"
