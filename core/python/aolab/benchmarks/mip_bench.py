"""``aolab bench-table --mip``: what reading far samples from the depth MIP chain does to
HBAO and the visibility bitmask (their ``mip_distance`` setting, q in pixels; docs/benchmarks.md,
"Far samples on a depth MIP chain").

- **Time**: the ``medium`` preset without the blur (the blur does not depend on q), 2
  threads, on each 1280×720 scene at the R whose median radius on screen is 64 and 256 px;
  every q of TIME_Q timed alternately with the others (``geometry_bench.alternated_ms``), so
  that their ratios see one load.
- **Accuracy**: the ``medium`` preset with its blur, as a user runs it, on every still scene
  at its own R against its Cycles reference: the MAE on the occluded region and on the whole
  frame, per q; the mean over scenes with its 95 % bootstrap interval, the paired difference
  to q off (Wilcoxon signed-rank, the study's test), and the reference's own noise floor
  beside it (an independent 1024-spp render against the reference; scenes.noise_floor_peer),
  since a change smaller than that floor is not one a reference can show.
"""

from __future__ import annotations

import json
import math
import statistics
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import aolab

from .. import scenes
from ..study import stats
from ..util import files
from . import geometry_bench

METHODS = ("hbao", "bitmask")
#: Radii on screen (median projected radius, px) of the time table.
TIME_RADII = (64, 256)
#: q of the time table: off, and around Scalable AO's 8.
TIME_Q = (0.0, 4.0, 8.0)
#: q of the accuracy table: off and the values ``aolab tune`` searches.
ACCURACY_Q = (0.0, 4.0, 8.0, 16.0, 32.0)
REGIONS = ("occluded", "all")


def _label(q: float) -> str:
    return "off" if q == 0 else f"q = {q:g}"


def _run(method: str, g, radius: float, q: float, blur: bool):
    return lambda: aolab.compute(method, g, radius=radius, threads=geometry_bench.THREADS,
                                 preset=geometry_bench.PRESET, blur=blur, mip_distance=q)


def times(frames: list[geometry_bench.Frame], repeat: int, progress=print) -> list[dict]:
    """Per target scene, method and radius on screen: ms at each q of TIME_Q, alternated."""
    rows = []
    for frame in (f for f in frames if f.target):
        for method in METHODS:
            for px in TIME_RADII:
                r = frame.pixel_radii[px]
                ms = geometry_bench.alternated_ms(
                    [_run(method, frame.g, r, q, blur=False) for q in TIME_Q], repeat)
                rows.append({"scene": frame.name, "method": method, "px": px,
                             "ms": dict(zip(TIME_Q, ms))})
        if progress:
            progress(f"# timed mip_distance on {frame.name}")
    return rows


def time_table(rows: list[dict]) -> str:
    header = ["method", "scene"] + [f"{px} px, {_label(q)}" for px in TIME_RADII for q in TIME_Q]
    body = {}
    for row in rows:
        cells = body.setdefault((row["method"], row["scene"]), {})
        for q, ms in row["ms"].items():
            cells[(row["px"], q)] = f"{ms:.1f}"
    return geometry_bench.markdown(header, [
        [m, s] + [cells.get((px, q), "—") for px in TIME_RADII for q in TIME_Q]
        for (m, s), cells in sorted(body.items())])


@dataclass
class SceneErrors:
    """One still scene: MAE per (method, q, region), the noise floor's MAE per region (None
    without one), and the mean |AO(q) − AO(off)| per (method, q)."""
    scene: str
    mae: dict
    floor: dict | None
    change: dict


def _mae(ao: np.ndarray, reference: np.ndarray, mask: np.ndarray) -> float:
    """NaN on an empty region (a scene with nothing occluded), which the means leave out."""
    if not mask.any():
        return math.nan
    return float(np.mean(np.abs(ao[mask].astype(np.float64) - reference[mask])))


def scene_errors(folder: Path) -> SceneErrors:
    scene = scenes.load_scene(folder)
    mae, change = {}, {}
    for method in METHODS:
        off = None
        for q in ACCURACY_Q:
            ao = _run(method, scene.g, scene.radius, q, blur=True)()
            off = ao if off is None else off
            change[(method, q)] = _mae(ao, off, scene.regions["all"])
            for region in REGIONS:
                mae[(method, q, region)] = _mae(ao, scene.reference, scene.regions[region])
    chosen = scenes.noise_floor_peer(scene.peers)
    floor = None if chosen is None else {
        region: _mae(chosen[0].ao, scene.reference, scene.regions[region]) * chosen[1]
        for region in REGIONS}
    return SceneErrors(scene.name, mae, floor, change)


def accuracy(specs: list[str], scenes_dir: Path | None, progress=print) -> list[SceneErrors]:
    """scene_errors of every still scene named (none named: every still scene)."""
    out = []
    for folder in scenes.resolve_scenes(specs, scenes_dir):
        if scenes.frame_numbers(folder) is None:
            out.append(scene_errors(folder))
    if progress:
        progress(f"# scored mip_distance on {len(out)} still scenes")
    return out


def _mean_interval(values: list[float], digits: int = 4) -> str:
    values = [v for v in values if math.isfinite(v)]
    interval = stats.bootstrap_interval(values)
    mean = f"{statistics.fmean(values):.{digits}f}"
    if interval is None:
        return mean
    return f"{mean} [{interval[0]:.{digits}f}, {interval[1]:.{digits}f}]"


def accuracy_summary(errors: list[SceneErrors]) -> list[dict]:
    """Per method and q: the mean MAE per region with its interval, the paired difference to
    q off, the mean change of the output."""
    rows = []
    for method in METHODS:
        for q in ACCURACY_Q:
            row = {"method": method, "q": q,
                   "change": statistics.fmean(e.change[(method, q)] for e in errors)}
            for region in REGIONS:
                per_scene = {e.scene: e.mae[(method, q, region)] for e in errors}
                off = {e.scene: e.mae[(method, 0.0, region)] for e in errors}
                row[region] = list(per_scene.values())
                row[f"{region}_paired"] = stats.paired(per_scene, off)
            rows.append(row)
    return rows


def _paired_cell(p: dict) -> str:
    if p["p"] is None or p["wins"] + p["losses"] == 0:
        return "—"
    return f"{p['mean_diff']:+.4f} ({p['wins']} better, {p['losses']} worse; p = {p['p']:.2g})"


def accuracy_table(errors: list[SceneErrors]) -> str:
    rows = accuracy_summary(errors)
    body = [[r["method"], _label(r["q"]), f"{r['change']:.4f}",
             _mean_interval(r["occluded"]), _paired_cell(r["occluded_paired"]),
             _mean_interval(r["all"]), _paired_cell(r["all_paired"])] for r in rows]
    floors = [e.floor for e in errors if e.floor is not None]
    if floors:
        body.append([f"noise floor ({len(floors)} scenes)", "", "",
                     _mean_interval([f["occluded"] for f in floors]), "",
                     _mean_interval([f["all"] for f in floors]), ""])
    return geometry_bench.markdown(
        ["method", "q", "mean |AO − AO off|", "occluded MAE [95 % CI]", "vs off",
         "whole-frame MAE [95 % CI]", "vs off"], body)


def run(opts: geometry_bench.Options) -> int:
    """``aolab bench-table --mip``: the two tables printed, their data written to --json; the
    exit status. Everything the command line names is checked before the first timing."""
    _refuse_others(opts)
    opts.methods = list(METHODS)
    scored = opts.corpus
    opts.corpus = False             # the corpus is scored, not timed
    frames = geometry_bench.check(opts)
    where = Path(opts.scenes_dir) if opts.scenes_dir else scenes.find_scenes_dir()
    geometry_bench.print_header(opts.repeat)
    rows = times(frames, opts.repeat)
    print("\n## mip_distance: time (ms; medium without the blur, 2 threads, alternated)\n")
    print(time_table(rows))
    errors = accuracy(opts.scenes or ([] if scored else [f.name for f in frames]), where)
    print(f"\n## mip_distance: accuracy on {len(errors)} still scenes at their R (medium, "
          "blur included)\n")
    print(accuracy_table(errors))
    if opts.json_path:
        files.write_text(Path(opts.json_path), json.dumps(_json(rows, errors), indent=2))
    return 0


def _refuse_others(opts: geometry_bench.Options) -> None:
    """The options of the other tables, which --mip does not draw: refused, not ignored."""
    given = {"METHOD": opts.methods, "--preset": opts.preset, "--scaling": opts.scaling,
             "--radii": opts.radii, "--size": opts.size, "--profile": opts.profile,
             "--svg": opts.svg}
    named = [name for name, value in given.items() if value]
    if named:
        raise ValueError(f"--mip times {' and '.join(METHODS)} at their medium preset and "
                         f"takes no {', '.join(named)}")


def _json(rows: list[dict], errors: list[SceneErrors]) -> dict:
    return {"times": [{**r, "ms": {f"{q:g}": v for q, v in r["ms"].items()}} for r in rows],
            "accuracy": [{"scene": e.scene, "floor": e.floor,
                          "mae": {f"{m}/{q:g}/{reg}": v for (m, q, reg), v in e.mae.items()},
                          "change": {f"{m}/{q:g}": v for (m, q), v in e.change.items()}}
                         for e in errors]}
