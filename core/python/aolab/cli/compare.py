"""``aolab compare``: every method against the Cycles references, timed and scored, with a
report (aolab.study.compare, docs/comparison.md)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..raytracing import RTAO_LADDER
from ..study import compare
from ..util.arguments import MAX_SIDE, float_option, int_list_option, int_option
from .options import (add_cluster_options, add_follow_symlinks_option, add_timing_options,
                      cluster_security, crop_of)


def add_parser(sub):
    c = sub.add_parser(
        "compare", help="score every method against the Cycles references, timed: report",
        description="Runs every method (or --methods) at its quality presets (--sweep quick: "
        "the method's defaults, low, medium and the tuned presets; presets: also high and ultra; "
        "full: every preset and the full parameter "
        "grid) on each reference scene at the scene's R, times it (warm-up, median of "
        "--repeat runs; the blur apart) and scores it against the 1024-spp Cycles reference on "
        "the whole frame and on regions, beside the AO = 1 baseline and the scene's peers "
        "(Cycles at fewer samples, EEVEE). Writes DIR/report.html (its images and scripts "
        "in DIR/report_files/), results.csv and results.json (docs/comparison.md). Ctrl-C "
        "keeps the partial results.")
    c.add_argument("scenes", nargs="*", metavar="SCENE",
                   help="reference_scenes/<name> folders or names (default: the default "
                   "study's scenes, manifest \"default_study\"; --corpus: every scene)")
    c.add_argument("--corpus", action="store_true",
                   help="without SCENE: every scene with a reference.exr, the whole corpus "
                   "(about 2.5 times the default study's time: 13 min on 2 cores)")
    c.add_argument("--methods", nargs="+", metavar="METHOD",
                   help="methods to run (default: every method of aolab.methods() except "
                   "the bounds, such as screen_space_limit, which run only when named)")
    c.add_argument("--sweep", choices=("quick", "presets", "full"), default="quick")
    c.add_argument("--out", default="out/compare", help="output folder (default out/compare)")
    add_timing_options(c, repeat=3, warmup=1, repeat_help="timed runs per configuration")
    c.add_argument("--max-ms", type=float_option("--max-ms", unit="ms", allow_inf=True),
                   default=1000.0, help="a configuration whose first run takes longer is "
                   "timed by that run alone (ms > 0 or inf, default 1000)")
    c.add_argument("--budget-ms", type=float_option("--budget-ms", unit="ms"), default=1000.0,
                   help="time budget for the images: each method's best setting within it "
                   "(ms > 0, default 1000)")
    c.add_argument("--crop", metavar="WxH", help="score a centred crop of every scene (quick "
                   "looks, tests)")
    c.add_argument("--scenes-dir", help="folder of the scenes (default: ./reference_scenes or "
                   "the checkout's, or $AOLAB_SCENES)")
    c.add_argument("--image-width", type=int_option("--image-width", 1, MAX_SIDE), default=480,
                   help=f"width of the report's images, 1 to {MAX_SIDE} px (default 480)")
    c.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar (default: when stderr is a terminal)")
    c.add_argument("--rtao-rays", type=int_list_option("--rtao-rays", 65536),
                   default=",".join(str(n) for n in RTAO_LADDER),
                   help="rtao's rays per pixel on every scene with a mesh, comma-separated "
                   "integers in [1, 65536] (default " + ",".join(str(n) for n in RTAO_LADDER)
                   + "); 'none' runs no rtao")
    add_follow_symlinks_option(c)
    add_cluster_options(c, "score the configurations", "scored as they are timed",
                        "aolab and the scenes at the same path; times are still measured "
                        "here, one configuration at a time")
    return c


def run(args) -> int:
    opts = compare.Options(
        scenes=args.scenes, corpus=args.corpus, methods=args.methods or None,
        sweep=args.sweep, out=Path(args.out),
        threads=args.threads, warmup=args.warmup, repeat=args.repeat, budget_ms=args.budget_ms,
        max_ms=args.max_ms, crop=crop_of(args.crop),
        scenes_dir=Path(args.scenes_dir) if args.scenes_dir else None,
        progress=args.progress if args.progress is not None else sys.stderr.isatty(),
        image_width=args.image_width, rtao_ladder=tuple(args.rtao_rays),
        workers=args.workers, scheduler=args.scheduler, security=cluster_security(args),
        follow_symlinks=args.follow_symlinks)
    return compare.run_study(opts)
