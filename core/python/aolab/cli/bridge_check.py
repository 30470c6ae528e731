"""``aolab bridge-check``: this Blender's G-buffer export and AO pass against the committed
references (aolab.checks.bridge_check)."""

from __future__ import annotations

from ..checks import bridge_check
from ..checks.bridge_check import CHECK_SPP
from ..util.arguments import int_option


def add_parser(sub):
    p = sub.add_parser(
        "bridge-check", help="this Blender's G-buffer export and AO pass against the "
        "committed references",
        description="Exports every committed scene again with the Blender at hand (G-buffer "
        "and Cycles AO pass, cached) and compares it with the committed reference: "
        "intrinsics exactly, depth and normals bit for bit or within a stated tolerance, the "
        "AO pass statistically against the committed Cycles rung at the same samples "
        "(docs/blender_bridge.md).")
    p.add_argument("scenes", nargs="*", metavar="NAME",
                   help="reference_scenes/<NAME> (default: every committed scene and frame)")
    p.add_argument("--spp", type=int_option("--spp", 1, 65536), default=CHECK_SPP,
                   help=f"samples of the AO pass (default {CHECK_SPP}, a committed rung)")
    p.add_argument("--cache", help="reference cache folder (default: as aolab reference)")
    p.add_argument("--out", default="out/bridge_check",
                   help="folder for agreement.md and agreement.json (default out/bridge_check)")
    p.add_argument("--update-doc", metavar="MD", help="also write the table into this Markdown "
                   "file (docs/blender_bridge.md), in the block of this Blender release")
    return p


def run(args) -> int:
    return bridge_check.run_check(args.scenes, spp=args.spp, cache=args.cache, out=args.out,
                                  update_doc=args.update_doc)
