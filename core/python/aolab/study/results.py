"""The results of ``aolab compare``: the schema of results.csv and results.json (the
columns, a row, its scores), the flicker of a sequence's frames, the ALL rows (means over the
scenes with their bootstrap intervals), the rows' flags against AO = 1 and the files
themselves (docs/comparison.md, "Results"). The study that fills them is ``compare``.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np

from .. import named_presets as presets_mod
from ..regions import REGIONS
from ..scenes import Scene
from ..util import files
from . import stats
from .findings import ACCUMULATED_SUFFIX, WEAK_FRACTION
from .runner import score
from .temporal import DISOCCLUDED

#: Metrics per region, in column order.
METRICS = ("mae", "rmse", "psnr", "bias", "ssim", "mae_cal", "count")
AGGREGATE_SCENE = "ALL"
BASELINE = "baseline_one"
#: The kind of the rows of the committed screen-space limits (aolab limits).
LIMIT_KIND = "limit"

#: results.csv columns before the per-region metrics.
BASE_COLUMNS = ("key", "scene", "sequence", "frame", "frame_index", "kind", "method", "label",
                "preset", "accumulated", "settings", "threads",
                "width", "height", "radius", "method_ms", "method_ms_min", "method_ms_max",
                "method_ms_stdev", "blur_ms", "blur_ms_min", "blur_ms_max", "accumulate_ms",
                "accumulate_ms_min", "accumulate_ms_max", "total_ms", "runs",
                "n_scenes", "calib_a", "calib_b", "occluded_mae_vs_baseline",
                "occluded_mae_vs_limit", "occluded_mae_definition", "flicker",
                "disoccluded_mae", "disoccluded_count", "converged_mae", "flag", "note")


def columns() -> list[str]:
    """Every column of results.csv, in order."""
    return list(BASE_COLUMNS) + [f"{r}_{m}" for r in REGIONS for m in METRICS]


def row_key(scene: str, method: str, label: str) -> str:
    return f"{scene}/{method}/{label}"


# ----------------------------------------------------------------------------------------
# Temporal stability (docs/comparison.md, "Temporal stability")


def flicker(ao_prev: np.ndarray, ao: np.ndarray, ref_prev: np.ndarray, ref: np.ndarray,
            valid_prev: np.ndarray, valid: np.ndarray) -> float | None:
    """The flicker of a pair of consecutive frames: the mean over the pixels scored in both of
    |(AO_t - AO_t-1) - (Ref_t - Ref_t-1)|, the change of a method's image that the reference's
    change does not explain; None when no pixel is scored in both."""
    both = np.asarray(valid_prev, bool) & np.asarray(valid, bool)
    if not both.any():
        return None
    change = ao[both].astype(np.float64) - ao_prev[both]
    wanted = ref[both].astype(np.float64) - ref_prev[both]
    return float(np.mean(np.abs(change - wanted)))


def flicker_floor(ref_prev: np.ndarray, ref: np.ndarray, valid_prev: np.ndarray,
                  valid: np.ndarray, samples: int) -> float | None:
    """The flicker the reference's own Monte Carlo noise gives a noise-free method, estimated
    from the two frames themselves: each pixel's AO is a mean of ``samples`` binary rays
    (occluded or not), of variance v(1 - v)/N; the noises of two frames are independent, so
    their difference has variance s^2 = v_t(1 - v_t)/N + v_t-1(1 - v_t-1)/N and, taken as
    normal, a mean absolute value s·sqrt(2/pi). The mean of that over the pixels scored in both
    frames; None when ``samples`` is unknown (< 1) or no pixel is scored in both. Cycles'
    stratified samples are less noisy than independent rays, so this is an upper estimate."""
    both = np.asarray(valid_prev, bool) & np.asarray(valid, bool)
    if samples < 1 or not both.any():
        return None
    a = np.clip(ref_prev[both].astype(np.float64), 0.0, 1.0)
    b = np.clip(ref[both].astype(np.float64), 0.0, 1.0)
    s = np.sqrt((a * (1 - a) + b * (1 - b)) / samples)
    return float(np.mean(s) * math.sqrt(2 / math.pi))


def reference_samples(scene: Scene) -> int:
    """The reference's samples per pixel from its sidecar (0 when unknown)."""
    try:
        return int((scene.g.sidecar or {}).get("samples") or 0)
    except (TypeError, ValueError):
        return 0


# ----------------------------------------------------------------------------------------
# Rows


def make_row(scene: Scene | str, kind: str, method: str, label: str, **extra) -> dict:
    """A row of results.json: its key, scene, kind, method and label, the scene's size, R and
    frame (``scene`` a Scene; a name for an ALL or sequence row), and ``extra``."""
    name = scene if isinstance(scene, str) else scene.name
    row = {"key": row_key(name, method, label), "scene": name, "kind": kind,
           "method": method, "label": label, "note": ""}
    if not isinstance(scene, str):
        row.update(width=scene.g.width, height=scene.g.height, radius=scene.radius)
        if scene.sequence is not None:
            row.update(sequence=scene.sequence, frame=scene.frame)
    row.update(extra)
    return row


def config_row(scene: Scene, method: str, s, threads: int, temporal=None,
               accumulated: bool = False, **fields) -> dict:
    """The row of configuration ``s`` (a named_presets setting) of ``method`` on ``scene``;
    with ``temporal`` (a sequence's temporal.Accumulation) the frame's index and whether it
    is the accumulated row (``accumulated``: its label + ACCUMULATED_SUFFIX)."""
    extra = {} if temporal is None else {"accumulated": accumulated,
                                         "frame_index": temporal.index}
    label = s.label + (ACCUMULATED_SUFFIX if accumulated else "")
    return make_row(scene, "method", method, label, preset=s.preset or "",
                    settings=s.recorded_settings(), threads=threads, **extra, **fields)


def add_scores(row: dict, scored: dict) -> None:
    row["calib_a"], row["calib_b"] = scored["calib_a"], scored["calib_b"]
    row["occluded_mae_definition"] = scored.get("occluded_definition")
    row["metrics"] = {region: dict(m) for region, m in scored["regions"].items()}


def score_row(scene: Scene, row: dict, ao: np.ndarray, scored: dict | None = None) -> None:
    """Scores ``row`` (``scored``: its scores when already computed) and, on a frame of a
    sequence, keeps ``ao`` for the flicker against the next frame; on a frame of a sequence
    with motion, also its MAE on the frame's disoccluded region."""
    add_scores(row, scored if scored is not None else score(ao, scene))
    region = scene.regions.get(DISOCCLUDED)
    if region is not None:
        row["disoccluded_count"] = int(region.sum())
        error = np.abs(ao[region].astype(np.float64) - scene.reference[region])
        row["disoccluded_mae"] = float(np.mean(error)) if region.any() else None
    if scene.outputs is not None:
        scene.outputs[(row["kind"], row["method"], row["label"])] = ao


def flag_rows(rows: list[dict]) -> None:
    """Sets occluded_mae_vs_baseline and the flag of each row against its scene's baseline."""
    base = {r["scene"]: r for r in rows if r["kind"] == "baseline" and "metrics" in r}
    for r in rows:
        b = base.get(r["scene"])
        if b is None or "metrics" not in r or r["kind"] == "baseline":
            continue
        mine, theirs = r["metrics"]["occluded"]["mae"], b["metrics"]["occluded"]["mae"]
        if not (math.isfinite(mine) and math.isfinite(theirs)) or theirs <= 0:
            continue
        ratio = mine / theirs
        r["occluded_mae_vs_baseline"] = ratio
        r["flag"] = "weak" if ratio > WEAK_FRACTION else ""


#: Time columns: ALL's are means of each scene's time scaled to a 1280x720 frame.
TIME_COLUMNS = ("method_ms", "method_ms_min", "method_ms_max", "method_ms_stdev", "blur_ms",
                "blur_ms_min", "blur_ms_max", "accumulate_ms", "accumulate_ms_min",
                "accumulate_ms_max", "total_ms")


def aggregate(rows: list[dict], scene_names: list[str], name: str = AGGREGATE_SCENE,
              unit: str = "scene", time_scale: dict | None = None) -> list[dict]:
    """Rows of scene ``name`` ("ALL", or a sequence over its frames, ``unit`` "frame"): per
    (kind, method, label), the mean over the scenes that have it of every metric and time
    (counts summed), each time first scaled by ``time_scale[scene]`` (default 1), and the
    95 % bootstrap intervals over the scenes of the whole-frame and occluded MAE and of the
    total time ("intervals"). Only complete scenes take part."""
    time_scale = time_scale or {}
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        if r["scene"] in scene_names and "metrics" in r:
            groups.setdefault((r["kind"], r["method"], r["label"]), []).append(r)
    out = []
    for (kind, method, label), rs in groups.items():
        agg = make_row(name, kind, method, label, n_scenes=len(rs),
                       preset=rs[0].get("preset", ""), settings=rs[0].get("settings", {}),
                       threads=rs[0].get("threads"),
                       note=f"mean over {len(rs)} {unit}(s): {', '.join(r['scene'] for r in rs)}")
        if "accumulated" in rs[0]:
            agg["accumulated"] = rs[0]["accumulated"]
        for col in TIME_COLUMNS + ("calib_a", "calib_b", "occluded_mae_vs_limit",
                                   "occluded_mae_definition", "flicker"):
            vals = [r[col] * (time_scale.get(r["scene"], 1.0) if col in TIME_COLUMNS else 1.0)
                    for r in rs if r.get(col) is not None]
            # against the limit: over the scenes that have one (as the split's limit line);
            # the flicker: over the frame pairs (a sequence's first frame has none) or over
            # the sequences
            if vals and (len(vals) == len(rs) or col in ("occluded_mae_vs_limit", "flicker")):
                agg[col] = float(np.mean(vals))
        metrics = {}
        for region in REGIONS:
            metrics[region] = {}
            for m in METRICS:
                vals = [r["metrics"][region][m] for r in rs]
                if m == "count":
                    metrics[region][m] = int(sum(vals))
                else:
                    finite = [v for v in vals if v is not None and math.isfinite(v)]
                    metrics[region][m] = float(np.mean(finite)) if finite else math.nan
        agg["metrics"] = metrics
        agg["intervals"] = intervals(rs, time_scale)
        out.append(agg)
    flag_rows(out)
    return out


def intervals(rs: list[dict], time_scale: dict) -> dict:
    """95 % bootstrap intervals over the rows' scenes of the mean whole-frame and occluded MAE
    and total time (stats.bootstrap_interval; None with one scene)."""
    def ci(values):
        got = stats.bootstrap_interval(values)
        return list(got) if got is not None else None
    return {"all_mae": ci([r["metrics"]["all"]["mae"] for r in rs]),
            "occluded_mae": ci([r["metrics"]["occluded"]["mae"] for r in rs]),
            "total_ms": ci([r["total_ms"] * time_scale.get(r["scene"], 1.0) for r in rs
                            if r.get("total_ms") is not None])}


def flat(row: dict) -> dict:
    """A row as the flat dict of results.csv (settings as JSON, metrics as columns)."""
    out = {c: row.get(c) for c in BASE_COLUMNS}
    out["settings"] = json.dumps(row.get("settings", {}), sort_keys=True)
    for region in REGIONS:
        for m in METRICS:
            out[f"{region}_{m}"] = row.get("metrics", {}).get(region, {}).get(m)
    return out


def _csv_value(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)
    return v


def json_safe(v):
    """``v`` for a strict JSON file: NaN as null, infinities as "inf" / "-inf", numpy
    scalars as Python numbers, through dicts, lists and tuples."""
    if isinstance(v, float) and not math.isfinite(v):
        return None if math.isnan(v) else ("inf" if v > 0 else "-inf")
    if isinstance(v, dict):
        return {k: json_safe(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [json_safe(x) for x in v]
    if isinstance(v, np.generic):
        return json_safe(v.item())
    return v


def write_results(out: Path, results: dict) -> None:
    """results.csv and results.json, each written to a temporary file and renamed."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=columns(), lineterminator="\n")
    writer.writeheader()
    for row in results["rows"]:
        writer.writerow({k: _csv_value(v) for k, v in flat(row).items()})
    # Together: a full disk never leaves a new results.csv beside the last run's JSON.
    files.write_together([(out / "results.csv", buf.getvalue().encode()),
                          (out / "results.json", json.dumps(json_safe(results),
                                                            indent=1).encode())])


def tuned_results() -> dict | None:
    """What the report shows of the tuned presets (aolab.presets' file): each method's entry
    without its search-space description, and where they came from; None without any."""
    path = presets_mod.tuned_file()
    try:
        data = json.loads(files.read_text(path, "tuned presets"))
    except (OSError, ValueError):
        return None
    methods = {m: {k: v for k, v in e.items() if k != "search_space"}
               for m, e in data.get("methods", {}).items()}
    if not methods:
        return None
    runs: dict = {}     # one run writes each method's entry as it finishes: group them
    for e in methods.values():
        runs.setdefault((e.get("command", "?"), e.get("commit", "?")), []).append(
            e.get("date", "?"))
    source = "; ".join(f"`{c}` at commit {k}, "
                       + (min(d) if min(d) == max(d) else f"{min(d)} to {max(d)}")
                       for (c, k), d in sorted(runs.items()))
    return {"file": path.name, "source": source, "methods": methods}
