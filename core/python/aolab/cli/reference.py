"""``aolab reference``: Cycles AO references rendered with Blender, cached (aolab.cycles).
The plans run in this process, or on a Dask cluster with --workers N or --scheduler ADDRESS:
the command chooses, so that aolab.cycles.run never imports aolab.cycles.cluster."""

from __future__ import annotations

from ..cycles import cluster, run as local
from ..cycles.plan import command_plans
from ..util.arguments import (MAX_SAMPLES, checked_type, int_list_option, int_option,
                              parse_frames)
from .common import RADIUS
from .options import add_cluster_options, add_follow_symlinks_option, cluster_security


def add_parser(sub):
    f = sub.add_parser("reference", help="render Cycles AO references with Blender (cached)",
                       description="Renders the G-buffer passes and the Cycles AO reference of "
                       "each scene (a .blend, a build script .py, or a reference_scenes/<name> "
                       "folder) in Blender in the background, into a cache; a repeated call is "
                       "served from the cache and an interrupted batch resumes.")
    f.add_argument("scenes", nargs="+", metavar="SCENE")
    f.add_argument("--spp", type=int_option("--spp", 1, MAX_SAMPLES),
                   help=f"reference samples, 1 to {MAX_SAMPLES} (default: manifest, else 1024)")
    f.add_argument("--radius", type=RADIUS, help="AO distance R, finite > 0 (default: "
                   "manifest, else the scene world's AO distance)")
    f.add_argument("--methods", nargs="*", help="methods the G-buffer is for (default: all); "
                   "they decide the passes")
    f.add_argument("--passes", help="explicit G-buffer passes, e.g. depth,normal")
    f.add_argument("--resolution", help="WxH, overriding the scene's")
    f.add_argument("--camera", help="camera object to render from (default: the scene camera)")
    f.add_argument("--gbuffer-samples", type=int_option("--gbuffer-samples", 1, MAX_SAMPLES),
                   default=1, help=f"samples of the G-buffer passes, 1 to {MAX_SAMPLES} "
                   "(default 1)")
    f.add_argument("--cache", help="cache folder (default $AOLAB_CACHE or "
                   "~/.cache/aolab/references)")
    f.add_argument("--out", help="also copy reference.exr/.json here (one folder per scene "
                   "when several)")
    f.add_argument("--peers", action="store_true", help="render the comparison peers instead "
                   "of the reference: Cycles at the --ladder samples (seed 1) and EEVEE (GTAO on "
                   "Blender 3.4, EEVEE Next on 4.2+) under xvfb-run, into peers.json + one "
                   "EXR each")
    f.add_argument("--ladder", type=int_list_option("--ladder", MAX_SAMPLES),
                   help="with --peers: samples, e.g. 1,4,16,64,256 (the default), or none "
                   "(EEVEE alone)")
    f.add_argument("--no-eevee", action="store_true", help="with --peers: skip EEVEE")
    f.add_argument("--force", action="store_true", help="render even if cached")
    f.add_argument("--quiet", action="store_true", help="no progress bar")
    add_follow_symlinks_option(f)
    f.add_argument("--frames", type=checked_type(parse_frames, "--frames"),
                   help="animation frames: N, START-END or START-END:STEP (one reference each, "
                   "copied to OUT/frames/NNNN; default: a sequence scene's manifest frames)")
    add_cluster_options(f, "render", "one job after another",
                        "aolab and Blender and the cache on shared storage")
    return f


def delivery(args) -> local.Delivery:
    """Where the results of `aolab reference` and `aolab mesh` go."""
    return local.Delivery(cache=args.cache, out=args.out, force=args.force, quiet=args.quiet)


def run(args) -> int:
    to = delivery(args)
    to.check()
    security = cluster_security(args)
    plans = command_plans(
        args.scenes, spp=args.spp, radius=args.radius, methods=args.methods, passes=args.passes,
        resolution=args.resolution, camera=args.camera, gbuffer_samples=args.gbuffer_samples,
        peers=args.peers, ladder=args.ladder, no_eevee=args.no_eevee, frames=args.frames,
        follow_symlinks=args.follow_symlinks)
    to.check_plans(plans)
    with local.holding(args.out, "aolab reference"):
        if args.scheduler is not None or args.workers > 1:
            return cluster.run_plans(plans, to, scheduler=args.scheduler, workers=args.workers,
                                     security=security)
        return local.run_plans(plans, to)
