"""``aolab bench-table``'s geometry tables: each method's time on the reference scenes and
against the AO radius in pixels, with the median and the worst over scenes
(docs/benchmarks.md, "Time on every scene").

What is timed is what a user gets from ``aolab.compute(method, g, preset="medium")``: the
SIMD kernel on 2 threads with the preset's settings and its shared blur, wall clock, the
median of ``repeat`` runs after one warm-up (``study.runner.median_ms``).

- **The target scenes** are the committed still scenes at 1280×720 (the size the targets
  are stated at). Each is timed at its own R and at the R whose median projected radius is
  16, 32, 64, 128 and 256 px (``scenes.radius_for_pixels``): the same geometry, the radius
  on screen made to vary.
- **The corpus** (the other still scenes, 640×360, the add-on's Live preview size) is
  timed at each scene's own R.
- **HBAO 8×8 against its scalar code**: the scalar per-pixel code on 1 thread against the
  SIMD kernel on 2 threads, both without the blur, on each target scene and radius.
- **Scaling** (``scaling=True``): each target scene upsampled 3× (3840×2160, depth
  interpolated along its planes, the intrinsics scaled with it, so the same R covers 3× the
  pixels: ``upsampled``) against the scene itself at its own R, the two timed alternately.

Sequences are left out: their frames are the stills' geometry seen in motion.
"""

from __future__ import annotations

import io
import json
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import aolab

from .. import scenes
from ..study.runner import median_ms
from ..util import files
from . import kernel_bench

#: The radii on screen of the per-radius table: the median projected radius, in pixels.
PIXEL_RADII = (16, 32, 64, 128, 256)
#: The size the targets are stated at; still scenes of another size are the corpus.
TARGET_SIZE = (1280, 720)
#: 1280×720 → 3840×2160.
UPSCALE = 3
PRESET = "medium"
THREADS = 2


@dataclass
class Frame:
    """A still scene as the benchmark times it: its R, the radius on screen R covers, and
    (target scenes) the R of each of PIXEL_RADII, found once (each is a median over the
    frame)."""
    name: str
    g: object
    radius: float
    radius_px: float
    target: bool
    pixel_radii: dict = field(default_factory=dict)


@dataclass
class SceneTimes:
    """One method on one scene: ms at the scene's R, and (target scenes) at each pixel
    radius."""
    scene: str
    method: str
    size: tuple
    radius: float
    radius_px: float
    target: bool
    ms: float
    px_ms: dict = field(default_factory=dict)


def load_frames(specs: list[str], scenes_dir: Path | None, corpus: bool) -> list[Frame]:
    """The still scenes named (default: every still scene), the target scenes first; the
    corpus only when ``corpus`` or named."""
    folders = scenes.resolve_scenes(specs, scenes_dir)
    frames = []
    for folder in folders:
        if scenes.frame_numbers(folder) is not None:
            continue
        g, _reference, radius, _crop = scenes.load_cropped(folder)
        target = (g.width, g.height) == TARGET_SIZE
        if not (target or corpus or specs):
            continue
        radii = {px: scenes.radius_for_pixels(g, px) for px in PIXEL_RADII} if target else {}
        frames.append(Frame(folder.name, g, radius, scenes.median_projected_radius(g, radius),
                            target, radii))
    if not frames:
        raise ValueError("no still scene to time: name scenes, or pass --corpus")
    return sorted(frames, key=lambda f: (not f.target, f.name))


def preset_run(method: str, g, radius: float):
    """A call of the method's medium preset (its blur included), SIMD kernel, 2 threads."""
    preset = kernel_bench.bench_preset(method, PRESET)
    return lambda: aolab.compute(method, g, radius=radius, threads=THREADS, preset=preset)


def time_preset(method: str, g, radius: float, repeat: int) -> float:
    return median_ms(preset_run(method, g, radius), repeat)


def scene_times(methods: list[str], frames: list[Frame], repeat: int, progress=print
                ) -> list[SceneTimes]:
    rows = []
    for frame in frames:
        for method in methods:
            row = SceneTimes(frame.name, method, (frame.g.width, frame.g.height), frame.radius,
                             frame.radius_px, frame.target,
                             time_preset(method, frame.g, frame.radius, repeat))
            for px, r in frame.pixel_radii.items():
                row.px_ms[px] = time_preset(method, frame.g, r, repeat)
            rows.append(row)
        if progress:
            progress(f"# timed {frame.name} ({frame.g.width}x{frame.g.height}, R = "
                     f"{frame.radius:g}, {frame.radius_px:.0f} px)")
    return rows


def hbao_speedups(frames: list[Frame], repeat: int) -> list[dict]:
    """HBAO 8×8 (medium, no blur): scalar 1 thread and SIMD 2 threads per target scene at
    its R and each pixel radius. The scalar code takes about a second a run, so it is timed
    twice, without a warm-up (first-touch costs are a few ms of it)."""
    settings = kernel_bench.configuration("hbao", PRESET)
    out = []
    for frame in (f for f in frames if f.target):
        for key, r in {"own": frame.radius, **frame.pixel_radii}.items():
            def run(kernel, threads, r=r):
                return aolab.compute("hbao", frame.g, radius=r, threads=threads,
                                     kernel=kernel, **settings)
            scalar = median_ms(lambda: run("scalar", 1), 2, warmup=0)
            simd = median_ms(lambda: run("simd", THREADS), repeat)
            out.append({"scene": frame.name, "radius_px": key, "scalar_ms": scalar,
                        "simd_ms": simd, "speedup": scalar / simd})
    return out


#: Upsampling interpolates depth only between neighbours within this relative depth of each
#: other: across a larger jump (an edge) it takes the nearest pixel instead.
EDGE_JUMP = 0.05


def upsampled(g, factor: int):
    """``g`` at factor² the pixels, the intrinsics scaled with it (pixel centres map as
    x' + ½ = factor·(x + ½)): the same view, as a render at the larger size would see it.
    Depth is interpolated as 1/d, which is affine in the image for a plane, so planes stay
    planes, and not across edges (EDGE_JUMP); normals, colour and background come from the
    nearest pixel. Repeating pixels instead would turn every slanted plane into stairs whose
    risers occlude, work that a real render at that size does not have."""
    depth = np.asarray(g.depth, np.float64)
    h, w = depth.shape
    ys, xs = _source_coordinates(h, factor), _source_coordinates(w, factor)
    y0, x0 = np.clip(np.floor(ys).astype(int), 0, max(h - 2, 0)), np.clip(
        np.floor(xs).astype(int), 0, max(w - 2, 0))
    y1, x1 = np.minimum(y0 + 1, h - 1), np.minimum(x0 + 1, w - 1)
    # Within a third of a pixel of the border this extrapolates, which a plane allows.
    fy, fx = (ys - y0)[:, None], (xs - x0)[None, :]
    corners = [depth[np.ix_(a, b)] for a in (y0, y1) for b in (x0, x1)]
    valid = np.asarray(g.valid_mask(), bool)
    all_valid = np.logical_and.reduce([valid[np.ix_(a, b)] for a in (y0, y1) for b in (x0, x1)])
    with np.errstate(divide="ignore", invalid="ignore"):
        lo, hi = np.minimum.reduce(corners), np.maximum.reduce(corners)
        smooth = all_valid & (hi <= lo * (1 + EDGE_JUMP))
        inv = [1.0 / c for c in corners]
        top = inv[0] * (1 - fx) + inv[1] * fx
        bottom = inv[2] * (1 - fx) + inv[3] * fx
        interpolated = 1.0 / (top * (1 - fy) + bottom * fy)
        smooth &= np.isfinite(interpolated) & (interpolated > 0)
    near_y, near_x = np.arange(h * factor) // factor, np.arange(w * factor) // factor

    def nearest(a):
        return None if a is None else np.asarray(a)[np.ix_(near_y, near_x)]
    big_depth = np.where(smooth, interpolated, nearest(depth)).astype(np.float32)
    return aolab.GBuffer(big_depth, nearest(g.normal), nearest(g.color), fx=g.fx * factor,
                         fy=g.fy * factor, cx=g.cx * factor, cy=g.cy * factor,
                         background_depth=g.background_depth, emission=nearest(g.emission))


def _source_coordinates(n: int, factor: int) -> np.ndarray:
    """The source pixel coordinate (centres at integers) of each of n·factor target pixels."""
    return (np.arange(n * factor) + 0.5) / factor - 0.5


def alternated_ms(runs: list, repeat: int) -> list[float]:
    """Median ms of each run, the runs timed in turn after a warm-up of each: their ratios
    then compare them under the same load, where timing one after the other would let the
    machine's drift between them into it."""
    for run in runs:
        run()
    ms = [[] for _ in runs]
    for _ in range(repeat):
        for run, out in zip(runs, ms):
            out.append(median_ms(run, 1, warmup=0))
    return [statistics.median(m) for m in ms]


def scaling(methods: list[str], frames: list[Frame], repeat: int, progress=print
            ) -> list[dict]:
    """Per method and target scene at its R: 3840×2160 (upsampled) ms and its ratio to
    1280×720, the two timed alternately (alternated_ms)."""
    out = []
    for frame in (f for f in frames if f.target):
        large = upsampled(frame.g, UPSCALE)
        for method in methods:
            small_ms, ms = alternated_ms([preset_run(method, frame.g, frame.radius),
                                          preset_run(method, large, frame.radius)], repeat)
            out.append({"scene": frame.name, "method": method, "ms": ms, "small_ms": small_ms,
                        "ratio": ms / small_ms})
        if progress:
            progress(f"# timed {frame.name} at {large.width}x{large.height}")
    return out


def median_worst(values: dict) -> tuple[float, float, str]:
    """(median, largest, the key of the largest) of {key: value}."""
    worst = max(values, key=values.get)
    return statistics.median(values.values()), values[worst], worst


def _px_label(key) -> str:
    return "own R" if key == "own" else f"{key} px"


def markdown(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|---" * len(header) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def scene_table(methods: list[str], times: list[SceneTimes]) -> str:
    """ms at each scene's own R: the target scenes one column each, their median and worst,
    then the corpus's median and worst."""
    targets = list(dict.fromkeys(t.scene for t in times if t.target))
    px = {t.scene: t.radius_px for t in times}
    has_corpus = any(not t.target for t in times)
    header = ["method"] + [f"{s} ({px[s]:.0f} px)" for s in targets] + ["median", "worst"]
    header += ["corpus median", "corpus worst"] if has_corpus else []
    rows = []
    for m in methods:
        mine = [t for t in times if t.method == m]
        on = {t.scene: t.ms for t in mine if t.target}
        row = [m] + [f"{on[s]:.1f}" for s in targets]
        row += _median_worst_cells(on)
        if has_corpus:
            row += _median_worst_cells({t.scene: t.ms for t in mine if not t.target}, True)
        rows.append(row)
    return markdown(header, rows)


def _median_worst_cells(values: dict, name: bool = False) -> list[str]:
    if not values:
        return ["—", "—"]
    med, worst, where = median_worst(values)
    return [f"{med:.1f}", f"{worst:.1f}" + (f" ({where})" if name else "")]


def radius_table(methods: list[str], times: list[SceneTimes]) -> str:
    """ms against the radius on screen: median / worst over the target scenes."""
    header = ["method"] + [f"{px} px" for px in PIXEL_RADII] + [
        f"worst at {PIXEL_RADII[-1]} px"]
    rows = []
    for m in methods:
        mine = [t for t in times if t.method == m and t.target]
        if not mine:
            continue
        cells = []
        for px in PIXEL_RADII:
            med, worst, _ = median_worst({t.scene: t.px_ms[px] for t in mine})
            cells.append(f"{med:.1f} / {worst:.1f}")
        _, _, where = median_worst({t.scene: t.px_ms[PIXEL_RADII[-1]] for t in mine})
        rows.append([m] + cells + [where])
    return markdown(header, rows)


def speedup_table(pairs: list[dict]) -> str:
    """HBAO 8×8, scalar 1 thread against SIMD 2 threads, per radius over the target scenes."""
    rows = []
    for key in ["own"] + list(PIXEL_RADII):
        mine = [p for p in pairs if p["radius_px"] == key]
        if not mine:
            continue
        low = min(mine, key=lambda p: p["speedup"])
        rows.append([_px_label(key),
                     f"{statistics.median(p['scalar_ms'] for p in mine):.0f}",
                     f"{statistics.median(p['simd_ms'] for p in mine):.1f}",
                     f"{statistics.median(p['speedup'] for p in mine):.1f}×",
                     f"{low['speedup']:.1f}× ({low['scene']})"])
    return markdown(["radius", "scalar 1t ms, median", "SIMD 2t ms, median",
                     "speed-up, median", "lowest"], rows)


def scaling_table(methods: list[str], large: list[dict]) -> str:
    """3840×2160 against 1280×720 at each target scene's R: medians and the worst ratio."""
    rows = []
    for m in methods:
        mine = [r for r in large if r["method"] == m]
        med, worst, where = median_worst({r["scene"]: r["ratio"] for r in mine})
        rows.append([m, f"{statistics.median(r['small_ms'] for r in mine):.1f}",
                     f"{statistics.median(r['ms'] for r in mine):.0f}", f"{med:.1f}",
                     f"{worst:.1f} ({where})"])
    return markdown(["method", "1280×720 ms, median", "3840×2160 ms, median",
                     "ratio, median", "worst ratio"], rows)


#: The targets (docs/benchmarks.md, "Targets").
FRAME_MS = 50.0
HBAO_SPEEDUP = 16.0
LIVE_MS = 100.0
SCALING_RATIO = 10.8


def _worst_target_case(method: str, times: list[SceneTimes]) -> tuple[float, str] | None:
    """The slowest of the method's target-scene times, at their R and each pixel radius."""
    cases = {}
    for t in times:
        if t.method == method and t.target:
            cases[f"{t.scene}, own R"] = t.ms
            cases.update({f"{t.scene}, {px} px": ms for px, ms in t.px_ms.items()})
    if not cases:
        return None
    _, worst, where = median_worst(cases)
    return worst, where


def targets(methods: list[str], times: list[SceneTimes], pairs: list[dict],
            large: list[dict] | None) -> list[dict]:
    """Where each target stands: {"target", "measured", "met"} rows."""
    out = []
    for m in methods:
        case = _worst_target_case(m, times)
        if case:
            out.append({"target": f"{m} ≤ {FRAME_MS:.0f} ms (1280×720, every scene, ≤ "
                                  f"{PIXEL_RADII[-1]} px)",
                        "measured": f"worst {case[0]:.1f} ms ({case[1]})",
                        "met": case[0] <= FRAME_MS})
    if pairs:
        low = min(pairs, key=lambda p: p["speedup"])
        out.append({"target": f"HBAO 8×8 ≥ {HBAO_SPEEDUP:.0f}× its scalar code",
                    "measured": f"lowest {low['speedup']:.1f}× ({low['scene']}, "
                                f"{_px_label(low['radius_px'])})",
                    "met": low["speedup"] >= HBAO_SPEEDUP})
    live = {(t.method, t.scene): t.ms for t in times if not t.target}
    if live:
        (m, s), ms = max(live.items(), key=lambda kv: kv[1])
        out.append({"target": f"Live preview (640×360) < {LIVE_MS:.0f} ms, every method",
                    "measured": f"slowest {ms:.1f} ms ({m}, {s})", "met": ms < LIVE_MS})
    for m in methods if large else []:
        mine = [r for r in large if r["method"] == m]
        worst = max(mine, key=lambda r: r["ratio"])
        out.append({"target": f"{m}: 3840×2160 ≤ {SCALING_RATIO}× 1280×720",
                    "measured": f"worst {worst['ratio']:.1f}× ({worst['scene']})",
                    "met": worst["ratio"] <= SCALING_RATIO})
    return out


def targets_table(rows: list[dict]) -> str:
    return markdown(["target", "measured", "status"],
                    [[r["target"], r["measured"], "**met**" if r["met"] else "not met"]
                     for r in rows])


def plot_svg(methods: list[str], times: list[SceneTimes], path: Path) -> None:
    """Time against the radius on screen per method (median over the target scenes, the
    band from the fastest to the slowest scene), log-log, as an SVG with fixed ids and no
    date, so that the same numbers give the same file."""
    import matplotlib
    matplotlib.use("svg")
    import matplotlib.pyplot as plt
    plt.rcParams["svg.hashsalt"] = "aolab"
    fig, ax = plt.subplots(figsize=(8, 5.2))
    # Eleven methods: more than a colour cycle holds, so each has a colour and a marker.
    colours, markers = plt.get_cmap("tab20").colors[::2] + ("black",), "osv^DPX*h<>"
    for i, m in enumerate(methods):
        mine = [t for t in times if t.method == m and t.target]
        if not mine:
            continue
        per = [[t.px_ms[px] for t in mine] for px in PIXEL_RADII]
        colour = colours[i % len(colours)]
        ax.plot(PIXEL_RADII, [statistics.median(v) for v in per],
                marker=markers[i % len(markers)],
                label=m, linewidth=1.5, color=colour)
        ax.fill_between(PIXEL_RADII, [min(v) for v in per], [max(v) for v in per],
                        color=colour, alpha=0.05, linewidth=0)
    ax.axhline(FRAME_MS, color="black", linestyle="--", linewidth=1)
    ax.text(PIXEL_RADII[0], FRAME_MS * 1.04, f"target {FRAME_MS:.0f} ms", fontsize=8)
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xticks(PIXEL_RADII, [str(p) for p in PIXEL_RADII])
    ax.set_xlabel("median AO radius on screen (px)")
    ax.set_ylabel("ms per 1280×720 frame, 2 threads (medium preset)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, ncol=2, loc="upper left")
    fig.tight_layout()
    svg = io.BytesIO()
    fig.savefig(svg, format="svg", metadata={"Date": None})
    plt.close(fig)
    files.write_bytes(path, svg.getvalue())


@dataclass
class Options:
    """What ``aolab bench-table`` was asked for (its command line)."""
    methods: list[str] = field(default_factory=list)
    preset: str | None = None
    repeat: int = 5
    scaling: bool = False
    radii: bool = False
    size: tuple | None = None
    json_path: str | None = None
    profile: str | None = None
    scenes: list[str] = field(default_factory=list)
    scenes_dir: str | None = None
    geometry: bool = True
    corpus: bool = True
    svg: str | None = None


def check(opts: Options) -> list[Frame]:
    """Everything the command line names, checked before the first timing (the run takes
    minutes, and a bad --json found after it would lose them): methods, presets, paths and
    scenes; the scenes loaded."""
    opts.methods = opts.methods or kernel_bench.default_methods()
    for method in opts.methods:
        kernel_bench.bench_preset(method, opts.preset)
    where = Path(opts.scenes_dir) if opts.scenes_dir else scenes.find_scenes_dir()
    read = scenes.resolve_scenes(opts.scenes, where) if opts.geometry else []
    files.check_paths(files={"--json": opts.json_path, "--svg": opts.svg},
                      folders={"--profile": opts.profile}, reads=scenes.scene_files(read),
                      made={"--profile": kernel_bench.profile_files(opts.methods, opts.profile)})
    if opts.profile:
        kernel_bench.need_perf()
    if not opts.geometry:
        return []
    return load_frames(opts.scenes, where, opts.corpus)


def _geometry(opts: Options, frames: list[Frame]) -> dict:
    """The geometry tables printed; their data."""
    methods = opts.methods
    times = scene_times(methods, frames, opts.repeat)
    print("\n## Time at each scene's own R (ms; medium preset with its blur, 2 threads)\n")
    print(scene_table(methods, times))
    print(f"\n## Time against the radius on screen (ms, median / worst over the "
          f"{TARGET_SIZE[0]}x{TARGET_SIZE[1]} scenes)\n")
    print(radius_table(methods, times))
    pairs = hbao_speedups(frames, opts.repeat) if "hbao" in methods else []
    if pairs:
        print("\n## HBAO 8x8: scalar code (1 thread) against the SIMD kernel (2 threads)\n")
        print(speedup_table(pairs))
    large = scaling(methods, frames, max(1, min(opts.repeat, 3))) if opts.scaling else []
    if large:
        print(f"\n## {TARGET_SIZE[0] * UPSCALE}x{TARGET_SIZE[1] * UPSCALE} against "
              f"{TARGET_SIZE[0]}x{TARGET_SIZE[1]}, each scene at its R\n")
        print(scaling_table(methods, large))
    if opts.svg:
        plot_svg(methods, times, Path(opts.svg))
    return {"times": [vars(t) for t in times], "hbao_speedups": pairs, "scaling": large,
            "targets": targets(methods, times, pairs, large)}


def print_header(repeat: int) -> None:
    """The run's first line: when, which commit, how many runs, the machine and its load."""
    print(f"# aolab bench-table {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, commit "
          f"{kernel_bench.commit()}, median of {repeat} runs; {kernel_bench.machine()}; "
          f"SIMD target {kernel_bench.simd_target()}")


def run_table(opts: Options) -> int:
    """``aolab bench-table``: the geometry tables, the blocks table (every method's scalar
    code against its SIMD kernel), where each target stands; the rows written to --json, each
    SIMD kernel profiled into --profile; the exit status."""
    frames = check(opts)
    size = tuple(opts.size) if opts.size else kernel_bench.SIZE
    shown = opts.preset or f"{kernel_bench.DEFAULT_BENCH_PRESET} (default where a method has none)"
    print_header(opts.repeat)
    geometry = _geometry(opts, frames) if frames else {}
    print(f"\n## Scalar code against SIMD kernel: {kernel_bench.SCENE} {size[0]}x{size[1]}, "
          f"R = {kernel_bench.RADIUS}, preset {shown}, without the blur\n")
    print(kernel_bench.header(opts.scaling, opts.radii))
    rows = kernel_bench.table(opts.methods, preset=opts.preset, repeat=opts.repeat,
                              scaling=opts.scaling, radii=opts.radii, size=size)
    if geometry:
        print("\n## Where each target stands\n")
        print(targets_table(geometry["targets"]))
    if opts.json_path:
        files.write_text(Path(opts.json_path),
                         json.dumps({"blocks": rows, **geometry}, indent=2, default=float))
    if opts.profile:
        _profile(rows, Path(opts.profile), size)
    return 0


def _profile(rows: list[dict], folder: Path, size) -> None:
    for row in rows:
        if row["method"] == kernel_bench.BLUR_ROW:
            continue
        print(f"\n## perf: {row['method']} ({row['preset']}, SIMD kernel, 2 threads)")
        for line in kernel_bench.profile(row["method"], row["settings"], folder, size=size):
            print(line)
