"""``aolab bench-table``: every method's scalar code against its SIMD kernel
(aolab.checks.kernel_bench, docs/benchmarks.md)."""

from __future__ import annotations

from ..checks import kernel_bench
from ..util.arguments import MAX_RUNS, int_option, size_option


def add_parser(sub):
    bt = sub.add_parser("bench-table",
                        help="every method's scalar code against its SIMD kernel, one run",
                        description="Times each method at a preset on the blocks scene at "
                        "1280x720, R = 0.25: its scalar code on 1 thread, its SIMD kernel on 1 "
                        "and 2 threads, the speed-up and the samples per second "
                        "(docs/benchmarks.md). scripts/bench.sh runs it.")
    # No `choices`: Python 3.11 argparse checks an empty nargs="*" list against them and
    # refuses it; an unknown name is a ValueError from aolab.method_info instead.
    bt.add_argument("methods", nargs="*", metavar="METHOD",
                    help="methods (default: every method but the oracles)")
    bt.add_argument("--preset", help="the preset to time, a name of `aolab presets METHOD` "
                    "(default medium, or default for a method without it; the shared blur is "
                    "left out)")
    bt.add_argument("--repeat", type=int_option("--repeat", 1, MAX_RUNS), default=5,
                    help=f"timed runs per kernel, 1 to {MAX_RUNS} (their median; default 5)")
    bt.add_argument("--scaling", action="store_true",
                    help="also 3840x2160: time, its ratio to 1280x720 and the peak memory")
    bt.add_argument("--radii", action="store_true",
                    help="also R x 2, 4 and 8 at the same settings (how time grows with R)")
    bt.add_argument("--size", type=size_option("--size"),
                    help="WxH instead of 1280x720 (e.g. 640x360, the add-on's live preview)")
    bt.add_argument("--json", help="also write the rows to this JSON file")
    bt.add_argument("--profile", metavar="DIR",
                    help="also record each method's SIMD kernel with perf into DIR and print "
                    "its hottest functions")
    return bt


def run(args) -> int:
    return kernel_bench.run_table(args.methods, preset=args.preset, repeat=args.repeat,
                                  scaling=args.scaling, radii=args.radii, size=args.size,
                                  json_path=args.json, profile=args.profile)
