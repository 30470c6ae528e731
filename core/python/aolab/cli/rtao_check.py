"""``aolab rtao-check``: rtao at 1024 rays against the committed Cycles references
(aolab.checks.rtao_check)."""

from __future__ import annotations

from ..checks import rtao_check
from ..checks.rtao_check import CHECK_RAYS
from ..util.arguments import int_option
from .options import threads_option


def add_parser(sub):
    p = sub.add_parser(
        "rtao-check", help="rtao at 1024 rays against the committed Cycles references",
        description="Traces every committed scene with rtao at 1024 rays per pixel (cached) "
        "and compares it with its Cycles 1024-spp reference: MAE and bias against the "
        "reference's noise floor, per region, and where the largest difference sits "
        "(docs/blender_bridge.md).")
    p.add_argument("scenes", nargs="*", metavar="SCENE",
                   help="reference_scenes/<name> folders or names (default: every scene with a "
                   "reference.exr and a reference.mesh)")
    p.add_argument("--rays", type=int_option("--rays", 1, 65536), default=CHECK_RAYS,
                   help=f"rays per pixel (default {CHECK_RAYS})")
    p.add_argument("--seed", type=int_option("--seed", 0, 2**31 - 1), default=0)
    p.add_argument("--threads", type=threads_option(), default=0)
    p.add_argument("--out", default="out/rtao_check", help="folder for agreement.md, "
                   "agreement.json and the difference images (default out/rtao_check)")
    p.add_argument("--update-doc", metavar="MD", help="also replace the generated block of this "
                   "Markdown file (docs/blender_bridge.md) with the table")
    return p


def run(args) -> int:
    return rtao_check.run_check(args.scenes, rays=args.rays, seed=args.seed,
                                threads=args.threads, out=args.out, update_doc=args.update_doc)
