"""``aolab limits``: the screen-space limit of each reference scene (aolab.study.limits)."""

from __future__ import annotations

from ..study import limits
from ..study.limits import RAYS, THICKNESS_R
from ..util.arguments import (MAX_THICKNESS_R, MAX_THREADS, checked_type, int_option,
                              parse_thickness)
from .options import add_follow_symlinks_option, threads_option


def add_parser(sub):
    p = sub.add_parser(
        "limits", help="compute the screen-space limit of each reference scene (committed)",
        description="Computes the screen-space limit, a bound, on each reference scene at several "
        "thicknesses (multiples of R) and writes reference_scenes/<scene>/limits/ "
        "(limits.json and one EXR each), which aolab compare reads. Up-to-date entries are "
        "kept; minutes per scene and thickness on 2 cores.")
    p.add_argument("scenes", nargs="*", metavar="SCENE",
                   help="reference_scenes/<name> folders or names (default: every scene)")
    p.add_argument("--thickness", nargs="+", metavar="T",
                   type=checked_type(parse_thickness, "--thickness"),
                   help=f"thicknesses in multiples of R, in (0, {MAX_THICKNESS_R:g}], inf = "
                   "height field (default "
                   + " ".join(f"{t:g}" for t in THICKNESS_R) + ")")
    p.add_argument("--rays", type=int_option("--rays", 1, 65536), default=RAYS,
                   help=f"rays per pixel, 1 to 65536 (default {RAYS})")
    p.add_argument("--threads", type=threads_option(), default=0,
                   help=f"worker threads, 0 to {MAX_THREADS} (0 = all cores)")
    p.add_argument("--scenes-dir", help="folder of the scenes (default as aolab compare)")
    p.add_argument("--force", action="store_true", help="recompute even if up to date")
    add_follow_symlinks_option(p)
    return p


def run(args) -> int:
    limits.compute_scenes(args.scenes, thickness=args.thickness, rays=args.rays,
                          threads=args.threads, force=args.force, scenes_dir=args.scenes_dir,
                          follow_symlinks=args.follow_symlinks)
    return 0
