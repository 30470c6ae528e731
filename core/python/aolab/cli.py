"""The ``aolab`` command.

    aolab methods                         list the methods and their settings
    aolab analytic NAME OUT.exr           write an analytic scene's G-buffer (+ sidecar)
    aolab run METHOD INPUT [options]      compute AO for a G-buffer, write EXR + PNG, score it
    aolab bench [options]                 time a method (median of repeated runs)
    aolab reference SCENE... [options]    render Cycles AO references with Blender (cached)
    aolab limits [SCENE...] [options]     compute the screen-space limit of each scene (committed)
    aolab compare [SCENE...] [options]    score every method against the references: report
    aolab presets [METHOD...]             the named presets of each method and their settings
    aolab tune [options]                  search each method's settings for the Pareto front

INPUT is a G-buffer EXR with its sidecar JSON, or ``analytic:NAME`` for a built-in scene.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import aolab

from .scoring import metrics_mask
from .settings import describe_value, parse_assignments


def _key_values(pairs: list[str], method: str | None = None) -> dict:
    """--set / --param KEY=VALUE items as a dict: numbers, bools, and a choice setting's name
    (or any other text, which aolab.compute then rejects, naming what is valid)."""
    try:
        return parse_assignments(pairs, method)
    except ValueError as e:
        raise SystemExit(f"aolab: {e}") from None


def _load_input(spec: str, radius: float | None, width: int, height: int):
    """A G-buffer from an EXR path or ``analytic:NAME``; returns (gbuffer, radius)."""
    if spec.startswith("analytic:"):
        params = {"radius": radius} if radius is not None else {}
        g = aolab.analytic_scene(spec.split(":", 1)[1], width, height, **params)
        return g, radius if radius is not None else 1.0
    path = Path(spec)
    if not path.exists():
        raise SystemExit(f"aolab: no such G-buffer file: {spec}")
    g = aolab.load_gbuffer(path)
    if radius is None:
        radius = g.sidecar.get("ao_distance")
        if radius is None or not np.isfinite(radius):
            raise SystemExit("aolab: the sidecar has no ao_distance; pass --radius")
    return g, float(radius)


def cmd_methods(args) -> int:
    for name in aolab.methods():
        info = aolab.method_info(name)
        if args.json:
            continue
        print(f"{name}: {info['title']} ({info['paper']})")
        reads = ["depth"] + (["normal"] if info["needs_normal"] else []) + \
            (["color"] if info["needs_color"] else [])
        print(f"  reads: {', '.join(reads)}")
        for s in info["settings"]:
            print(f"  {s['name']:<22} {s['type']:<6} default {s['default']!s:<8} "
                  f"{describe_value(s)}  {s['description']}")
    if args.json:
        print(json.dumps([aolab.method_info(n) for n in aolab.methods()], indent=2))
    return 0


def cmd_analytic(args) -> int:
    params = _key_values(args.param)
    if args.radius is not None:
        params["radius"] = args.radius
    g = aolab.analytic_scene(args.name, args.width, args.height, **params)
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    aolab.save_gbuffer(out, g, reference=g.reference, sidecar=g.sidecar)
    print(f"wrote {out} and {out.with_suffix('.json')} ({args.width}x{args.height}, "
          f"radius {params.get('radius', 1.0)})")
    return 0


def cmd_run(args) -> int:
    g, radius = _load_input(args.input, args.radius, args.width, args.height)
    settings = _key_values(args.set, args.method)
    kwargs = dict(radius=radius, threads=args.threads, preset=args.preset, blur=args.blur,
                  blur_sigma=args.blur_sigma, blur_taps=args.blur_taps, **settings)
    t0 = time.perf_counter()
    ao = aolab.compute(args.method, g, **kwargs)
    elapsed = time.perf_counter() - t0
    out = Path(args.out) if args.out else Path(f"{args.method}_ao")
    out.parent.mkdir(parents=True, exist_ok=True)
    aolab.write_image(out.with_suffix(".exr"), ao)
    aolab.write_image(out.with_suffix(".png"), ao)
    result = {"method": args.method, "input": args.input, "width": g.width, "height": g.height,
              "radius": radius, "preset": args.preset, "settings": settings,
              "threads": args.threads, "seconds": elapsed, "output": str(out.with_suffix(".exr"))}
    print(f"{args.method}: {g.width}x{g.height}, radius {radius:g}, {elapsed * 1000:.1f} ms "
          f"-> {out.with_suffix('.exr')}, {out.with_suffix('.png')}")
    mask = metrics_mask(g)
    if ao.ndim == 3:
        print("  RGB result (colour bleeding): written as an image, not scored")
    elif mask is not None:
        m = aolab.metrics(ao, g.reference, mask)
        result["metrics"] = m
        print(f"  against the reference on {m['count']} pixels: MAE {m['mae']:.4f}  "
              f"SSIM {m['ssim']:.4f}  RMSE {m['rmse']:.4f}  PSNR {m['psnr']:.2f} dB  "
              f"bias {m['bias']:+.4f}")
    else:
        print("  no reference AO in the input: nothing to score")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2, default=float))
    return 0


def cmd_bench(args) -> int:
    g, radius = _load_input(args.input, args.radius, args.width, args.height)
    settings = _key_values(args.set, args.method)
    for _ in range(args.warmup):
        aolab.compute(args.method, g, radius=radius, threads=args.threads, **settings)
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        aolab.compute(args.method, g, radius=radius, threads=args.threads, **settings)
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    spread = (max(times) - min(times)) if len(times) > 1 else 0.0
    cpu = platform.processor() or platform.machine()
    print(f"{args.method} on {args.input} {g.width}x{g.height}, radius {radius:g}, "
          f"threads {args.threads or os.cpu_count()}, {cpu}: "
          f"median {med * 1000:.1f} ms over {args.repeat} runs (spread {spread * 1000:.1f} ms)")
    return 0


def cmd_reference(args) -> int:
    from . import reference
    try:
        return reference.main(args)
    except reference.ReferenceError as e:
        print(f"aolab reference: {e}", file=sys.stderr)
        return 2


def cmd_presets(args) -> int:
    every = {m: aolab.presets(m) for m in args.methods or aolab.methods()}
    if args.json:
        print(json.dumps(every, indent=2))
        return 0

    def shown(v):   # floats at the single precision the methods keep
        return f"{v:.7g}" if isinstance(v, float) else str(v)
    for method, named in every.items():
        print(f"{method}:")
        for name, values in named.items():
            print(f"  {name:<14} " + ", ".join(f"{k}={shown(v)}" for k, v in values.items()))
    return 0


def cmd_tune(args) -> int:
    from . import tune
    return tune.main(args)


def cmd_limits(args) -> int:
    from . import limits
    return limits.main(args)


def cmd_compare(args) -> int:
    from . import compare
    return compare.main(args)


def add_compare_parser(sub) -> None:
    c = sub.add_parser(
        "compare", help="score every method against the Cycles references, timed: report",
        description="Runs every method (or --methods) at its quality presets (--sweep quick: "
        "the method's defaults, low, medium and the tuned presets; presets: also high and ultra; "
        "full: every preset and the full parameter "
        "grid) on each reference scene at the scene's R, times it (warm-up, median of "
        "--repeat runs; the blur apart) and scores it against the 1024-spp Cycles reference on "
        "the whole frame and on regions, beside the AO = 1 baseline and the scene's peers "
        "(Cycles at fewer samples, EEVEE). Writes DIR/report.html, results.csv and "
        "results.json (docs/comparison.md). Ctrl-C keeps the partial results.")
    c.add_argument("scenes", nargs="*", metavar="SCENE",
                   help="reference_scenes/<name> folders or names (default: every scene with a "
                   "reference.exr)")
    c.add_argument("--methods", nargs="+", metavar="METHOD",
                   help="methods to run (default: every method of aolab.methods() except "
                   "the oracles, such as screen_space_limit, which run only when named)")
    c.add_argument("--sweep", choices=("quick", "presets", "full"), default="quick")
    c.add_argument("--out", default="out/compare", help="output folder (default out/compare)")
    c.add_argument("--threads", type=int, default=0, help="worker threads (0 = all cores)")
    c.add_argument("--repeat", type=int, default=3, help="timed runs per configuration")
    c.add_argument("--warmup", type=int, default=1, help="untimed runs before them")
    c.add_argument("--budget-ms", type=float, default=1000.0,
                   help="time budget for the images: each method's best setting within it")
    c.add_argument("--crop", metavar="WxH", help="score a centred crop of every scene (quick "
                   "looks, tests)")
    c.add_argument("--scenes-dir", help="folder of the scenes (default: ./reference_scenes or "
                   "the checkout's, or $AOLAB_SCENES)")
    c.add_argument("--image-width", type=int, default=480, help="width of the report's images")
    c.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar (default: when stderr is a terminal)")
    c.set_defaults(func=cmd_compare)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="aolab", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    m = sub.add_parser("methods", help="list the methods and their settings")
    m.add_argument("--json", action="store_true", help="print the descriptions as JSON")
    m.set_defaults(func=cmd_methods)

    def input_options(q):
        q.add_argument("--radius", type=float, help="view-space radius R (default: the "
                       "sidecar's ao_distance; 1 for analytic scenes)")
        q.add_argument("--width", type=int, default=1280, help="analytic scenes: width")
        q.add_argument("--height", type=int, default=720, help="analytic scenes: height")
        q.add_argument("--threads", type=int, default=0, help="worker threads (0 = all cores)")
        q.add_argument("--set", action="append", metavar="KEY=VALUE",
                       help="a method setting, e.g. --set directions=16; a choice by "
                       "name, e.g. --set falloff=clipped (repeatable)")

    a = sub.add_parser("analytic", help="write an analytic scene's G-buffer EXR and sidecar")
    a.add_argument("name", choices=aolab.analytic_scene_names())
    a.add_argument("output", help="output .exr path (the sidecar goes beside it)")
    a.add_argument("--width", type=int, default=1280)
    a.add_argument("--height", type=int, default=720)
    a.add_argument("--radius", type=float, help="R of the closed-form reference (default 1)")
    a.add_argument("--param", action="append", metavar="KEY=VALUE",
                   help="scene parameter, e.g. --param tilt=60 (repeatable)")
    a.set_defaults(func=cmd_analytic)

    r = sub.add_parser("run", help="compute AO for a G-buffer and score it")
    r.add_argument("method", choices=aolab.methods())
    r.add_argument("input", help="G-buffer .exr (with sidecar) or analytic:NAME")
    input_options(r)
    r.add_argument("--out", help="output path without extension (default METHOD_ao)")
    r.add_argument("--preset", help="a named preset of the method (`aolab presets METHOD`: "
                   "default, low, medium, high, ultra, tuned-...); --set and --blur/--no-blur "
                   "override it")
    r.add_argument("--blur", action=argparse.BooleanOptionalAction, default=None,
                   help="apply the separable Gaussian blur (default: the preset's, else off)")
    r.add_argument("--blur-sigma", type=float, default=1.5)
    r.add_argument("--blur-taps", type=int, default=5)
    r.add_argument("--json", help="also write the result (timing, metrics) to this JSON file")
    r.set_defaults(func=cmd_run)

    b = sub.add_parser("bench", help="median time of a method over repeated runs")
    b.add_argument("method", choices=aolab.methods())
    b.add_argument("input", nargs="?", default="analytic:blocks")
    input_options(b)
    b.add_argument("--repeat", type=int, default=7)
    b.add_argument("--warmup", type=int, default=1)
    b.set_defaults(func=cmd_bench)

    f = sub.add_parser("reference", help="render Cycles AO references with Blender (cached)",
                       description="Renders the G-buffer passes and the Cycles AO reference of "
                       "each scene (a .blend, a build script .py, or a reference_scenes/<name> "
                       "folder) in Blender in the background, into a cache; a repeated call is "
                       "served from the cache and an interrupted batch resumes.")
    f.add_argument("scenes", nargs="+", metavar="SCENE")
    f.add_argument("--spp", type=int, help="reference samples (default: manifest, else 1024)")
    f.add_argument("--radius", type=float, help="AO distance R (default: manifest, else the "
                   "scene world's AO distance)")
    f.add_argument("--methods", nargs="*", help="methods the G-buffer is for (default: all); "
                   "they decide the passes")
    f.add_argument("--passes", help="explicit G-buffer passes, e.g. depth,normal")
    f.add_argument("--resolution", help="WxH, overriding the scene's")
    f.add_argument("--camera", help="camera object to render from (default: the scene camera)")
    f.add_argument("--gbuffer-samples", type=int, default=1)
    f.add_argument("--cache", help="cache folder (default $AOLAB_CACHE or "
                   "~/.cache/aolab/references)")
    f.add_argument("--out", help="also copy reference.exr/.json here (one folder per scene "
                   "when several)")
    f.add_argument("--peers", action="store_true", help="render the comparison peers instead "
                   "of the reference: Cycles at the --ladder samples (seed 1) and EEVEE's GTAO "
                   "under xvfb-run, into peers.json + one EXR each")
    f.add_argument("--ladder", help="with --peers: samples, e.g. 1,4,16,64,256 (the default)")
    f.add_argument("--no-eevee", action="store_true", help="with --peers: skip EEVEE")
    f.add_argument("--force", action="store_true", help="render even if cached")
    f.add_argument("--quiet", action="store_true", help="no progress bar")
    f.set_defaults(func=cmd_reference)

    from .limits import add_limits_parser
    add_limits_parser(sub).set_defaults(func=cmd_limits)
    add_compare_parser(sub)

    q = sub.add_parser("presets", help="the named presets of each method and their settings")
    q.add_argument("methods", nargs="*", metavar="METHOD", help="methods (default: all)")
    q.add_argument("--json", action="store_true", help="print them as JSON")
    q.set_defaults(func=cmd_presets)

    from .tune import add_tune_parser
    add_tune_parser(sub).set_defaults(func=cmd_tune)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, FileNotFoundError) as e:
        print(f"aolab: {e}", file=sys.stderr)
        return 2
