"""``aolab radius-study``: the Pyramid HBAO paper's comparison against the radius, repeated.

Astapov, Frolov, Galaktionov, "Pyramid HBAO — a Scalable Horizon-based Ambient Occlusion
Method" (2021), §4, Tables 1a–1c and Fig. 8: HBAO, Scalable AO and Pyramid HBAO on two
scenes at several radii, MAE and SSIM against a 1024-ray Blender reference and the time of
each method without its separable Gaussian filter; Scalable AO and Pyramid HBAO "with the
same number of samples per each depth pyramid level".

Here: the scenes' own R times each scale, one Cycles reference per scene and radius (rendered
once by ``aolab reference`` and cached), and per radius

- **HBAO** at D = 8 and constant sample density along each direction: N_s = 8 at scale 1,
  proportional to the scale (docs/benchmarks.md shows the cost of that); scored with the
  shared Gaussian, timed without it.
- **Pyramid HBAO** at its defaults (D = 8, S = 4 reads per level, K = 3, levels from R);
  scored with its Gaussian (§3.5), timed without it.
- **Scalable AO** with as many taps per pixel as Pyramid HBAO reads, D·S·L, L the levels
  Pyramid HBAO marches at the scene's median projected radius (equal samples per level, as
  the paper compared them), capped at SAO's largest tap count; scored with its bilateral
  reconstruction, timed without it.

Writes ``radius_study.json`` and ``radius_study.md`` (the table docs/benchmarks.md quotes)
and ``radius_study.svg`` (time and MAE against the scale, the paper's Fig. 8) into --out.
"""

from __future__ import annotations

import io
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import aolab

from ..cycles.plan import make_plan, resolve_scene
from ..cycles.run import Delivery, render
from ..scenes import find_scenes_dir, median_projected_radius
from ..util import files
from ..util.arguments import parse_resolution
from ..util.provenance import machine_info
from .runner import Timing, load_scene, run_configuration, score

#: The radii, as multiples of each scene's own R: the paper's tables span a factor 4 to 8.
DEFAULT_SCALES = (0.5, 1.0, 2.0, 4.0)
#: room: an interior with furniture (the paper's Viking Room); street: architecture over a
#: long depth range (its Crytek Sponza).
DEFAULT_SCENES = ("room", "street")
#: A quarter of the committed references' pixels: 1024-spp references at four radii of two
#: scenes take about 35 min at this size on 2 cores (four times that at 1280x720).
DEFAULT_RESOLUTION = (640, 360)
DEFAULT_SPP = 1024
#: HBAO's steps per direction at scale 1 (its default N_s); they grow with the scale.
HBAO_STEPS_AT_SCALE_1 = 8
HBAO_DIRECTIONS = 8
METHODS = ("hbao", "pyramid_hbao", "sao")
LABELS = {"hbao": "HBAO", "pyramid_hbao": "Pyramid HBAO", "sao": "Scalable AO"}


def pyramid_levels(radius_px: float, samples: int, reduction: int) -> int:
    """The levels Pyramid HBAO marches to reach ``radius_px`` (its `levels` = 0 rule at the
    mean start step 1: the smallest L with S·(K^L − 1)/(K − 1) ≥ R·f/d)."""
    levels = 1
    while samples * (reduction ** levels - 1) / (reduction - 1) < radius_px and levels < 32:
        levels += 1
    return levels


def default_of(method: str, name: str):
    return next(s["default"] for s in aolab.method_info(method)["settings"] if s["name"] == name)


def max_of(method: str, name: str):
    return next(s["max"] for s in aolab.method_info(method)["settings"] if s["name"] == name)


#: HBAO's and Pyramid HBAO's settings for the reference's own definition (the Cycles AO
#: pass: cosine-weighted, no distance attenuation; docs/methods/hbao.md): each method shown
#: as its paper gives it and at its best against this reference.
CYCLES_DEFINITION = {"hbao": {"attenuation": "none", "integral": "cosine"},
                     "pyramid_hbao": {"attenuation": "none"}}


def configurations(scale: float, radius_px: float) -> list[dict]:
    """Per configuration: the method, a label, the settings, the scored variant (with its
    filter) and the timed one (without), and the samples per pixel."""
    steps = max(1, round(HBAO_STEPS_AT_SCALE_1 * scale))
    d, s, k = (int(default_of("pyramid_hbao", n)) for n in ("directions", "samples", "reduction"))
    levels = pyramid_levels(radius_px, s, k)
    taps = min(int(max_of("sao", "samples")), d * s * levels)
    hbao = {"method": "hbao", "settings": {"directions": HBAO_DIRECTIONS, "steps": steps},
            "scored": {"blur": True}, "timed": {"blur": False},
            "samples": HBAO_DIRECTIONS * steps, "note": f"D {HBAO_DIRECTIONS}, N_s {steps}"}
    pyramid = {"method": "pyramid_hbao", "settings": {},
               "scored": {"gaussian_filter": True}, "timed": {"gaussian_filter": False},
               "samples": d * s * levels, "note": f"D {d}, S {s}, K {k}, L {levels}"}
    sao = {"method": "sao", "settings": {"samples": taps},
           "scored": {"filter": True}, "timed": {"filter": False}, "samples": taps,
           "note": f"{taps} taps" + (" (its most)" if taps < d * s * levels else "")}
    out = []
    for c in (hbao, pyramid, sao):
        out.append({**c, "label": LABELS[c["method"]]})
        if c["method"] in CYCLES_DEFINITION:
            out.append({**c, "label": LABELS[c["method"]] + ", Cycles' definition",
                        "settings": {**c["settings"], **CYCLES_DEFINITION[c["method"]]}})
    return out


def run_case(scene_name: str, folder: Path, scale: float, threads: int, warmup: int,
             repeat: int) -> list[dict]:
    """Each configuration on one scene at one scale: its scored variant (with its filter)
    scored, its timed one (without) timed by the runner."""
    scene = load_scene(folder)
    radius_px = median_projected_radius(scene.g, scene.radius)
    timing = Timing(warmup, repeat, threads)
    rows = []
    for c in configurations(scale, radius_px):
        def settings(extra):
            return {**c["settings"], "blur": extra.get("blur", False),
                    **{k: v for k, v in extra.items() if k != "blur"}}

        ao = np.asarray(aolab.compute(c["method"], scene.g, radius=scene.radius,
                                      threads=threads, **settings(c["scored"])), np.float32)
        scored = score(ao, scene)["regions"]
        run = run_configuration(c["method"], settings(c["timed"]), scene, timing)
        rows.append({"scene": scene_name, "scale": scale, "radius": scene.radius,
                     "radius_px": radius_px, "method": c["method"], "label": c["label"],
                     "config": c["note"],
                     "samples": c["samples"], "settings": {"radius": scene.radius,
                                                           **c["settings"]},
                     "median_ms": statistics.median(run.times),
                     "mae": scored["all"]["mae"], "ssim": scored["all"]["ssim"],
                     "occluded_mae": scored["occluded"]["mae"]})
    return rows


def table(rows: list[dict]) -> str:
    """The markdown table of docs/benchmarks.md: a row per scene, radius and configuration."""
    out = ["| scene | R (scale) | R on screen | configuration | samples / px | ms | MAE | "
           "occluded MAE | SSIM |", "|---|---|---|---|---|---|---|---|---|"]

    def order(r):
        scene = DEFAULT_SCENES.index(r["scene"]) if r["scene"] in DEFAULT_SCENES else 99
        return scene, r["scene"], r["scale"]
    for r in sorted(rows, key=order):   # stable: the configurations keep their order
        out.append(f"| {r['scene']} | {r['radius']:g} (×{r['scale']:g}) | "
                   f"{r['radius_px']:.0f} px | {r['label']} ({r['config']}) | {r['samples']} | "
                   f"{r['median_ms']:.1f} | {r['mae']:.4f} | {r['occluded_mae']:.4f} | "
                   f"{r['ssim']:.3f} |")
    return "\n".join(out) + "\n"


def plot(rows: list[dict], path: Path) -> None:
    """Time and MAE against the scale, a line per method and scene (the paper's Fig. 8)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    matplotlib.rcParams["svg.hashsalt"] = "aolab"   # the same file for the same numbers
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4))
    styles = {"room": "-", "street": "--"}
    labels = list(dict.fromkeys(r["label"] for r in rows))
    colours = ("tab:red", "tab:orange", "tab:blue", "tab:cyan", "tab:green", "tab:olive")
    for label, colour in zip(labels, colours):
        for scene in sorted({r["scene"] for r in rows}):
            pts = sorted((r["scale"], r["median_ms"], r["mae"]) for r in rows
                         if r["label"] == label and r["scene"] == scene)
            if not pts:
                continue
            xs = [p[0] for p in pts]
            if "definition" not in label:   # the same time as the paper's variant
                axes[0].plot(xs, [p[1] for p in pts], styles.get(scene, ":"), color=colour,
                             marker="o", label=f"{label}, {scene}")
            axes[1].plot(xs, [p[2] for p in pts], styles.get(scene, ":"), color=colour,
                         marker="o", label=f"{label}, {scene}")
    for ax, label in zip(axes, ("median time (ms), without filters", "MAE against Cycles")):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("radius (multiple of the scene's R)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].set_yscale("log")
    axes[0].legend(fontsize=6)
    axes[1].legend(fontsize=5, ncol=2)
    fig.tight_layout()
    svg = io.BytesIO()
    fig.savefig(svg, format="svg", metadata={"Date": None})
    plt.close(fig)
    files.write_bytes(path, svg.getvalue())


#: The files radius-study writes into --out.
OUTPUT_FILES = ("radius_study.json", "radius_study.md", "radius_study.svg")


def study_plans(scenes, scales, resolution, spp: int, scenes_dir: Path | None,
                follow_symlinks: bool = False) -> list:
    """(scene name, scale, aolab.cycles.plan.Plan) for every scene and scale; the passes are given
    (depth and normal, which all three methods read), so the plans do not depend on which
    methods are registered."""
    scenes_dir = scenes_dir or find_scenes_dir()
    if scenes_dir is None:
        raise ValueError("no reference_scenes folder found: give --scenes-dir")
    plans = []
    for name in scenes:
        spec = resolve_scene(str(Path(scenes_dir) / name), follow_symlinks)
        base = spec.manifest.get("radius")
        if base is None:
            raise ValueError(f"scene {spec.name!r} has no radius in its manifest")
        for scale in scales:
            plans.append((spec.name, scale, make_plan(
                spec, spp=spp, radius=float(base) * scale, passes=["depth", "normal"],
                resolution=resolution)))
    return plans


def run_study(scenes: list[str] = DEFAULT_SCENES, *, scales=DEFAULT_SCALES,
              resolution: str = "x".join(map(str, DEFAULT_RESOLUTION)), spp: int = DEFAULT_SPP,
              threads: int = 0, warmup: int = 1, repeat: int = 5, cache: str | None = None,
              scenes_dir: str | None = None, out: str = "out/radius_study",
              quiet: bool = False, follow_symlinks: bool = False) -> int:
    """``aolab radius-study``: the exit status.
    One run at a time writes into the output folder (files.output_lock): a second one is
    refused naming the first instead of mixing their files. Its paths are checked first
    (--out was refused after the renders, 35 min)."""
    Delivery(cache=cache, out=out).check()
    size = parse_resolution(resolution)
    plans = study_plans(list(scenes), list(scales), size, spp,
                        Path(scenes_dir) if scenes_dir else None, follow_symlinks)
    files.check_paths(reads={"the scene": [plan.scene.path for _, _, plan in plans]},
                      made={"--out": [Path(out) / name for name in OUTPUT_FILES]})
    with files.output_lock(out, "aolab radius-study"):
        started = time.time()
        rows = measure(plans, cache, threads=threads, warmup=warmup, repeat=repeat,
                       quiet=quiet)
        result = {"command": "aolab radius-study " + " ".join(sys.argv[2:]),
                  "machine": machine_info(threads), "resolution": list(size), "spp": spp,
                  "repeat": repeat, "warmup": warmup,
                  "seconds": round(time.time() - started, 1), "rows": rows}
        write(result, Path(out))
    return 0


def measure(plans, cache, *, threads: int, warmup: int, repeat: int, quiet: bool) -> list:
    """Every reference of ``plans`` rendered (or cached) first, the renders being the long
    part; then each method timed and scored at each radius."""
    rows = []
    for name, scale, plan in plans:   # every reference first: the renders are the long part
        folder, cached = render(plan, cache, progress=not quiet)
        print(f"{name} x{scale:g}: reference {'cached' if cached else 'rendered'} ({folder})",
              file=sys.stderr)
    for name, scale, plan in plans:
        folder, _ = render(plan, cache, progress=False)
        rows += run_case(name, folder, scale, threads, warmup, repeat)
        print(f"{name} x{scale:g}: " + ", ".join(
            f"{r['label']} {r['median_ms']:.1f} ms MAE {r['mae']:.4f}" for r in rows[-5:]),
            file=sys.stderr)
    return rows


def write(result: dict, out: Path) -> None:
    """radius_study.json and .md put in place together, the plot beside them, the table
    printed."""
    out.mkdir(parents=True, exist_ok=True)
    rows = result["rows"]
    json_file, md_file, svg_file = (out / name for name in OUTPUT_FILES)
    files.write_together([(json_file, (json.dumps(result, indent=1) + "\n").encode()),
                          (md_file, table(rows).encode())])
    plot(rows, svg_file)
    print(table(rows))
