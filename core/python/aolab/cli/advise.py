"""``aolab advise``: which method, at which settings, for this scene within a time budget
(aolab.study.advise)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import aolab

from ..study import advise, quick_reference
from ..study.results import json_safe
from ..util import files
from ..util.arguments import int_option, parse_budget
from ..util.files import check_paths
from ..util.progress import bar as progress_bar
from .common import RADIUS, gbuffer_files, mesh_files
from .options import add_follow_symlinks_option, threads_option


def add_parser(sub):
    a = sub.add_parser(
        "advise", help="which method and preset for this scene within a time budget",
        description="Runs every method's named presets (default, the study's, the tuned "
        "ones) on one scene, timed (per 1280x720 frame) and scored against the scene's Cycles "
        "reference when there is one, else against a quick reference (rtao at --rays rays, "
        "its noise stated), and names the most accurate configuration within each budget "
        "that is no worse on the whole frame than AO = 1 or its method's default "
        "(docs/comparison.md, \"Advise\").")
    a.add_argument("scene", metavar="SCENE",
                   help="a .blend, a build script .py or a reference_scenes name or folder "
                   "(rendered by Blender at --scale %% of its size, cached), or a G-buffer "
                   ".exr with its sidecar (used as it is)")
    a.add_argument("--budget", action="append", metavar="MS",
                   help="a time per 1280x720 frame, e.g. 16ms (repeatable; default: "
                   f"{', '.join(f'{b:g}ms' for b in advise.BUDGETS_MS)})")
    a.add_argument("--reference", default="auto",
                   help="auto (default: the Cycles reference when one is there, else the "
                   "quick one), cycles or quick")
    a.add_argument("--rays", type=int_option("--rays", quick_reference.MIN_RAYS, 65536),
                   default=quick_reference.QUICK_RAYS,
                   help=f"the quick reference's rays per pixel, {quick_reference.MIN_RAYS} to "
                   f"65536 (default {quick_reference.QUICK_RAYS})")
    a.add_argument("--scale", type=int_option("--scale", 1, 100),
                   help="render a scene at this %% of its output size, 1 to 100 (default "
                   f"{advise.DEFAULT_SCALE}, the panel's Resolution); not for a G-buffer")
    a.add_argument("--radius", type=RADIUS, help="AO distance R of a scene Blender renders, "
                   "finite > 0 (default: its manifest's, else its world's AO distance)")
    a.add_argument("--spp", type=int_option("--spp", 1, 16777216), default=advise.CYCLES_SPP,
                   help="samples of the cached Cycles reference looked for (default "
                   f"{advise.CYCLES_SPP})")
    a.add_argument("--methods", nargs="+", metavar="METHOD",
                   help="methods to run (default: every method but the bounds)")
    a.add_argument("--threads", type=threads_option(), default=0,
                   help="worker threads (0 = all cores)")
    a.add_argument("--cache", help="cache folder of the renders (default $AOLAB_CACHE or "
                   "~/.cache/aolab/references)")
    add_follow_symlinks_option(a)
    a.add_argument("--json", help="also write every configuration's scores and the advice "
                   "to this JSON file (not SCENE's own files nor --plot: refused before any "
                   "work)")
    a.add_argument("--plot", help="also write the accuracy-against-time front to this PNG "
                   "(not SCENE's own files nor --json)")
    return a


def run(args) -> int:
    """aolab advise: the advice per budget on stdout."""
    # Every value is checked before Blender starts; a bad one is one line, status 2.
    budgets = [parse_budget(b) for b in args.budget] if args.budget else \
        list(advise.BUDGETS_MS)
    if args.reference not in advise.REFERENCE_CHOICES:
        raise ValueError(f"--reference must be one of {', '.join(advise.REFERENCE_CHOICES)}, "
                         f"got {args.reference!r}")
    if args.plot and not args.plot.lower().endswith(".png"):
        raise ValueError(f"--plot must name a .png file, got {args.plot!r}")
    check_paths(files={"--json": args.json, "--plot": args.plot}, folders={"--cache": args.cache},
                reads=_scene_files(advise.scene_spec(args.scene)))
    known = aolab.methods()
    for m in args.methods or []:
        if m not in known:
            raise ValueError(f"method {m!r} is not one of {known}")
    name, g, radius, ref = advise.load(args.scene, scale=args.scale, radius=args.radius,
                                       reference=args.reference, rays=args.rays, spp=args.spp,
                                       threads=args.threads, cache=args.cache,
                                       progress=sys.stderr.isatty(),
                                       follow_symlinks=args.follow_symlinks)
    if ref.warning:
        print(f"aolab: warning: {' '.join(ref.warning.split())}", file=sys.stderr)
    bar = _Progress() if sys.stderr.isatty() else None
    try:
        result = advise.run(g, ref, radius, name=name, threads=args.threads,
                            methods=args.methods, budgets=budgets,
                            on_step=None if bar is None else bar.step)
    finally:
        if bar is not None:
            bar.close()
    print(f"aolab advise: {advise.headline(result)}")
    for note in result["notes"]:
        print(f"  note: {note}")
    for r in result["refused"]:
        print(f"  refused: {r['method']} {'/'.join(r['names'])}: {r['error']}")
    for b in budgets:
        for line in advise.advice_lines(result, b):
            print(line)
    outputs = []
    if args.json:
        data = {**result, "advice": {f"{b:g}ms": _numbers(advise.choose(result, b))
                                     for b in budgets}}
        outputs.append((args.json, json.dumps(json_safe(data), indent=1).encode()))
    if args.plot:
        image = advise.plot(result, budgets)
        outputs.append((args.plot, aolab.encode_image(args.plot, image)))
    files.write_together(outputs)
    return 0


def _scene_files(scene: Path) -> dict:
    """The files advise reads of its SCENE, {what: path}: a G-buffer with its sidecar and
    the .mesh beside it (the quick reference's triangles); a scene folder's own files; or
    the .blend or build script itself."""
    if scene.suffix.lower() == ".exr":
        return {**gbuffer_files(str(scene)),
                **mesh_files(scene.with_suffix(".mesh"), "the input's mesh")}
    if scene.is_dir():
        return {"the scene's file": sorted(p for p in scene.iterdir() if p.is_file())}
    return {"the scene": scene}


def _numbers(got: dict) -> dict:
    """A choice with its trials named by their numbers (results.json style)."""
    def num(t):
        return None if t is None else t["number"]
    return {"best": num(got["best"]), "as_good": [num(t) for t in got["as_good"]],
            "others": [num(t) for t in got["others"]], "fastest": num(got["fastest"]),
            "why": got["why"]}


class _Progress:
    """The progress bar over the configurations (advise.run's on_step)."""

    def __init__(self):
        self.tqdm = progress_bar(True, unit="config", leave=False)

    def step(self, i: int, n: int, config: dict) -> None:
        if self.tqdm is not None:
            self.tqdm.total, self.tqdm.n = n, i
            self.tqdm.set_description(f"{config['method']} {'/'.join(config['names'])}")

    def close(self) -> None:
        if self.tqdm is not None:
            self.tqdm.close()
