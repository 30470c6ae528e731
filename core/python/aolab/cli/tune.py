"""``aolab tune``: each method's settings searched for the tuned presets (aolab.study.tune,
docs/tuning.md)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..study import tune
from ..study.tune import DEFAULT_MAX_MS, DEFAULT_TRIALS
from ..util.arguments import float_option, int_option
from .options import (add_cluster_options, add_follow_symlinks_option, add_timing_options,
                      cluster_security, crop_of)


def add_parser(sub):
    max_trials = 100000
    t = sub.add_parser(
        "tune", help="search each method's settings: tuned presets per time budget",
        description="Searches every setting of each method (and the shared blur) with "
        "Optuna's multi-objective sampler for the Pareto front of occluded-region MAE against "
        "time on the reference scenes, and writes the presets tuned-50ms ... tuned-500ms, "
        "chosen within each budget on all scenes (whole-frame MAE no worse than AO = 1 on any "
        "scene nor than the default) and scored leave-one-family-out "
        "(docs/tuning.md). Trials are kept in DIR/tune.db: Ctrl-C keeps them and the same "
        "command resumes.")
    t.add_argument("--methods", nargs="+", metavar="METHOD",
                   help="methods to tune (default: every method but the bounds)")
    t.add_argument("--trials", type=int_option("--trials", 1, max_trials),
                   default=DEFAULT_TRIALS,
                   help=f"trials each method's study should have, 1 to {max_trials} (a rerun "
                   f"adds the missing ones; default {DEFAULT_TRIALS})")
    t.add_argument("--scenes", nargs="+", metavar="SCENE",
                   help="reference_scenes/<name> folders or names (default: every still scene, "
                   "the corpus)")
    t.add_argument("--out", default="out/tune", help="folder of tune.db (default out/tune)")
    t.add_argument("--seed", type=int_option("--seed", 0, 2**32 - 1), default=0,
                   help="the sampler's seed, 0 to 2^32 - 1 (default 0)")
    t.add_argument("--timeout", type=float_option("--timeout", lo_inclusive=True, unit="s"),
                   metavar="S", help="start no trial after S seconds, S >= 0 (all methods "
                   "together)")
    t.add_argument("--sampler", choices=("tpe", "nsga2"), default="tpe",
                   help="Optuna's multi-objective TPE (default) or NSGA-II")
    t.add_argument("--crop", metavar="WxH", help="tune on a centred crop of every scene "
                   "(tests, quick looks: times are then not those of the full frame)")
    t.add_argument("--scenes-dir", help="folder of the scenes (default as aolab compare)")
    t.add_argument("--presets-file", help="the tuned-presets JSON to update (default: the "
                   "checkout's core/python/aolab/tuned_presets.json for a run on every scene "
                   "at full size, else DIR/tuned_presets.json)")
    add_timing_options(t, repeat=3, warmup=1, repeat_help="timed runs (their median)",
                       warmup_help="untimed runs before the timed ones")
    t.add_argument("--max-ms", type=float_option("--max-ms", unit="ms"), default=DEFAULT_MAX_MS,
                   help="a configuration whose first run takes longer is timed by that run "
                   f"alone (ms > 0; default {DEFAULT_MAX_MS:g} ms: 2x the largest budget)")
    t.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar (default: when stderr is a terminal)")
    add_follow_symlinks_option(t)
    add_cluster_options(t, "score the trials", "scored as they are timed",
                        "aolab and the scenes at the same path; times are still measured "
                        "here, one configuration at a time")
    return t


def run(args) -> int:
    opts = tune.Options(
        methods=args.methods, trials=args.trials, scenes=args.scenes or [], out=Path(args.out),
        seed=args.seed, timeout=args.timeout, sampler=args.sampler, crop=crop_of(args.crop),
        scenes_dir=Path(args.scenes_dir) if args.scenes_dir else None,
        presets_file=Path(args.presets_file) if args.presets_file else None,
        timing=tune.Timing(args.warmup, args.repeat, args.threads, args.max_ms),
        progress=args.progress if args.progress is not None else sys.stderr.isatty(),
        workers=args.workers, scheduler=args.scheduler, security=cluster_security(args),
        follow_symlinks=args.follow_symlinks)
    return tune.run_command(opts)
