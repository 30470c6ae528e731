"""The ``aolab`` command.

    aolab methods                         list the methods and their settings
    aolab analytic NAME OUT.exr           write an analytic scene's G-buffer (+ sidecar)
    aolab run METHOD INPUT [options]      compute AO for a G-buffer, write EXR + PNG, score it
    aolab rtao INPUT [options]            ray-traced AO against the scene's triangles (Embree)
    aolab rtao-check [SCENE...]           rtao at 1024 rays against the committed references
    aolab bridge-check [SCENE...]         this Blender's export against the committed references
    aolab bench [options]                 time a method (median of repeated runs)
    aolab bench-table [METHOD...]         every method's scalar code against its SIMD kernel
    aolab reference SCENE... [options]    render Cycles AO references with Blender (cached)
    aolab mesh SCENE... [options]         export each scene's triangles as rendered (cached)
    aolab limits [SCENE...] [options]     compute the screen-space limit of each scene (committed)
    aolab compare [SCENE...] [options]    score every method against the references: report
    aolab presets [METHOD...]             the named presets of each method and their settings
    aolab tune [options]                  search each method's settings for the Pareto front
    aolab radius-study [SCENE...]         HBAO, Pyramid HBAO and Scalable AO against the radius

INPUT is a G-buffer EXR with its sidecar JSON, or ``analytic:NAME`` for a built-in scene.

Errors: bad input never shows a traceback. A bad option value is refused when the command
line is read (the usage line, then ``argument --OPT: --OPT must be ..., got VALUE``; exit
status 2); any error while a command runs prints one line ``aolab: <message>`` (the
exception's type name when it has no message) on stderr and exits with status 2. Ctrl-C
exits with status 130 (compare, tune and reference keep their partial work first).
``aolab --debug COMMAND ...`` shows the Python traceback instead.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import statistics
import sys
import time
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np

import aolab

from . import files
from .options import (MAX_RUNS, MAX_SAMPLES, MAX_SIDE, MAX_THREADS, add_timing_options, check_paths,
                      checked_type, float_option, int_list_option, int_option,
                      size_option, threads_option)
from .raytracing import DEFAULT_RAYS as RTAO_DEFAULT_RAYS
from .raytracing import RTAO_LADDER
from .reference import parse_frames
from .scoring import metrics_mask
from .settings import describe_value, parse_assignments


# --- errors ---------------------------------------------------------------------------------

def error_message(e: BaseException) -> str:
    """One line for ``aolab: <message>``: the exception's message with its lines joined; an
    OSError as its reason and file; the type name in front unless the exception is a plain
    ValueError (the library's errors), an OSError or a SystemExit, and alone when there is no
    message (a MemoryError)."""
    if isinstance(e, OSError) and e.strerror:
        files = [f for f in (e.filename, getattr(e, "filename2", None)) if f is not None]
        text = e.strerror + "".join(
            f": {os.fsdecode(f) if isinstance(f, bytes) else str(f)!r}" for f in files)
    elif isinstance(e, SystemExit):
        text = "" if e.code is None else str(e.code)
    else:
        try:
            text = str(e)
        except Exception:   # a __str__ that fails itself
            text = ""
    text = " ".join(text.split())   # one line
    if text.startswith("aolab: "):
        text = text[len("aolab: "):]
    if not text:
        return type(e).__name__
    if type(e) is ValueError or isinstance(e, (OSError, SystemExit)):
        return text
    return f"{type(e).__name__}: {text}"


def _report(message: str) -> None:
    """``aolab: message`` on stderr, whatever the terminal's encoding."""
    line = f"aolab: {message}\n"
    encoding = getattr(sys.stderr, "encoding", None) or "utf-8"
    try:
        line = line.encode(encoding, "backslashreplace").decode(encoding)
    except LookupError:
        pass
    sys.stderr.write(line)
    sys.stderr.flush()


def _one_line_warnings(show):
    """A ``warnings.showwarning`` that prints an aolab warning (RtaoRangeWarning) as one line
    ``aolab: warning: <message>``, like the command's errors, and passes any other to
    ``show``."""
    def show_warning(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, aolab.RtaoRangeWarning):
            _report("warning: " + " ".join(str(message).split()))
        else:
            show(message, category, filename, lineno, file, line)
    return show_warning


def _key_values(pairs: list[str] | None, method: str | None = None) -> dict:
    """--set / --param KEY=VALUE items as a dict: numbers, bools, and a choice setting's name
    (or any other text, which aolab.compute then rejects, naming what is valid). With a
    method, a setting's text that is no value of its type is a ValueError naming it, and so
    is a key that is one of the command's own options (--set radius=2: use --radius)."""
    values = parse_assignments(pairs, method)
    if method is not None:
        for key in values:
            if key in _OWN_OPTIONS:
                raise ValueError(f"--set {key}=...: {key} is not set with --set; use "
                                 f"{_OWN_OPTIONS[key]}")
    return values


#: Keywords of aolab.compute that the commands set from their own options.
_OWN_OPTIONS = {"radius": "--radius", "threads": "--threads", "preset": "--preset",
                "blur": "--blur / --no-blur", "blur_sigma": "--blur-sigma",
                "blur_taps": "--blur-taps", "progress": "no option (it is not a setting)"}


def _load_input(spec: str, radius: float | None, width: int, height: int):
    """A G-buffer from an EXR path or ``analytic:NAME``; returns (gbuffer, radius)."""
    if spec.startswith("analytic:"):
        params = {"radius": radius} if radius is not None else {}
        g = aolab.analytic_scene(spec.split(":", 1)[1], width, height, **params)
        return g, radius if radius is not None else 1.0
    path = files.regular_file(spec, "G-buffer")
    g = aolab.load_gbuffer(path)
    if radius is None:
        radius = g.sidecar.get("ao_distance")
        if not isinstance(radius, (int, float)) or not (np.isfinite(radius) and radius > 0):
            raise ValueError(f"the sidecar of {spec} has no ao_distance > 0 (got {radius!r}); "
                             "pass --radius")
    return g, float(radius)


#: What aolab run writes: one image per suffix.
OUT_SUFFIXES = (".exr", ".png")


def _existing_ancestor_is_not_a_folder(path: Path) -> Path | None:
    """The first existing ancestor of ``path`` (itself excluded) that is not a folder."""
    for parent in path.parents:
        if parent.exists():
            return None if parent.is_dir() else parent
        if parent.is_symlink():   # a dangling link
            return parent
    return None


def _output_stem(out: str | None, method: str) -> Path:
    """The path aolab run writes STEM.exr and STEM.png to: METHOD_ao by default, inside
    ``out`` when it is an existing folder or ends in a slash, else ``out`` without its .exr
    or .png suffix; another suffix (out.txt) is a ValueError naming it, and so is a path
    under a file. Creates the folders."""
    default = f"{method}_ao"
    if not out:
        return Path(default)
    if out.endswith(("/", os.sep)) or Path(out).is_dir():
        folder, stem = Path(out), Path(out) / default
    else:
        stem = Path(out)
        suffix = stem.suffix
        if suffix.lower() in OUT_SUFFIXES:
            stem = stem.with_suffix("")
        elif re.fullmatch(r"\.[A-Za-z][A-Za-z0-9]*", suffix):
            raise ValueError(f"--out is the output path without extension (aolab run writes "
                             f"OUT.exr and OUT.png), got {out!r} with the suffix {suffix!r}")
        folder = stem.parent
        if stem.is_dir():
            raise ValueError(f"--out {out!r}: {stem} is a folder")
    blocker = _existing_ancestor_is_not_a_folder(stem)
    if blocker is not None:
        raise ValueError(f"--out {out!r}: {blocker} is a file, not a folder")
    for suffix in OUT_SUFFIXES:
        target = stem.parent / (stem.name + suffix)
        if target.is_dir():
            raise ValueError(f"--out {out!r}: {target} is a folder")
    folder.mkdir(parents=True, exist_ok=True)
    return stem


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
    out = Path(args.output)
    blocker = _existing_ancestor_is_not_a_folder(out)
    if blocker is not None:
        raise ValueError(f"output {args.output!r}: {blocker} is a file, not a folder")
    if out.is_dir() or args.output.endswith(("/", os.sep)):
        raise ValueError(f"output must be an .exr file path, got {args.output!r}, a folder")
    g = aolab.analytic_scene(args.name, args.width, args.height, **params)
    out.parent.mkdir(parents=True, exist_ok=True)
    aolab.save_gbuffer(out, g, reference=g.reference, sidecar=g.sidecar)
    print(f"wrote {out} and {out.with_suffix('.json')} ({args.width}x{args.height}, "
          f"radius {params.get('radius', 1.0)})")
    return 0


def _scores(g, ao) -> tuple[dict | None, str]:
    """``ao``'s metrics against the G-buffer's AO pass where it has one, and the line that
    reports them or says why nothing is scored."""
    mask = metrics_mask(g)
    if ao.ndim == 3:
        return None, "  RGB result (colour bleeding): written as an image, not scored"
    if mask is not None:
        m = aolab.metrics(ao, g.reference, mask)
        return m, (f"  against the reference on {m['count']} pixels: MAE {m['mae']:.4f}  "
                   f"SSIM {m['ssim']:.4f}  RMSE {m['rmse']:.4f}  PSNR {m['psnr']:.2f} dB  "
                   f"bias {m['bias']:+.4f}")
    if getattr(g, "reference", None) is not None:
        return None, ("  the input's AO pass has no finite value on a geometry pixel (all "
                      "NaN): nothing to score")
    return None, "  no reference AO in the input: nothing to score"


def _write_result(g, ao, stem: Path, result: dict, json_path: str | None, header: str) -> None:
    """STEM.exr, STEM.png and the --json file, put in place together (files.write_together:
    a full disk leaves the earlier ones), then the header line and the scores printed."""
    exr, png = (stem.parent / (stem.name + suffix) for suffix in OUT_SUFFIXES)
    metrics, line = _scores(g, ao)
    if metrics is not None:
        result["metrics"] = metrics
    result["output"] = str(exr)
    outputs = [(exr, aolab.encode_image(exr, ao)), (png, aolab.encode_image(png, ao))]
    if json_path:
        outputs.append((json_path, json.dumps(result, indent=2, default=float).encode()))
    files.write_together(outputs)
    print(f"{header} -> {exr}, {png}")
    print(line)


def cmd_run(args) -> int:
    settings = _key_values(args.set, args.method)
    check_paths(files={"--json": args.json})
    g, radius = _load_input(args.input, args.radius, args.width, args.height)
    out = _output_stem(args.out, args.method)
    kwargs = dict(radius=radius, threads=args.threads, preset=args.preset, blur=args.blur,
                  blur_sigma=args.blur_sigma, blur_taps=args.blur_taps, **settings)
    t0 = time.perf_counter()
    ao = aolab.compute(args.method, g, **kwargs)
    elapsed = time.perf_counter() - t0
    result = {"method": args.method, "input": args.input, "width": g.width, "height": g.height,
              "radius": radius, "preset": args.preset, "settings": settings,
              "threads": args.threads, "seconds": elapsed}
    _write_result(g, ao, out, result, args.json,
                  f"{args.method}: {g.width}x{g.height}, radius {radius:g}, "
                  f"{elapsed * 1000:.1f} ms")
    return 0


def cmd_rtao(args) -> int:
    """aolab rtao: ray-traced AO of a G-buffer against its scene's triangles."""
    check_paths(files={"--json": args.json})
    spec = args.input
    if not spec.startswith("analytic:") and Path(spec).is_dir():
        spec = str(Path(spec) / "reference.exr")   # a reference_scenes/<name> folder
    g, radius = _load_input(spec, args.radius, args.width, args.height)
    unknown = args.allow_unknown_scene
    if args.mesh:
        mesh = aolab.load_mesh(files.regular_file(args.mesh, "mesh"))
    elif spec.startswith("analytic:"):   # the scene's own planes, made here
        name = spec.split(":", 1)[1]
        mesh = SimpleNamespace(info={})
        mesh.vertices, mesh.triangles = aolab.analytic_scene_mesh(name)
    else:
        mesh = aolab.mesh_for_gbuffer(g, allow_unknown_scene=unknown)
    out = _output_stem(args.out, "rtao")
    scene = aolab.ray_scene(mesh, g, threads=args.threads, allow_unknown_scene=unknown)
    t0 = time.perf_counter()
    ao = aolab.rtao(g, scene, radius=radius, rays=args.rays, seed=args.seed,
                    threads=args.threads, allow_unknown_scene=unknown)
    elapsed = time.perf_counter() - t0
    result = {"method": "rtao", "input": args.input, "width": g.width, "height": g.height,
              "radius": radius, "rays": args.rays, "seed": args.seed, "threads": args.threads,
              "triangles": scene.triangles, "build_seconds": scene.build_seconds,
              "seconds": elapsed}
    _write_result(g, ao, out, result, args.json,
                  f"rtao: {g.width}x{g.height}, radius {radius:g}, {args.rays} rays per pixel, "
                  f"{scene.triangles} triangles: BVH {scene.build_seconds * 1000:.1f} ms, rays "
                  f"{elapsed * 1000:.1f} ms")
    return 0


def cmd_bridge_check(args) -> int:
    from . import bridge_check
    return bridge_check.main(args)


def cmd_rtao_check(args) -> int:
    from . import rtao_check
    return rtao_check.main(args)


def cmd_bench(args) -> int:
    settings = _key_values(args.set, args.method)
    g, radius = _load_input(args.input, args.radius, args.width, args.height)
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


def cmd_bench_table(args) -> int:
    from . import kernel_bench
    return kernel_bench.main(args)


def cmd_reference(args) -> int:
    """aolab reference: the plans rendered here, or on a Dask cluster with --workers N or
    --scheduler ADDRESS (a ReferenceError is an `aolab: ...` message like any other)."""
    from . import reference
    plans = reference.command_plans(args)
    with reference.holding(args.out, "aolab reference"):
        if args.scheduler or args.workers > 1:
            from . import cluster
            return cluster.run_plans(plans, args)
        return reference.run_plans(plans, args)


def cmd_mesh(args) -> int:
    from . import reference
    return reference.mesh_main(args)


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


def cmd_radius_study(args) -> int:
    from . import radius_study
    return radius_study.main(args)


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
    c.set_defaults(func=cmd_compare)


class Parser(argparse.ArgumentParser):
    """argparse with two gaps closed: Python 3.11's argparse drops a value ``--`` given as
    ``--OPT=--`` and stores an empty list without calling the option's ``type``, so the
    range check never runs. Here ``--OPT=--`` is refused like any other bad value. And its
    "unrecognized arguments" message shows them as typed, so a newline in one split the
    message over lines; here it is one line. Subcommand parsers are of this class too
    (add_subparsers makes them of the parent's class), each checking its own options."""

    def error(self, message):
        super().error(message.replace("\r", "\\r").replace("\n", "\\n"))

    def parse_known_args(self, args=None, namespace=None):
        for text in sys.argv[1:] if args is None else args:
            if text == "--":   # what follows is positional
                break
            option = text[:-3] if text.endswith("=--") else None
            if option in self._option_string_actions:
                self.error(f"argument {option}: expected one value, got '--'")
        return super().parse_known_args(args, namespace)


def build_parser() -> argparse.ArgumentParser:
    p = Parser(prog="aolab", description=__doc__,
               formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--debug", action="store_true",
                   help="show the Python traceback of an error instead of the one-line "
                   "'aolab: <message>' (give it before the command: aolab --debug run ...)")
    sub = p.add_subparsers(dest="command", required=True)
    radius = float_option("--radius", unit="view-space units")
    side = {name: int_option(name, 1, MAX_SIDE) for name in ("--width", "--height")}

    m = sub.add_parser("methods", help="list the methods and their settings")
    m.add_argument("--json", action="store_true", help="print the descriptions as JSON")
    m.set_defaults(func=cmd_methods)

    def input_options(q, threads=True, settings=True):
        q.add_argument("--radius", type=radius, help="view-space radius R, finite > 0 "
                       "(default: the sidecar's ao_distance; 1 for analytic scenes)")
        q.add_argument("--width", type=side["--width"], default=1280,
                       help=f"analytic scenes: width, 1 to {MAX_SIDE} (default 1280)")
        q.add_argument("--height", type=side["--height"], default=720,
                       help=f"analytic scenes: height, 1 to {MAX_SIDE} (default 720)")
        if threads:
            q.add_argument("--threads", type=threads_option(), default=0,
                           help=f"worker threads, 0 to {MAX_THREADS} (0 = all cores)")
        if not settings:
            return
        q.add_argument("--set", action="append", metavar="KEY=VALUE",
                       help="a method setting, e.g. --set directions=16; a choice by "
                       "name, e.g. --set falloff=clipped (repeatable; `aolab methods` lists "
                       "them). R is not a setting here: --set radius=... is refused, use "
                       "--radius")

    a = sub.add_parser("analytic", help="write an analytic scene's G-buffer EXR and sidecar")
    a.add_argument("name", choices=aolab.analytic_scene_names())
    a.add_argument("output", help="output .exr path (the sidecar goes beside it)")
    a.add_argument("--width", type=side["--width"], default=1280,
                   help=f"1 to {MAX_SIDE} (default 1280)")
    a.add_argument("--height", type=side["--height"], default=720,
                   help=f"1 to {MAX_SIDE} (default 720)")
    a.add_argument("--radius", type=radius, help="R of the closed-form reference, finite > 0 "
                   "(default 1)")
    a.add_argument("--param", action="append", metavar="KEY=VALUE",
                   help="scene parameter, e.g. --param tilt=60 (repeatable)")
    a.set_defaults(func=cmd_analytic)

    r = sub.add_parser("run", help="compute AO for a G-buffer and score it")
    r.add_argument("method", choices=aolab.methods())
    r.add_argument("input", help="G-buffer .exr (with sidecar) or analytic:NAME")
    input_options(r)
    r.add_argument("--out", help="output path without extension: writes OUT.exr and OUT.png "
                   "(a trailing .exr or .png is dropped; another extension, such as .txt, is "
                   "refused); an existing folder or a path ending in / gets METHOD_ao.exr and "
                   ".png inside it (default METHOD_ao in the current folder)")
    r.add_argument("--preset", help="a named preset of the method (`aolab presets METHOD`: "
                   "default, low, medium, high, ultra, tuned-...); --set and --blur/--no-blur "
                   "override it")
    r.add_argument("--blur", action=argparse.BooleanOptionalAction, default=None,
                   help="apply the separable Gaussian blur (default: the preset's, else off)")
    sigma = float_option("--blur-sigma", 0.1, 64, lo_inclusive=True, unit="px")
    r.add_argument("--blur-sigma", type=sigma, default=1.5,
                   help="the blur's standard deviation, 0.1 to 64 px (default 1.5)")
    r.add_argument("--blur-taps", type=int_option("--blur-taps", 1, 129, odd=True), default=5,
                   help="the blur's taps per pass, odd, 1 to 129 (default 5)")
    r.add_argument("--json", help="also write the result (timing, metrics) to this JSON file")
    r.set_defaults(func=cmd_run)

    rt = sub.add_parser(
        "rtao", help="ray-traced AO of a G-buffer against its scene's triangles (Embree)",
        description="Cycles' AO integral traced on the CPU with Embree from every pixel of a "
        "G-buffer: stratified cosine-weighted rays, a hit within R occluding "
        "(docs/methods/rtao.md). The triangles are the mesh written beside the G-buffer "
        "(`aolab mesh`, or `aolab reference --passes depth,normal,mesh`), or --mesh.")
    rt.add_argument("input", help="G-buffer .exr (with sidecar), a reference_scenes/<name> "
                    "folder, or analytic:NAME (its planes as triangles)")
    input_options(rt, settings=False)
    rt.add_argument("--mesh", help="the scene's .mesh file (default: <stem>.mesh beside the "
                    "G-buffer); its scene hash must equal the G-buffer's")
    rt.add_argument("--allow-unknown-scene", action="store_true",
                    help="trace a mesh whose scene cannot be checked: the mesh or the "
                    "G-buffer carries no scene hash (an analytic scene, a .mesh without its "
                    ".mesh.json); a hash that differs is refused all the same")
    rt.add_argument("--rays", type=int_option("--rays", 1, 65536), default=RTAO_DEFAULT_RAYS,
                    help=f"rays per pixel, 1 to 65536 (default {RTAO_DEFAULT_RAYS}, the "
                    "reference's samples)")
    rt.add_argument("--seed", type=int_option("--seed", 0, 2**31 - 1), default=0,
                    help="seed of the per-pixel jitter, 0 to 2^31 - 1 (default 0)")
    rt.add_argument("--out", help="output path without extension: writes OUT.exr and OUT.png "
                    "(default rtao_ao in the current folder)")
    rt.add_argument("--json", help="also write the result (timing, metrics) to this JSON file")
    rt.set_defaults(func=cmd_rtao)

    from .rtao_check import add_parser as add_rtao_check_parser
    add_rtao_check_parser(sub).set_defaults(func=cmd_rtao_check)
    from .bridge_check import add_parser as add_bridge_check_parser
    add_bridge_check_parser(sub).set_defaults(func=cmd_bridge_check)

    b = sub.add_parser("bench", help="median time of a method over repeated runs")
    b.add_argument("method", choices=aolab.methods())
    b.add_argument("input", nargs="?", default="analytic:blocks")
    input_options(b, threads=False)
    add_timing_options(b, repeat=7, warmup=1, repeat_help="timed runs (their median)")
    b.set_defaults(func=cmd_bench)

    bt = sub.add_parser("bench-table",
                        help="every method's scalar code against its SIMD kernel, one run",
                        description="Times each method at a preset on the blocks scene at "
                        "1280x720, R = 0.25: its scalar code on 1 thread, its SIMD kernel on 1 "
                        "and 2 threads, the speed-up and the samples per second "
                        "(docs/benchmarks.md). scripts/bench.sh runs it.")
    # No `choices`: Python 3.11 argparse checks an empty nargs="*" list against them and
    # refuses it; an unknown name is a ValueError from aolab.method_info instead.
    bt.add_argument("methods", nargs="*", metavar="METHOD",
                    help="methods (default: every method but the oracles)")
    bt.add_argument("--preset", help="the preset to time, a name of `aolab presets METHOD` "
                    "(default medium, or default for a method without it; the shared blur is "
                    "left out)")
    bt.add_argument("--repeat", type=int_option("--repeat", 1, MAX_RUNS), default=5,
                    help=f"timed runs per kernel, 1 to {MAX_RUNS} (their median; default 5)")
    bt.add_argument("--scaling", action="store_true",
                    help="also 3840x2160: time, its ratio to 1280x720 and the peak memory")
    bt.add_argument("--radii", action="store_true",
                    help="also R x 2, 4 and 8 at the same settings (how time grows with R)")
    bt.add_argument("--size", type=size_option("--size"),
                    help="WxH instead of 1280x720 (e.g. 640x360, the add-on's live preview)")
    bt.add_argument("--json", help="also write the rows to this JSON file")
    bt.add_argument("--profile", metavar="DIR",
                    help="also record each method's SIMD kernel with perf into DIR and print "
                    "its hottest functions")
    bt.set_defaults(func=cmd_bench_table)

    f = sub.add_parser("reference", help="render Cycles AO references with Blender (cached)",
                       description="Renders the G-buffer passes and the Cycles AO reference of "
                       "each scene (a .blend, a build script .py, or a reference_scenes/<name> "
                       "folder) in Blender in the background, into a cache; a repeated call is "
                       "served from the cache and an interrupted batch resumes.")
    f.add_argument("scenes", nargs="+", metavar="SCENE")
    f.add_argument("--spp", type=int_option("--spp", 1, MAX_SAMPLES),
                   help=f"reference samples, 1 to {MAX_SAMPLES} (default: manifest, else 1024)")
    f.add_argument("--radius", type=radius, help="AO distance R, finite > 0 (default: "
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
    f.add_argument("--frames", type=checked_type(parse_frames, "--frames"),
                   help="animation frames: N, START-END or START-END:STEP (one reference each, "
                   "copied to OUT/frames/NNNN; default: a sequence scene's manifest frames)")
    f.add_argument("--workers", type=int_option("--workers", 1, 256), default=1,
                   help="render on a local Dask cluster of this many workers, 1 to 256 (default "
                   "1: in this process, one job after another; docs/scale_out.md)")
    f.add_argument("--scheduler", metavar="ADDRESS",
                   help="render on the Dask cluster whose scheduler is at ADDRESS (e.g. "
                   "tcp://10.0.0.5:8786); its workers need aolab and Blender and the cache on "
                   "shared storage (docs/scale_out.md)")
    f.set_defaults(func=cmd_reference)

    ms = sub.add_parser("mesh", help="export each scene's triangles as Cycles renders them "
                        "(no render; cached)",
                        description="Exports the world-space triangles of every object Cycles' "
                        "AO sees (modifiers, instances and visibility as for render) of each "
                        "scene (a .blend, a build script .py, or a reference_scenes/<name> "
                        "folder) with Blender in the background, without rendering, into "
                        "reference.mesh + reference.mesh.json in the reference cache. A scene "
                        "folder's manifest gives the resolution and camera, so the scene_hash "
                        "matches its reference.json (docs/blender_bridge.md).")
    ms.add_argument("scenes", nargs="+", metavar="SCENE")
    ms.add_argument("--out", help="also copy reference.mesh/.mesh.json here (one folder per "
                    "scene when several)")
    ms.add_argument("--resolution", help="WxH, overriding the scene's (it enters the "
                    "scene_hash, as for a reference)")
    ms.add_argument("--camera", help="camera object (default: manifest, else the scene camera)")
    ms.add_argument("--cache", help="cache folder (default $AOLAB_CACHE or "
                    "~/.cache/aolab/references)")
    ms.add_argument("--force", action="store_true", help="export even if cached")
    ms.add_argument("--quiet", action="store_true", help="no progress bar")
    ms.set_defaults(func=cmd_mesh)

    from .limits import add_limits_parser
    add_limits_parser(sub).set_defaults(func=cmd_limits)
    from .radius_study import add_parser as add_radius_study_parser
    add_radius_study_parser(sub).set_defaults(func=cmd_radius_study)
    add_compare_parser(sub)

    q = sub.add_parser("presets", help="the named presets of each method and their settings")
    q.add_argument("methods", nargs="*", metavar="METHOD", help="methods (default: all)")
    q.add_argument("--json", action="store_true", help="print them as JSON")
    q.set_defaults(func=cmd_presets)

    from .tune import add_tune_parser
    add_tune_parser(sub).set_defaults(func=cmd_tune)
    return p


def main(argv: list[str] | None = None) -> int:
    """The aolab command: the exit status. A bad option value returns 2 after argparse's usage
    line and message; an exception from a command prints ``aolab: <message>`` (one line) and
    returns 2, Ctrl-C returns 130, and ``--debug`` re-raises instead (docs/conventions.md,
    Errors)."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as e:   # a bad option value (2), --help (0): argparse printed why
        return e.code if isinstance(e.code, int) else 2
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _one_line_warnings(warnings.showwarning)
            return args.func(args)
    except KeyboardInterrupt:
        if args.debug:
            raise
        _report("interrupted")
        return 130
    except BrokenPipeError:   # aolab methods | head: the reader left; say nothing
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        return 141   # 128 + SIGPIPE, what a shell shows for a process the pipe ended
    except SystemExit as e:
        if e.code is None or isinstance(e.code, int) or args.debug:
            raise
        _report(error_message(e))   # SystemExit("message") from a command
        return 2
    except Exception as e:
        if args.debug:
            raise
        _report(error_message(e))
        return 2
