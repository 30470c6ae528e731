"""``aolab radius-study``: HBAO, Pyramid HBAO and Scalable AO against the radius
(aolab.study.radius_study)."""

from __future__ import annotations

from ..study import radius_study
from ..study.radius_study import DEFAULT_RESOLUTION, DEFAULT_SCALES, DEFAULT_SCENES, DEFAULT_SPP
from ..util.arguments import MAX_SAMPLES, float_option, int_option
from .options import add_follow_symlinks_option, add_timing_options


def add_parser(sub):
    p = sub.add_parser(
        "radius-study", help="HBAO, Pyramid HBAO and Scalable AO against the radius",
        description="Repeats the Pyramid HBAO paper's comparison (§4, Tables 1a-1c, Fig. 8): "
        "each scene at several multiples of its R, a cached Cycles reference per radius "
        "(rendered on first use: about 35 min for the defaults on 2 cores), time without "
        "filters and MAE/SSIM with them.")
    p.add_argument("scenes", nargs="*", metavar="SCENE", default=list(DEFAULT_SCENES),
                   help="reference_scenes names (default: " + " ".join(DEFAULT_SCENES) + ")")
    p.add_argument("--scales", nargs="+", type=float_option("--scales", hi=64.0),
                   default=list(DEFAULT_SCALES),
                   help="multiples of each scene's R (default " +
                   " ".join(f"{s:g}" for s in DEFAULT_SCALES) + ")")
    p.add_argument("--resolution", default="x".join(map(str, DEFAULT_RESOLUTION)),
                   help="WxH of the references (default %(default)s)")
    p.add_argument("--spp", type=int_option("--spp", 1, MAX_SAMPLES), default=DEFAULT_SPP,
                   help=f"reference samples (default {DEFAULT_SPP})")
    add_timing_options(p, repeat=5, warmup=1)
    p.add_argument("--cache", help="reference cache (default as aolab reference)")
    p.add_argument("--scenes-dir", help="folder of the scenes (default as aolab compare)")
    p.add_argument("--out", default="out/radius_study", help="output folder")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_follow_symlinks_option(p)
    return p


def run(args) -> int:
    return radius_study.run_study(
        args.scenes, scales=args.scales, resolution=args.resolution, spp=args.spp,
        threads=args.threads, warmup=args.warmup, repeat=args.repeat, cache=args.cache,
        scenes_dir=args.scenes_dir, out=args.out, quiet=args.quiet,
        follow_symlinks=args.follow_symlinks)
