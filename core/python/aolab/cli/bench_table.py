"""``aolab bench-table``: every method's time on the reference scenes and against the radius
on screen, and its scalar code against its SIMD kernel (aolab.benchmarks.geometry_bench and
kernel_bench, docs/benchmarks.md)."""

from __future__ import annotations

from ..benchmarks import geometry_bench, mip_bench
from ..util.arguments import MAX_RUNS, int_option, size_option


def add_parser(sub):
    bt = sub.add_parser("bench-table",
                        help="every method's time on every scene and radius, and its scalar "
                        "code against its SIMD kernel",
                        description="Times each method's medium preset on the 1280x720 "
                        "reference scenes at their R and at radii of 16 to 256 px on screen "
                        "(median and worst over scenes), on the corpus scenes at their R, "
                        "HBAO 8x8's scalar code against its SIMD kernel there; then each "
                        "method at a preset on the blocks scene at 1280x720, R = 0.25: its "
                        "scalar code on 1 thread, its SIMD kernel on 1 and 2 threads, the "
                        "speed-up and the samples per second; last, where each target stands "
                        "(docs/benchmarks.md). scripts/bench.sh runs it.")
    # No `choices`: Python 3.11 argparse checks an empty nargs="*" list against them and
    # refuses it; an unknown name is a ValueError from aolab.method_info instead.
    bt.add_argument("methods", nargs="*", metavar="METHOD",
                    help="methods (default: every method but the bounds)")
    bt.add_argument("--preset", help="the preset to time, a name of `aolab presets METHOD` "
                    "(default medium, or default for a method without it; the shared blur is "
                    "left out)")
    bt.add_argument("--repeat", type=int_option("--repeat", 1, MAX_RUNS), default=5,
                    help=f"timed runs per kernel, 1 to {MAX_RUNS} (their median; default 5)")
    bt.add_argument("--scaling", action="store_true",
                    help="also 3840x2160: time, its ratio to 1280x720 and the peak memory, and "
                    "each 1280x720 scene upsampled 3x against itself")
    bt.add_argument("--radii", action="store_true",
                    help="also R x 2, 4 and 8 at the same settings (how time grows with R)")
    bt.add_argument("--size", type=size_option("--size"),
                    help="the blocks scene at WxH instead of 1280x720 (e.g. 640x360, the "
                    "add-on's live preview)")
    bt.add_argument("--scene", action="append", default=[], metavar="NAME",
                    help="time on this scene (a name in reference_scenes/ or a folder; "
                    "repeatable; default: every still scene)")
    bt.add_argument("--scenes-dir", help="where the scenes are (default: reference_scenes/ "
                    "of the checkout, or $AOLAB_SCENES)")
    bt.add_argument("--no-corpus", action="store_true",
                    help="only the 1280x720 scenes, not the 640x360 corpus")
    bt.add_argument("--no-scenes", action="store_true",
                    help="only the blocks table: no scene is timed")
    bt.add_argument("--svg", help="also write the time against the radius on screen, per "
                    "method, to this SVG file (docs/benchmarks_radius.svg)")
    bt.add_argument("--mip", action="store_true",
                    help="instead: HBAO's and the bitmask's mip_distance (far samples on the "
                    "depth MIP chain), its time at 64 and 256 px on screen (q off, 4, 8, "
                    "alternated) and its accuracy on every still scene against the reference "
                    "and its noise floor (q off, 4, 8, 16, 32)")
    bt.add_argument("--json", help="also write the rows to this JSON file")
    bt.add_argument("--profile", metavar="DIR",
                    help="also record each method's SIMD kernel with perf into DIR and print "
                    "its hottest functions")
    return bt


def run(args) -> int:
    run_table = mip_bench.run if args.mip else geometry_bench.run_table
    return run_table(geometry_bench.Options(
        methods=args.methods, preset=args.preset, repeat=args.repeat, scaling=args.scaling,
        radii=args.radii, size=args.size, json_path=args.json, profile=args.profile,
        scenes=args.scene, scenes_dir=args.scenes_dir, geometry=not args.no_scenes,
        corpus=not args.no_corpus, svg=args.svg))
