"""``aolab compare``: every method against the Cycles reference on every reference scene,
timed and scored, with a report (docs/comparison.md).

    aolab compare [SCENES...] [--methods M ...] [--sweep quick|presets|full] [--out DIR]

For each scene (a reference_scenes/<name> folder with reference.exr) and each configuration
of each method (aolab.presets), the method is run ``warmup`` + ``repeat`` times at the
scene's R; the median of the timed runs is its time, and the shared blur (if the
configuration has one) is timed apart in the same way. The output is scored against the
1024-spp reference on the scored pixels and on each region of aolab.regions, beside the
"AO = 1" baseline and the peers of reference_scenes/<name>/peers/ (Cycles at fewer samples,
an independent 1024-spp render, EEVEE's GTAO). Results go to DIR/results.csv,
DIR/results.json and DIR/report.html, with the report's images and scripts in
DIR/report_files/. While the study runs they are written to the staging folder DIR.partial/
beside DIR (atomically, after every scene) and moved into DIR only when the study is complete:
Ctrl-C keeps what is done in DIR.partial/ and leaves the results of an earlier complete run in
DIR untouched (docs/conventions.md, "Output folders").
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import signal
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import aolab

from .. import catalog
from .. import named_presets as presets_mod
from ..raytracing import RTAO_LADDER
from ..regions import DESCRIPTIONS as REGION_DESCRIPTIONS
from ..regions import REGIONS
from ..scenes import (Crop, Scene, check_sequence, find_scenes_dir, frame_folder, frame_numbers,
                      frame_scene_name, load_cropped, load_scene, manifest, noise_floor_peer,
                      resolve_scenes, scene_files)
from ..scoring import check_same_bits, digest, signed_error_rgb
from ..util import files
from ..util.dask_cluster import ClusterSecurity, connect, crop_key, wait_all, worker_scene
from ..util.provenance import git_commit, machine_info
from . import report, report_files, stats
from .pareto import hd_scale
from .findings import ACCUMULATED_SUFFIX, WEAK_FRACTION
from .temporal import DISOCCLUDED, Accumulation, accumulation_scores
from .timing import time_fields, timed

#: Metrics per region, in column order.
METRICS = ("mae", "rmse", "psnr", "bias", "ssim", "mae_cal", "count")
#: The SSIM window's radius (docs/metrics.md): the mean is taken this far from the edge.
SSIM_CROP = 5
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
# Scoring


def _stats(d: np.ndarray) -> dict:
    n = d.size
    if n == 0:
        return {"mae": math.nan, "rmse": math.nan, "psnr": math.nan, "bias": math.nan}
    mse = float(np.mean(d * d))
    return {"mae": float(np.mean(np.abs(d))), "rmse": math.sqrt(mse),
            "psnr": 10 * math.log10(1 / mse) if mse > 0 else math.inf,
            "bias": float(np.mean(d))}


#: Iterations and residual floor of the least-absolute-deviations fit, and the most pixels
#: it is fitted on (every k-th scored pixel in row-major order beyond that).
CALIBRATION_ITERATIONS = 30
CALIBRATION_EPS = 1e-6
CALIBRATION_MAX_PIXELS = 200_000


def _lad_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    a, b = 1.0, 0.0
    residual = np.abs(y - x)
    best = (float(np.mean(residual)), a, b)
    for _ in range(CALIBRATION_ITERATIONS):
        # the weights from the residuals the MAE of (a, b) was measured on: one pass fewer
        w = 1.0 / np.maximum(residual, CALIBRATION_EPS)
        wx = w * x
        sw, sx, sy = w.sum(), wx.sum(), (w * y).sum()
        sxx, sxy = (wx * x).sum(), (wx * y).sum()
        det = sw * sxx - sx * sx
        if det <= 0:
            break
        a, b = (sw * sxy - sx * sy) / det, (sxx * sy - sx * sxy) / det
        residual = np.abs(y - a * x - b)
        mae = float(np.mean(residual))
        if mae < best[0] - 1e-7:
            best = (mae, a, b)
        else:
            best = min(best, (mae, a, b))
            break
    return best[1], best[2]


def calibration(ao: np.ndarray, reference: np.ndarray, mask: np.ndarray) -> tuple[float, float]:
    """The affine map a·ao + b with the least mean absolute deviation from ``reference`` over
    ``mask``: the best affine fit for the MAE (a least-squares fit can raise the MAE when most
    pixels are white and a few errors are large).

    Iteratively reweighted least squares (weights 1/max(|residual|, CALIBRATION_EPS)), a
    majorise-minimise scheme, started from the identity (a = 1, b = 0) and fitted on at most
    CALIBRATION_MAX_PIXELS evenly strided scored pixels; the fit is kept only if it lowers
    the MAE over all of ``mask``, so the calibrated MAE is at most the raw MAE. A constant
    ``ao`` gives a = 0 and b = the median of the reference."""
    x = ao[mask].astype(np.float64)
    y = reference[mask].astype(np.float64)
    if x.size == 0:
        return math.nan, math.nan
    if float(np.ptp(x)) <= 1e-12:
        return 0.0, float(np.median(y))
    k = max(1, math.ceil(x.size / CALIBRATION_MAX_PIXELS))
    a, b = _lad_fit(x[::k], y[::k])
    if np.mean(np.abs(y - a * x - b)) >= np.mean(np.abs(y - x)):
        return 1.0, 0.0
    return float(a), float(b)


def score(ao: np.ndarray, scene: Scene) -> dict:
    """Metrics of ``ao`` against the scene's reference on every region, and the calibration.

    Returns {"regions": {region: {mae, rmse, psnr, bias, ssim, mae_cal, count}},
    "calib_a": a, "calib_b": b, "occluded_definition": the occluded MAE minus the occluded
    MAE after the affine map fitted on the occluded region (None when it is empty)}. SSIM of
    a region is the mean of the whole-frame SSIM map (unscored pixels set to 1 in both
    images, as aolab.metrics does) over the region's pixels
    at least SSIM_CROP px from the edge, so that a region's score does not depend on what
    lies outside it; on "all" it equals aolab.metrics' SSIM. The calibration a, b is fitted
    once on all scored pixels and applied on every region.
    """
    valid = scene.regions["all"]
    ref = scene.reference
    a_img = np.where(valid, ao, 1.0).astype(np.float32)
    r_img = np.where(valid, ref, 1.0).astype(np.float32)
    smap = aolab._core.ssim_map(a_img, r_img)
    interior = np.zeros(valid.shape, bool)
    h, w = valid.shape
    if h > 2 * SSIM_CROP and w > 2 * SSIM_CROP:
        interior[SSIM_CROP:h - SSIM_CROP, SSIM_CROP:w - SSIM_CROP] = True
    ca, cb = calibration(ao, ref, valid)
    d_all = ao.astype(np.float64) - ref
    d_cal = (ca * ao.astype(np.float64) + cb) - ref
    # The error split's "definition": what an affine map fitted on the occluded region itself
    # removes there (the whole-frame fit above is ruled by the many white pixels).
    occ = scene.regions["occluded"]
    definition = None
    if occ.any():
        oa, ob = calibration(ao, ref, occ)
        definition = float(np.mean(np.abs(d_all[occ])) -
                           np.mean(np.abs(oa * ao[occ].astype(np.float64) + ob - ref[occ])))
    out = {}
    for region in REGIONS:
        m = scene.regions[region]
        stats = _stats(d_all[m])
        stats["mae_cal"] = float(np.mean(np.abs(d_cal[m]))) if m.any() else math.nan
        inner = m & interior
        pick = inner if inner.any() else m
        stats["ssim"] = float(np.mean(smap[pick], dtype=np.float64)) if pick.any() else math.nan
        stats["count"] = int(m.sum())
        out[region] = stats
    return {"regions": out, "calib_a": ca, "calib_b": cb, "occluded_definition": definition}


def vs_limit(ao: np.ndarray, scene: Scene) -> float | None:
    """The MAE between ``ao`` and the scene's screen-space limit on the occluded region: the
    error of a method's approximation and sampling, apart from what any screen-space method
    loses (the limit against the reference) — docs/comparison.md, "The error split"."""
    m = scene.regions["occluded"]
    if scene.limit is None or not m.any():
        return None
    return float(np.mean(np.abs(ao[m].astype(np.float64) - scene.limit.ao[m])))


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


def _samples(scene: Scene) -> int:
    """The reference's samples per pixel from its sidecar (0 when unknown)."""
    try:
        return int((scene.g.sidecar or {}).get("samples") or 0)
    except (TypeError, ValueError):
        return 0


# ----------------------------------------------------------------------------------------
# Rows


def _row(scene: Scene | str, kind: str, method: str, label: str, **extra) -> dict:
    name = scene if isinstance(scene, str) else scene.name
    row = {"key": row_key(name, method, label), "scene": name, "kind": kind,
           "method": method, "label": label, "note": ""}
    if not isinstance(scene, str):
        row.update(width=scene.g.width, height=scene.g.height, radius=scene.radius)
        if scene.sequence is not None:
            row.update(sequence=scene.sequence, frame=scene.frame)
    row.update(extra)
    return row


def _add_scores(row: dict, scored: dict) -> None:
    row["calib_a"], row["calib_b"] = scored["calib_a"], scored["calib_b"]
    row["occluded_mae_definition"] = scored.get("occluded_definition")
    row["metrics"] = {region: dict(m) for region, m in scored["regions"].items()}


def _score_row(scene: Scene, row: dict, ao: np.ndarray, scored: dict | None = None) -> None:
    """Scores ``row`` (``scored``: its scores when already computed) and, on a frame of a
    sequence, keeps ``ao`` for the flicker against the next frame; on a frame of a sequence
    with motion, also its MAE on the frame's disoccluded region."""
    _add_scores(row, scored if scored is not None else score(ao, scene))
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
        agg = _row(name, kind, method, label, n_scenes=len(rs),
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


#: The files a study writes, in the order publish() moves them (results.json, which says
#: whether the study is complete, last).
OUTPUT_FILES = ("results.csv", "report.html", "results.json")
#: The suffix of the staging folder beside the output folder (staging_folder).
STAGING_SUFFIX = ".partial"


def staging_folder(out: Path) -> Path:
    """``<out>.partial``, beside the output folder: the study writes its files there while it
    runs (after every scene) and moves them into ``out`` only when it is complete, so an
    interrupted or failed run leaves the complete results of an earlier run in ``out``
    untouched and its own partial results in the staging folder."""
    out = Path(out)
    if out.name in ("", ".", ".."):    # name it by its absolute path
        out = Path(os.path.abspath(out))
    return out.with_name(out.name + STAGING_SUFFIX)


def check_out(out: Path) -> None:
    """A ValueError unless ``out`` and its staging folder can be folders: neither, nor any
    folder above them, is an existing file (or anything else that is not a folder)."""
    out = Path(out)
    if out.resolve() == Path(out.resolve().anchor):
        raise ValueError(f"--out must be a folder below the file-system root (the study "
                         f"stages its files beside it), got {str(out)!r}")
    for path, what in ((out, "the output folder"), (staging_folder(out), "its staging folder")):
        for p in [path, *path.parents]:
            if p.exists() and not p.is_dir():
                raise ValueError(f"--out must be a folder, got {str(out)!r}: {what} "
                                 f"{str(path)!r} cannot be made because {str(p)!r} is an "
                                 "existing file, not a folder")


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


# ----------------------------------------------------------------------------------------
# The study


#: A first run longer than this (ms) is a configuration's only timed run: the slow ones (the
#: visibility bitmask's defaults take over a second) would otherwise hold the study up by
#: their warm-up and repeats, which change their time by less than its spread.
DEFAULT_MAX_MS = 1000.0


@dataclass
class Options:
    scenes: list[str] = field(default_factory=list)
    #: Without scenes: every still and sequence of the corpus, not the default study's.
    corpus: bool = False
    methods: list[str] | None = None
    sweep: str = "quick"
    out: Path = Path("out/compare")
    threads: int = 0
    warmup: int = 1
    repeat: int = 3
    budget_ms: float = 1000.0
    #: A configuration whose first run takes longer is timed by that run alone.
    max_ms: float = DEFAULT_MAX_MS
    crop: Crop | None = None
    scenes_dir: Path | None = None
    progress: bool = True
    image_width: int = 480
    #: rtao's rays per pixel on each scene with a mesh (empty: no rtao rows).
    rtao_ladder: tuple[int, ...] = RTAO_LADDER
    #: Score the configurations on a Dask cluster: a local one of this many workers, or the
    #: scheduler's; the times are still measured here.
    workers: int = 1
    scheduler: str | None = None
    #: How to meet a remote scheduler (TLS files, or consent to plain tcp on the network).
    security: ClusterSecurity | None = None
    #: Read a scene's files through symbolic links (scenes.check_confined); refused without.
    follow_symlinks: bool = False


def _downscale(a: np.ndarray, width: int) -> np.ndarray:
    k = max(1, math.ceil(a.shape[1] / width))
    if k == 1:
        return a.astype(np.float32)
    h, w = (a.shape[0] // k) * k, (a.shape[1] // k) * k
    a = a[:h, :w].astype(np.float32)
    return a.reshape(h // k, k, w // k, k, *a.shape[2:]).mean(axis=(1, 3))


class _Images:
    """A scene's images for the report: every scored configuration's AO and signed error
    (encoded as it is offered, so that no full-size image is kept), and per method the best
    configuration within the time budget (lowest MAE on all scored pixels) and the fastest
    one, as the fallback when none fits, for the image grid."""

    def __init__(self, budget_ms: float, scene: Scene, width: int, encoded: bool = True):
        self.budget = budget_ms
        self.scene = scene
        self.width = width
        #: False: no image is encoded (a sequence's frames after the first, never shown).
        self.encoded = encoded
        self.best: dict[str, dict] = {}
        self.fastest: dict[str, dict] = {}
        #: "method/label" -> {"ao": WebP bytes, "error": WebP bytes}
        self.configs: dict[str, dict] = {}
        self._last = None   # (the last image encoded, its encoding)

    def encode(self, row: dict, ao: np.ndarray) -> None:
        """Keeps the row's AO and signed error (ao - reference, 0 off the scored pixels),
        downscaled to at most ``width`` px and encoded."""
        if not self.encoded:
            return
        if self._last is None or self._last[0] is not ao:   # (a blur group shares its image)
            valid = self.scene.regions["all"]
            err = np.where(valid, ao.astype(np.float64) - self.scene.reference, 0.0)
            self._last = (ao, {
                "ao": report_files.webp_bytes(_downscale(ao, self.width)),
                "error": report_files.webp_bytes(signed_error_rgb(_downscale(err, self.width)))})
        self.configs[f'{row["method"]}/{row["label"]}'] = self._last[1]

    def offer(self, row: dict, ao: np.ndarray) -> None:
        if "metrics" not in row or row.get("total_ms") is None:
            return
        self.encode(row, ao)
        m, t = row["metrics"]["all"]["mae"], row["total_ms"]
        name = row["method"]
        best = self.best.get(name)
        if t <= self.budget and (best is None or m < best["metrics"]["all"]["mae"]):
            self.best[name] = row
        if name not in self.fastest or t < self.fastest[name]["total_ms"]:
            self.fastest[name] = row

    def chosen(self):
        for name in self.fastest:
            if name in self.best:
                yield self.best[name], True
            else:
                yield self.fastest[name], False


#: Peers whose images the report shows: those plotted (the Cycles ladder, EEVEE) and the
#: screen-space limits (the image grid shows the chosen one).
IMAGED_PEERS = ("cycles", "eevee", LIMIT_KIND)


def _peer_images(scene: Scene, rows: list[dict], images: _Images):
    """Encodes every peer of IMAGED_PEERS; yields, for the grid, EEVEE, the Cycles rung with
    most samples within the budget (else the cheapest), and the scene's screen-space limit."""
    by_name = {r["method"]: r for r in rows if r["scene"] == scene.name}
    for p in scene.peers:
        if p.kind in IMAGED_PEERS and p.name in by_name:
            images.encode(by_name[p.name], p.ao)
    cycles = [p for p in scene.peers if p.kind == "cycles" and p.render_time_s is not None]
    fits = [p for p in cycles if p.render_time_s * 1000 <= images.budget]
    pick = max(fits, key=lambda p: p.entry.get("samples", 0)) if fits else (
        min(cycles, key=lambda p: p.render_time_s) if cycles else None)
    chosen = [p for p in scene.peers if p.kind == "eevee"] + ([pick] if pick else [])
    for p in chosen:
        if p.name in by_name:
            yield by_name[p.name], p is not pick or bool(fits)
    if scene.limit is not None and scene.limit.name in by_name:
        yield by_name[scene.limit.name], True


def scene_images(scene: Scene, images: _Images, rows: list[dict]) -> dict:
    """A scene's images for the report, encoded (report_files.webp_bytes): the reference,
    every imaged configuration's AO and signed error ("configs", by "method/label"), and the
    image grid's entries, each naming its configuration."""
    valid = scene.regions["all"]
    entries = []
    shown = list(images.chosen()) + list(_peer_images(scene, rows, images))
    for row, within in shown:
        entries.append({"key": row["key"], "config": f'{row["method"]}/{row["label"]}',
                        "method": row["method"], "label": row["label"],
                        "kind": row["kind"], "total_ms": row.get("total_ms"),
                        "mae": row["metrics"]["all"]["mae"], "within_budget": within})
    reference = _downscale(np.where(valid, scene.reference, 1.0), images.width)
    return {"reference": report_files.webp_bytes(reference), "configs": images.configs,
            "entries": entries, "size": [reference.shape[1], reference.shape[0]]}


def config_accuracy(folder: str, crop, name: str | None, method: str, compute_settings: dict,
                    blurs: list[bool], frame: int | None = None,
                    follow_symlinks: bool = False) -> dict:
    """On a Dask worker: one configuration group's output on a scene (read from ``folder``,
    shared storage, once per worker; at ``frame``, the frame's index in a sequence with
    motion), blurred or not as ``blurs`` asks, scored: blur -> (score, vs_limit, digest),
    None for an RGB output; {"error": message} when the method refuses the settings."""
    scene = worker_scene((__name__, folder, crop_key(crop), name, follow_symlinks),
                         lambda: load_scene(Path(folder), crop, name,
                                            follow_symlinks=follow_symlinks))
    try:
        raw = np.asarray(aolab.compute(method, scene.g, radius=scene.radius, threads=1,
                                       frame=frame, **compute_settings))
    except (ValueError, RuntimeError) as e:
        return {"error": str(e)}
    out = {}
    for blur in blurs:
        ao = presets_mod.shared_blur(raw, scene.g, threads=1) if blur and raw.ndim == 2 else raw
        out[blur] = None if ao.ndim != 2 else (score(ao, scene), vs_limit(ao, scene), digest(ao))
    return out


def from_cluster(remote: dict, blur: bool, ao: np.ndarray, scene: str, method: str) -> tuple:
    """The cluster's (score, vs_limit) of the output timed here, which must have the same
    bits as the worker's."""
    scored, limit, theirs = remote[blur]
    check_same_bits(theirs, digest(ao), method, scene)
    return scored, limit


def rtao_not_run_reason(e: BaseException) -> str:
    """Why rtao did not run on a scene, as results.json keeps it: a missing mesh said without
    its path (the run's command line says where; the results name no folder of the machine),
    any other reason (a mesh of another scene, a refused range) as it is."""
    if isinstance(e, FileNotFoundError):
        return ("no reference.mesh beside its G-buffer (`aolab mesh` exports one, "
                "docs/methods/rtao.md)")
    return str(e)


def _method_runs(method: str, sweep: str) -> list[tuple[dict, list]]:
    """The configurations of ``method`` grouped by what the method computes (its settings over
    the defaults, whether spelled out or not): configurations that differ only in the blur,
    or only in their names (the defaults and a preset equal to them), share one timed run."""
    groups: dict[tuple, tuple[dict, list]] = {}
    for s in presets_mod.settings_for(method, sweep):
        key = presets_mod.identity(method, s.compute_settings(), False)
        groups.setdefault(key, (s.compute_settings(), []))[1].append(s)
    return list(groups.values())


class Study:
    """One run of the comparison; ``rows`` grows as configurations finish."""

    def __init__(self, opts: Options):
        self.opts = opts
        self.rows: list[dict] = []
        self.complete_scenes: list[str] = []
        self.scene_info: dict[str, dict] = {}
        self.images: dict[str, dict] = {}
        self.notes: list[str] = []
        self.meta: dict = {}
        #: Every scene is done and the staging folder holds the complete results.
        self.complete = False
        #: The Dask client and local cluster that score configurations (--workers, --scheduler).
        self.client = self.cluster = None

    def results(self, partial: bool) -> dict:
        rows = list(self.rows)
        flag_rows(rows)
        # ALL is the mean over the still scenes: a sequence's frames have their own size (the
        # committed one 320x180), so their times would pull the means of the stills' 1280x720
        # times down; sequences have their own rows and section (temporal stability).
        stills = [n for n in self.complete_scenes
                  if not self.scene_info.get(n, {}).get("sequence")]
        scale = {n: self.scene_info[n].get("time_scale", 1.0) for n in stills}
        agg = aggregate(rows, stills, time_scale=scale) if stills else []
        meta = dict(self.meta)
        meta["partial"] = partial
        meta["finished"] = time.strftime("%Y-%m-%d %H:%M:%S")
        meta["elapsed_s"] = time.perf_counter() - self._t0
        meta["load_average_end"] = list(os.getloadavg()) if hasattr(os, "getloadavg") else None
        meta["complete_scenes"] = list(self.complete_scenes)
        return {"meta": meta, "scenes": self.scene_info, "notes": self.notes,
                "regions": REGION_DESCRIPTIONS, "rows": rows + agg, "tuned": tuned_results()}

    @property
    def staging(self) -> Path:
        """Where the study's files are written while it runs (staging_folder)."""
        return staging_folder(Path(self.opts.out))

    def write(self, partial: bool) -> dict:
        """results.csv, results.json and report.html into the staging folder, each atomically
        (publish() moves them into the output folder once the study is complete)."""
        staging = self.staging
        staging.mkdir(parents=True, exist_ok=True)
        results = self.results(partial)
        write_results(staging, results)
        report.write_report(staging / "report.html", results, self.images)
        return results

    def publish(self) -> None:
        """Moves the complete study's files from the staging folder into the output folder,
        each with an atomic rename: first the report's images and scripts (report_files/,
        named by their content, beside the earlier report's), then results.csv, report.html
        and results.json (which says whether the study is complete) last; then removes the
        files of report_files/ that the new report.html does not name, and the staging
        folder. Interrupted anywhere, the output folder's report.html finds all its files.
        Other files in the output folder are left alone."""
        out, staging = Path(self.opts.out), self.staging
        out.mkdir(parents=True, exist_ok=True)
        report_files.move_in(staging, out)
        for name in OUTPUT_FILES:
            if (staging / name).exists():   # (a publish that was interrupted moved some)
                os.replace(staging / name, out / name)
        report_files.prune(out / "report.html")
        try:
            staging.rmdir()
        except OSError:  # someone put something else there: leave it
            pass

    def run(self) -> dict:
        opts = self.opts
        self._t0 = time.perf_counter()
        check_out(Path(opts.out))
        scenes_dir = opts.scenes_dir or find_scenes_dir()
        follow = opts.follow_symlinks
        folders = resolve_scenes(opts.scenes, scenes_dir, default_study=not opts.corpus,
                                 follow_symlinks=follow)
        out, staging = Path(opts.out), staging_folder(opts.out)
        files.check_paths(reads=scene_files(folders),
                          made={"--out": [f / n for f in (out, staging) for n in OUTPUT_FILES]},
                          cleared={"the report folder of --out": out / report_files.FOLDER})
        motion = {}   # sequence -> every frame after the first has motion vectors
        for folder in folders:  # every scene's errors before any work
            if frame_numbers(folder):
                motion[folder] = check_sequence(folder, opts.crop, follow_symlinks=follow)
            else:
                load_cropped(folder, opts.crop, follow_symlinks=follow)
        report_files.check_names_fit(Path(opts.out))
        # Oracles (method_info "oracle") are bounds, not contenders, and slow: they run only
        # when named.
        methods = opts.methods if opts.methods else [
            m for m in aolab.methods() if not aolab.method_info(m).get("oracle", False)]
        known = aolab.methods()
        for m in methods:
            if m not in known:
                raise ValueError(f"method {m!r} is not one of {known}")
        plan = {m: _method_runs(m, opts.sweep) for m in methods}
        frames = sum(len(frame_numbers(f) or [None]) for f in folders)
        n_units = frames * (1 + sum(len(v) for v in plan.values()) + len(opts.rtao_ladder))
        self.meta = {
            "command": "aolab compare", "argv": sys.argv[1:],
            "started": time.strftime("%Y-%m-%d %H:%M:%S"), "sweep": opts.sweep,
            "methods": methods, "scenes": [f.name for f in folders],
            "warmup": opts.warmup, "repeat": opts.repeat, "budget_ms": opts.budget_ms,
            "max_ms": opts.max_ms,
            "crop": None if opts.crop is None else f"{opts.crop.width}x{opts.crop.height}",
            "machine": machine_info(opts.threads), "aolab_commit": git_commit(folders[0]),
            "weak_fraction": WEAK_FRACTION, "blur_sigma": presets_mod.BLUR_SIGMA,
            "blur_taps": presets_mod.BLUR_TAPS,
            "presets_source": {m: (catalog.entry(m).source if catalog.entry(m) else
                                   "no presets registered: the method's defaults")
                               for m in methods},
        }
        threads = opts.threads
        bar = _progress(opts.progress, n_units)
        if opts.scheduler is not None or opts.workers > 1:
            self.client, self.cluster = connect(opts.scheduler, opts.workers, opts.security)
        try:
            for folder in folders:
                if frame_numbers(folder):
                    self._run_sequence(folder, plan, threads, bar, motion[folder])
                else:
                    self._run_scene(folder, plan, threads, bar)
        finally:
            if bar is not None:
                bar.close()
            for held in (self.client, self.cluster):
                if held is not None:
                    held.close()
        results = self.write(partial=False)
        self.complete = True
        self.publish()
        return results

    def _run_sequence(self, folder: Path, plan: dict, threads: int, bar,
                      motion: bool = False) -> None:
        """Each frame scored as a scene of its own (rows of scene <name>@NNNN with ``sequence``
        and ``frame``), each row's flicker against the frame before, the reference's flicker
        floor per pair, then the sequence's rows (scene <name>): means over its frames, the
        flicker over its pairs. The images shown are the first frame's. With ``motion`` (every
        frame after the first has motion vectors) each configuration runs at frame=k and is
        also accumulated (Accumulation): a second row per frame, label + ACCUMULATED_SUFFIX."""
        name = folder.name
        frames = frame_numbers(folder)
        names = [frame_scene_name(name, f) for f in frames]
        floors, previous = [], None
        temporal = Accumulation(self.opts.warmup + self.opts.repeat) if motion else None
        for index, (frame, frame_name) in enumerate(zip(frames, names)):
            scene = self._run_scene(frame_folder(folder, frame), plan, threads, bar,
                                    name=frame_name, sequence=(name, frame),
                                    shown=frame == frames[0],
                                    temporal=(temporal, index) if temporal else None)
            if previous is not None:
                floors.append(self._flicker(previous, scene))
            previous = scene
        first = self.scene_info[names[0]]
        floor = [f for f in floors if f is not None]
        self.scene_info[name] = {
            "folder": str(folder), "sequence": True, "frames": frames, "frame_scenes": names,
            "width": first["width"], "height": first["height"], "radius": first["radius"],
            "title": manifest(folder).get("title", name), "samples": _samples(previous),
            "flicker_floor": {
                "value": float(np.mean(floor)), "pairs": floors, "estimated": True,
                "source": "upper estimate from the reference's own values: binomial noise "
                          "v(1 - v)/N per pixel and frame, independent between frames (2-4x "
                          "the noise Cycles' stratified samples have on the stills)"}
            if floor else None}
        mine = [r for r in self.rows if r.get("sequence") == name]
        means = aggregate(mine, names, name, unit="frame")
        if temporal is not None:
            self.scene_info[name]["accumulation"] = accumulation_scores(mine, means, frames,
                                                                        temporal)
        for r in means:
            r["sequence"] = name
            self.rows.append(r)
        self.images[name] = self.images.get(names[0])
        self.complete_scenes.append(name)
        self.write(partial=True)

    def _flicker(self, previous: Scene, scene: Scene) -> float | None:
        """Sets the flicker of every row of ``scene`` scored in both frames (against
        ``previous``) and returns the reference's flicker floor for the pair."""
        valid_prev, valid = previous.regions["all"], scene.regions["all"]
        for r in self.rows:
            if r["scene"] != scene.name:
                continue
            kept = (r["kind"], r["method"], r["label"])
            if kept in previous.outputs and kept in scene.outputs:
                r["flicker"] = flicker(previous.outputs[kept], scene.outputs[kept],
                                       previous.reference, scene.reference, valid_prev, valid)
        previous.outputs = None     # only the frame before is needed: free its images
        return flicker_floor(previous.reference, scene.reference, valid_prev, valid,
                             min(_samples(previous), _samples(scene)))

    def _run_scene(self, folder: Path, plan: dict, threads: int, bar, name: str | None = None,
                   sequence: tuple[str, int] | None = None, shown: bool = True,
                   temporal: tuple | None = None) -> Scene:
        """One scene (or, with ``name`` and ``sequence`` = (its name, the frame), one frame of
        a sequence, whose images are then kept for the flicker); ``shown``: its images are
        made for the report (a sequence shows its first frame's); ``temporal``: (the
        sequence's Accumulation, the frame's index) for a sequence with motion."""
        opts = self.opts
        if bar is not None:
            bar.set_description(f"{name or folder.name}: loading")
        scene = load_scene(folder, opts.crop, name, follow_symlinks=opts.follow_symlinks)
        if sequence is not None:
            scene.sequence, scene.frame = sequence
            scene.outputs = {}
        if temporal is not None:
            temporal[0].begin_frame(scene, temporal[1], opts.warmup, opts.repeat, threads)
        self.notes.extend(f"{scene.name}: {n}" for n in scene.notes)
        self.scene_info[scene.name] = {
            "folder": str(folder), "width": scene.g.width, "height": scene.g.height,
            "radius": scene.radius,
            "region_pixels": {r: int(m.sum()) for r, m in scene.regions.items()},
            "peers": [p.name for p in scene.peers if p.kind != LIMIT_KIND],
            "limits": [p.name for p in scene.peers if p.kind == LIMIT_KIND],
            "title": manifest(folder).get("title", scene.name),
            "family": manifest(folder).get("family"),
            # ALL's times are per 1280x720 frame; a crop's stay the crop's (pareto.hd_scale)
            "time_scale": 1.0 if opts.crop else hd_scale(scene.g.width, scene.g.height),
        }
        images = _Images(opts.budget_ms, scene, opts.image_width, encoded=shown)
        # The baseline, AO = 1 everywhere: no occlusion at all, no time.
        base = _row(scene, "baseline", BASELINE, "AO=1", preset="", settings={},
                    note="no occlusion at all (AO = 1 everywhere)")
        _score_row(scene, base, np.ones_like(scene.reference))
        self.rows.append(base)
        self._peers(scene)
        if bar is not None:
            bar.update(1)
        frame = temporal[1] if temporal is not None else None
        remote = (self._score_on_cluster(folder, name, plan, bar, frame) if self.client
                  else {})
        for method, runs in plan.items():
            for i, (compute_settings, settings) in enumerate(runs):
                if bar is not None:
                    bar.set_description(f"{scene.name}: {method} {settings[0].label}")
                self._run_config(scene, method, compute_settings, settings, threads, images,
                                 remote.get((method, i)),
                                 temporal[0] if temporal is not None else None)
                if bar is not None:
                    bar.update(1)
        self._rtao_ladder(scene, threads, images, bar)
        self._noise_floor(scene)
        if shown:
            self.images[scene.name] = scene_images(scene, images, self.rows)
        if sequence is None:   # a sequence is complete with its last frame (_run_sequence)
            self.complete_scenes.append(scene.name)
            # (a frame's rows are written with its sequence's: the partial files after every
            # frame cost a third of a sequence's time; Ctrl-C still writes what is done)
            self.write(partial=True)
        return scene

    def _score_on_cluster(self, folder: Path, name: str | None, plan: dict, bar,
                          frame: int | None = None) -> dict:
        """(method, index in its runs) -> config_accuracy's result for each configuration of
        the scene, computed on the cluster before any is timed here: the workers are idle
        while this machine times (a local cluster shares its cores)."""
        if bar is not None:
            bar.set_description(f"{name or folder.name}: scoring on the cluster")
        futures = {(method, i): self.client.submit(
            config_accuracy, str(folder), self.opts.crop, name, method, compute_settings,
            sorted({bool(s.blur) for s in settings}), frame, self.opts.follow_symlinks,
            pure=False)
            for method, runs in plan.items() for i, (compute_settings, settings) in enumerate(runs)}
        wait_all(self.client, list(futures.values()), lambda: None)
        return {k: f.result() for k, f in futures.items()}

    def _run_config(self, scene, method, compute_settings, settings, threads, images,
                    remote: dict | None = None, temporal: Accumulation | None = None):
        """One group of configurations (the same compute settings, blurred or not): timed
        here, scored here or, with ``remote`` (config_accuracy's result), on the cluster. With
        ``temporal`` (a frame of a sequence with motion) the method runs at frame=k, and each
        configuration also gets its accumulated row (_accumulated_rows)."""
        opts = self.opts
        g = scene.g
        frame = temporal.index if temporal is not None else None
        extra = {} if temporal is None else {"accumulated": False, "frame_index": frame}
        try:
            if remote is not None and "error" in remote:
                raise ValueError(remote["error"])
            raw, times = timed(lambda: aolab.compute(method, g, radius=scene.radius,
                                                     threads=threads, frame=frame,
                                                     **compute_settings),
                               opts.warmup, opts.repeat, opts.max_ms)
        except (ValueError, RuntimeError) as e:
            for s in settings:
                self.rows.append(_row(scene, "method", method, s.label, preset=s.preset or "",
                                      settings=s.recorded_settings(), threads=threads,
                                      note=f"error: {e}", **extra))
            if temporal is not None:
                for s in settings:
                    self.rows.append(_row(scene, "method", method, s.label + ACCUMULATED_SUFFIX,
                                          preset=s.preset or "", settings=s.recorded_settings(),
                                          threads=threads, note=f"error: {e}",
                                          **dict(extra, accumulated=True)))
            return
        raw = np.asarray(raw)
        # Configurations of the group with the same blur switch give the same image: it is
        # blurred, timed and scored once and its numbers are shared.
        done: dict[bool, tuple] = {}
        for s in settings:
            row = _row(scene, "method", method, s.label, preset=s.preset or "",
                       settings=s.recorded_settings(), threads=threads, runs=len(times),
                       **extra, **time_fields("method", times))
            blur = bool(s.blur and raw.ndim == 2)
            if blur not in done:
                ao, blur_times = raw, []
                if blur:
                    ao, blur_times = timed(lambda: presets_mod.shared_blur(raw, g, threads),
                                           opts.warmup, opts.repeat)
                scored = (None if ao.ndim != 2 else
                          from_cluster(remote, blur, ao, scene.name, method) if remote else
                          (score(ao, scene), vs_limit(ao, scene)))
                done[blur] = (ao, blur_times, scored)
            ao, blur_times, scored = done[blur]
            row.update(time_fields("blur", blur_times))
            row["total_ms"] = row["method_ms"] + (row.get("blur_ms") or 0.0)
            if scored is None:
                row["note"] = (f"output has shape {ao.shape} (RGB, e.g. colour bleeding): timed, "
                               "not scored against the grey AO reference")
            else:
                _score_row(scene, row, ao, scored[0])
                row["occluded_mae_vs_limit"] = scored[1]
                images.offer(row, ao)
            self.rows.append(row)
        if temporal is not None:
            self._accumulated_rows(scene, method, compute_settings, settings, threads, temporal,
                                   done, times)

    def _accumulated_rows(self, scene, method, compute_settings, settings, threads,
                          temporal: Accumulation, done: dict, times: list[float]) -> None:
        """Each configuration of a group accumulated: its output of this frame (``done``:
        blur -> (output, blur times, scores)) blended into the history of that output, scored
        like any output; its time the method's and the blur's, as its single-frame row's,
        plus the step's (Accumulation.begin_frame). An RGB output is not accumulated."""
        accumulated: dict[bool, tuple] = {}
        for s in settings:
            blur = bool(s.blur)
            if blur not in done:   # (an RGB output has only the unblurred entry)
                blur = False
            ao, blur_times, scored = done[blur]
            row = _row(scene, "method", method, s.label + ACCUMULATED_SUFFIX,
                       preset=s.preset or "", settings=s.recorded_settings(), threads=threads,
                       runs=len(times), accumulated=True, frame_index=temporal.index,
                       **time_fields("method", times), **time_fields("blur", blur_times),
                       **time_fields("accumulate", temporal.times))
            row["total_ms"] = (row["method_ms"] + (row.get("blur_ms") or 0.0)
                               + row["accumulate_ms"])
            if scored is None:
                row["note"] = "RGB output: not accumulated (the step takes 1-channel AO)"
                self.rows.append(row)
                continue
            if blur not in accumulated:
                key = (method, json.dumps(compute_settings, sort_keys=True, default=str), blur)
                out = temporal.step(key, ao, scene.g, threads)
                accumulated[blur] = (out, score(out, scene), vs_limit(out, scene))
            out, got, limit = accumulated[blur]
            _score_row(scene, row, out, got)
            row["occluded_mae_vs_limit"] = limit
            self.rows.append(row)

    def _rtao_ladder(self, scene: Scene, threads: int, images, bar) -> None:
        """rtao at each rung of the ladder against the scene's mesh (the file beside its
        reference.exr), timed like a method: the BVH is built once and timed apart, its time
        stated in each row's note and settings, not added to the rung's time."""
        ladder = self.opts.rtao_ladder
        if not ladder:
            return
        try:
            mesh = aolab.mesh_for_gbuffer(scene.g)
            rays_scene = aolab.ray_scene(mesh, scene.g, threads=threads)
            # rtao's range rule (docs/conventions.md, "Ranges"), before any rung is timed:
            # a refused scene is noted like a missing mesh, a warned one once.
            offsets = aolab.rtao_range(scene.g, rays_scene, radius=scene.radius,
                                       threads=threads)
            if offsets["refusal"]:
                raise ValueError(offsets["refusal"])
        except (ValueError, OSError) as e:
            self.notes.append(f"{scene.name}: rtao not run ({e})")
            self.scene_info[scene.name]["rtao_not_run"] = rtao_not_run_reason(e)
            if bar is not None:
                bar.update(len(ladder))
            return
        if offsets["warning"]:
            self.notes.append(f"{scene.name}: {offsets['warning']}")
        build_ms = rays_scene.build_seconds * 1000.0
        info = {"triangles": rays_scene.triangles, "bvh_build_ms": build_ms}
        self.scene_info[scene.name]["rtao"] = info
        self.scene_info[scene.name]["rtao_offset"] = {
            k: offsets[k] for k in ("pixels", "warned", "largest_share_of_radius")}
        for rays in ladder:
            if bar is not None:
                bar.set_description(f"{scene.name}: rtao {rays} rays")
            with warnings.catch_warnings():   # noted above, once
                warnings.simplefilter("ignore", aolab.RtaoRangeWarning)
                ao, times = timed(lambda: aolab.rtao(scene.g, rays_scene, radius=scene.radius,
                                                     rays=rays, threads=threads),
                                  self.opts.warmup, self.opts.repeat, self.opts.max_ms)
            row = _row(scene, "rtao", "rtao", f"{rays} ray{'s' if rays != 1 else ''}", preset="",
                       settings={"rays": rays, **info}, threads=threads, runs=len(times),
                       note=f"Embree BVH of {rays_scene.triangles} triangles built in "
                            f"{build_ms:.1f} ms, apart (not in the time)",
                       **time_fields("method", times))
            row["total_ms"] = row["method_ms"]
            _score_row(scene, row, ao)
            row["occluded_mae_vs_limit"] = vs_limit(ao, scene)
            images.offer(row, ao)
            self.rows.append(row)
            if bar is not None:
                bar.update(1)

    def _peers(self, scene: Scene) -> None:
        mine = []
        for p in scene.peers:
            ms = p.render_time_s * 1000 if p.render_time_s is not None else None
            settings = {k: v for k, v in p.entry.items()
                        if k not in ("name", "kind", "file", "render_time_s", "note")}
            row = _row(scene, p.kind, p.name, p.entry.get("label", p.name), preset="",
                       settings=settings, method_ms=ms, total_ms=ms, runs=1 if ms else None,
                       note=p.entry.get("note", ""))
            _score_row(scene, row, p.ao)
            self.rows.append(row)
            mine.append((p, row))
        limits = [(p, r) for p, r in mine if p.kind == LIMIT_KIND
                  and math.isfinite(r["metrics"]["occluded"]["mae"])]
        if limits:
            p, r = min(limits, key=lambda pr: pr[1]["metrics"]["occluded"]["mae"])
            scene.limit = p
            self.scene_info[scene.name]["limit"] = {
                "key": r["key"], "name": p.name, "label": r["label"],
                "thickness_r": p.entry.get("thickness_r"),
                **{f"{reg}_mae": r["metrics"][reg]["mae"] for reg in REGIONS}}
        for p, r in mine:
            if p.kind != LIMIT_KIND:
                r["occluded_mae_vs_limit"] = vs_limit(p.ao, scene)

    def _noise_floor(self, scene: Scene) -> None:
        """The reference's own noise floor (noise_floor_peer), per region, or unknown."""
        mine = {r["method"]: r for r in self.rows if r["scene"] == scene.name and "metrics" in r}
        info = self.scene_info[scene.name]
        chosen = noise_floor_peer(scene.peers)
        if chosen is None:
            info["noise_floor"] = None
            return
        peer, factor, source = chosen
        r = mine[peer.name]
        info["noise_floor"] = {"source": source, "key": r["key"], "estimated": factor != 1.0,
                               **{f"{reg}_mae": r["metrics"][reg]["mae"] * factor
                                  for reg in REGIONS}}
        if factor == 1.0:
            info["noise_floor"]["all_ssim"] = r["metrics"]["all"]["ssim"]


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


def _progress(enabled: bool, total: int):
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=total, unit="run", dynamic_ncols=True, file=sys.stderr)


def run_study(opts: Options) -> int:
    """The study of ``opts`` with its output folder held (``aolab compare``): the exit
    status."""
    study = Study(opts)
    # One run at a time in an output folder: a second one would remove this one's staging
    # folder and publish a mix of both (files.output_lock).
    check_out(opts.out)
    with files.output_lock(opts.out, "aolab compare"):
        return _run(study, opts)


def _run(study: Study, opts: Options) -> int:
    """The study, with Ctrl-C and `kill` keeping the partial results; the exit status."""
    def terminated(signum, frame):  # `kill` keeps the partial results like Ctrl-C
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, terminated)
    try:
        results = study.run()
    except KeyboardInterrupt:
        if not study.meta:
            print("aolab compare: interrupted before the first scene; nothing written",
                  file=sys.stderr)
            return 130
        if study.complete:   # interrupted while moving the complete results: finish that
            study.publish()
            print(f"\naolab compare: interrupted after the study was complete; its results "
                  f"are in {opts.out}/", file=sys.stderr)
            return 130
        study.write(partial=True)
        done = len(study.complete_scenes)
        kept = [n for n in OUTPUT_FILES if (opts.out / n).is_file()]
        earlier = (f"the results of an earlier run in {opts.out}/ are untouched"
                   if kept else f"nothing was written to {opts.out}/")
        print(f"\naolab compare: interrupted. Partial results ({len(study.rows)} rows, "
              f"{done} of {len(study.meta['scenes'])} scenes complete) are in "
              f"{study.staging}/ (results.csv, results.json, report.html marked PARTIAL); "
              f"{earlier}. Run the command again for the full study.", file=sys.stderr)
        return 130
    finally:
        signal.signal(signal.SIGTERM, previous)
    meta = results["meta"]
    # a sequence's configurations are counted once (its rows over the frames), not per frame,
    # and an accumulated row is its configuration's second
    mine = [r for r in results["rows"] if r["kind"] == "method" and r["scene"] in meta["scenes"]]
    n = sum(1 for r in mine if r.get("accumulated") is not True)
    accumulated = sorted({r["scene"] for r in mine if r.get("accumulated") is True})
    also = (f" (each also accumulated on {', '.join(accumulated)})" if accumulated else "")
    print(f"aolab compare: {n} configurations{also} on {len(meta['scenes'])} scenes in "
          f"{meta['elapsed_s']:.0f} s ({meta['machine']['threads']} threads, "
          f"{meta['machine']['cpu']}) -> {opts.out}/report.html, results.csv, results.json")
    return 0
