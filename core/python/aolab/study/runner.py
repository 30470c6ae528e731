"""The study runner: one configuration of a method on one scene, run, blurred, timed and
scored — here, or scored on a Dask worker and its bits checked against the output timed here.
``aolab compare``, ``aolab tune``, ``aolab advise`` and the radius study are drivers over it,
so that they time, score and guard alike (docs/comparison.md, "Timing protocol").

Its parts: the scene (:func:`load_scene`, :func:`make_scene`: a ``scenes.Scene`` with its
time scale), the time (:class:`Timing`, :func:`timed`, :func:`time_fields`), the score
(:func:`score`, :func:`calibration`, :func:`vs_limit`), the run (:func:`run_configuration`,
:func:`score_remotely` on a worker), the whole-frame guard (:func:`whole_frame_ok`) and what
the drivers share around them (:func:`still_scenes`; the progress bar is util.progress.bar).
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import aolab

from .. import named_presets as presets_mod
from ..regions import REGIONS, region_masks
from ..scenes import Scene, load_scene as load_scene_folder
from ..scoring import check_same_bits, digest
from ..util.dask_cluster import crop_key, worker_scene

# ----------------------------------------------------------------------------------------
# The scene

#: Budgets and mean times are per frame of this many pixels (1280x720): a scene's time is
#: scaled by HD_PIXELS / its pixels, since every method's work grows with the pixel count, so
#: that the corpus's 640x360 scenes and the 1280x720 ones weigh alike.
HD_PIXELS = 1280 * 720


def hd_scale(width: int, height: int) -> float:
    """The factor from a width x height frame's time to a 1280x720 frame's."""
    return HD_PIXELS / (width * height)


def load_scene(folder: Path, crop=None, name: str | None = None, *,
               follow_symlinks: bool = False) -> Scene:
    """A scene folder as every study runs it (scenes.load_scene: G-buffer, reference, R,
    regions, peers), its times scaled to a 1280x720 frame; a crop's stay the crop's."""
    scene = load_scene_folder(Path(folder), crop, name, follow_symlinks=follow_symlinks)
    scene.time_scale = 1.0 if crop is not None else hd_scale(scene.g.width, scene.g.height)
    return scene


def make_scene(name: str, g, reference: np.ndarray, radius: float, *,
               time_scale: float | None = None) -> Scene:
    """A scene from a G-buffer and the reference it is scored against (aolab advise's), with
    its regions; ``time_scale`` defaults to the 1280x720 frame's (:func:`hd_scale`)."""
    scale = hd_scale(g.width, g.height) if time_scale is None else time_scale
    return Scene(name, None, g, reference, radius, region_masks(g, reference, radius),
                 time_scale=scale)


# ----------------------------------------------------------------------------------------
# The time


@dataclass
class Timing:
    """How a configuration is timed: ``warmup`` untimed runs, then the median of ``repeat``
    timed ones, on ``threads`` (0: every core); a first run longer than ``max_ms`` is the
    only one, and its time is the time."""
    warmup: int = 1
    repeat: int = 3
    threads: int = 0
    max_ms: float = math.inf


def timed(fn, warmup: int, repeat: int, max_ms: float = math.inf):
    """Runs ``fn`` warmup + repeat times; returns (first output, times of the timed runs in ms).
    The output of the first run is kept (the methods are deterministic). A first run longer
    than ``max_ms`` is the only one, and its time is the time: past a second, a warm-up
    changes the time by far less than the run-to-run spread (``-math.inf``: one run only)."""
    result, times = None, []
    for i in range(warmup + repeat):
        t0 = time.perf_counter()
        out = fn()
        dt = (time.perf_counter() - t0) * 1000.0
        if i == 0:
            result = out
            if dt > max_ms:
                return result, [dt]
        if i >= warmup:
            times.append(dt)
    return result, times


def median_ms(fn, repeat: int, warmup: int = 1) -> float:
    """The median ms of ``repeat`` timed calls of ``fn`` after ``warmup`` untimed ones."""
    return statistics.median(timed(fn, warmup, repeat)[1])


def time_fields(prefix: str, times: list[float]) -> dict:
    """A row's fields of ``times`` (ms): <prefix>_ms (the median), _ms_min and _ms_max, and
    for the method its standard deviation; none without times."""
    if not times:
        return {}
    out = {f"{prefix}_ms": statistics.median(times), f"{prefix}_ms_min": min(times),
           f"{prefix}_ms_max": max(times)}
    if prefix == "method":
        out["method_ms_stdev"] = statistics.stdev(times) if len(times) > 1 else 0.0
    return out


# ----------------------------------------------------------------------------------------
# The score

#: The SSIM window's radius (docs/metrics.md): the mean is taken this far from the edge.
SSIM_CROP = 5
#: Iterations and residual floor of the least-absolute-deviations fit, and the most pixels
#: it is fitted on (every k-th scored pixel in row-major order beyond that).
CALIBRATION_ITERATIONS = 30
CALIBRATION_EPS = 1e-6
CALIBRATION_MAX_PIXELS = 200_000


def _stats(d: np.ndarray) -> dict:
    n = d.size
    if n == 0:
        return {"mae": math.nan, "rmse": math.nan, "psnr": math.nan, "bias": math.nan}
    mse = float(np.mean(d * d))
    return {"mae": float(np.mean(np.abs(d))), "rmse": math.sqrt(mse),
            "psnr": 10 * math.log10(1 / mse) if mse > 0 else math.inf,
            "bias": float(np.mean(d))}


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


def _ssim_map(ao: np.ndarray, scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The whole-frame SSIM map (unscored pixels set to 1 in both images, as aolab.metrics
    does) and the pixels at least SSIM_CROP px from the edge."""
    valid = scene.valid
    a_img = np.where(valid, ao, 1.0).astype(np.float32)
    r_img = np.where(valid, scene.reference, 1.0).astype(np.float32)
    interior = np.zeros(valid.shape, bool)
    h, w = valid.shape
    if h > 2 * SSIM_CROP and w > 2 * SSIM_CROP:
        interior[SSIM_CROP:h - SSIM_CROP, SSIM_CROP:w - SSIM_CROP] = True
    return aolab._core.ssim_map(a_img, r_img), interior


def _definition(ao: np.ndarray, scene: Scene, d_all: np.ndarray) -> float | None:
    """The error split's "definition": what an affine map fitted on the occluded region
    itself removes there (the whole-frame fit is ruled by the many white pixels)."""
    occ, ref = scene.occluded, scene.reference
    if not occ.any():
        return None
    oa, ob = calibration(ao, ref, occ)
    return float(np.mean(np.abs(d_all[occ])) -
                 np.mean(np.abs(oa * ao[occ].astype(np.float64) + ob - ref[occ])))


def score(ao: np.ndarray, scene: Scene, brief: bool = False) -> dict:
    """Metrics of ``ao`` against the scene's reference on every region, and the calibration:
    the one scorer of the studies.

    Returns {"regions": {region: {mae, rmse, psnr, bias, ssim, mae_cal, count}},
    "calib_a": a, "calib_b": b, "occluded_definition": the occluded MAE minus the occluded
    MAE after the affine map fitted on the occluded region (None when it is empty)}. SSIM of
    a region is the mean of the whole-frame SSIM map over the region's pixels at least
    SSIM_CROP px from the edge, so that a region's score does not depend on what lies outside
    it; on "all" it equals aolab.metrics' SSIM. The calibration a, b is fitted once on all
    scored pixels and applied on every region. ``brief``: only the regions "all" and
    "occluded", without SSIM and calibration (what a trial of tune or advise keeps:
    :func:`trial_scores`)."""
    d_all = ao.astype(np.float64) - scene.reference
    if brief:
        return {"regions": {r: _stats(d_all[scene.regions[r]]) for r in ("all", "occluded")}}
    smap, interior = _ssim_map(ao, scene)
    ca, cb = calibration(ao, scene.reference, scene.valid)
    d_cal = (ca * ao.astype(np.float64) + cb) - scene.reference
    definition = _definition(ao, scene, d_all)
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


def trial_scores(ao: np.ndarray, scene: Scene) -> dict:
    """A trial's record of one output (aolab tune, aolab advise): the occluded-region MAE and
    bias, the whole-frame MAE (:func:`score`, brief) and the digest of the output's bits."""
    regions = score(ao, scene, brief=True)["regions"]
    return {"mae": regions["occluded"]["mae"], "bias": regions["occluded"]["bias"],
            "all_mae": regions["all"]["mae"], "digest": digest(ao)}


def vs_limit(ao: np.ndarray, scene: Scene) -> float | None:
    """The MAE between ``ao`` and the scene's screen-space limit on the occluded region: the
    error of a method's approximation and sampling, apart from what any screen-space method
    loses (the limit against the reference) — docs/comparison.md, "The error split"."""
    m = scene.occluded
    if scene.limit is None or not m.any():
        return None
    return float(np.mean(np.abs(ao[m].astype(np.float64) - scene.limit.ao[m])))


# ----------------------------------------------------------------------------------------
# The run


@dataclass
class Output:
    """One output of a configuration: the image, the blur's times (none unblurred) and its
    scores (the scorer's; None for an RGB output, which is timed, not scored)."""
    ao: np.ndarray
    blur_times: list
    scores: object


@dataclass
class Run:
    """A configuration's run on a scene (:func:`run_configuration`): the method, its raw
    output, its times, whether it was timed by a single run, and its outputs by blur
    (:func:`score_outputs`, :meth:`output`)."""
    method: str
    raw: np.ndarray
    times: list
    single: bool
    outputs: dict = field(default_factory=dict)

    def blurred(self, blur: bool) -> bool:
        """Whether the output of a configuration with ``blur`` is blurred (not an RGB one)."""
        return bool(blur and self.raw.ndim == 2)

    def output(self, blur: bool) -> Output:
        return self.outputs[self.blurred(blur)]


def require_grey(method: str, ao) -> np.ndarray:
    """``ao`` as an array; a ValueError when it is not one grey channel."""
    ao = np.asarray(ao)
    if ao.ndim != 2:
        raise ValueError(f"{method} returned an image of shape {ao.shape}, not grey AO")
    return ao


def run_configuration(method: str, settings: dict, scene: Scene, timing: Timing, *,
                      frame: int | None = None, single: bool = False,
                      grey: bool = False) -> Run:
    """``method`` at ``settings`` on ``scene`` at its R (at ``frame``, a frame's index in a
    sequence), timed by :func:`timed` (``single``: by its first run alone). ``grey``: an RGB
    output is a ValueError at its first run. The method's refusal is its ValueError or
    RuntimeError. Its outputs are :func:`score_outputs`'."""
    def compute():
        out = aolab.compute(method, scene.g, radius=scene.radius, threads=timing.threads,
                            frame=frame, **settings)
        return require_grey(method, out) if grey else out

    cap = -math.inf if single else timing.max_ms
    raw, times = timed(compute, timing.warmup, timing.repeat, cap)
    return Run(method, np.asarray(raw), times, len(times) == 1 and times[0] > cap)


def score_outputs(run: Run, scene: Scene, timing: Timing, blurs=(False,), *, scorer=score,
                  remote: dict | None = None, blur_capped: bool = False) -> Run:
    """Each output of ``blurs`` of ``run``, in turn: the shared blur timed apart (capped by
    ``timing.max_ms``, or by the single run, only if ``blur_capped``) and scored by
    ``scorer(ao, scene)``; with ``remote`` (a worker's :func:`score_remotely`), the worker's
    scores once the bits timed here are the worker's (else a ValueError)."""
    cap = (-math.inf if run.single else timing.max_ms) if blur_capped else math.inf
    for blur in blurs:
        key = run.blurred(blur)
        if key in run.outputs:
            continue
        ao, blur_times = run.raw, []
        if key:
            ao, blur_times = timed(lambda: presets_mod.shared_blur(run.raw, scene.g,
                                                                   timing.threads),
                                   timing.warmup, timing.repeat, cap)
        run.outputs[key] = Output(ao, blur_times, _scores(ao, scene, scorer, run.method,
                                                          (remote or {}).get(key)))
    return run


def _scores(ao: np.ndarray, scene: Scene, scorer, method: str, theirs: dict | None):
    """The scores of one output: the worker's (``theirs``) when its bits are these, else
    scored here; None for an RGB output."""
    if ao.ndim != 2:
        return None
    if theirs is None:
        return scorer(ao, scene)
    check_same_bits(theirs["digest"], digest(ao), method, scene.name)
    return theirs["scores"]


def score_remotely(folder: str, crop, name: str | None, method: str, settings: dict,
                   blurs: list[bool], scorer=score, frame: int | None = None,
                   follow_symlinks: bool = False) -> dict:
    """On a Dask worker: a configuration's output on a scene (read from ``folder``, shared
    storage, once per worker), blurred or not as ``blurs`` asks, scored: blur ->
    {"scores": scorer's, "digest"}, None for an RGB output; {"error": message, "refused":
    whether the method refused the settings (a ValueError)} when the method fails."""
    scene = worker_scene((__name__, folder, crop_key(crop), name, follow_symlinks),
                         lambda: load_scene(Path(folder), crop, name,
                                            follow_symlinks=follow_symlinks))
    try:
        raw = np.asarray(aolab.compute(method, scene.g, radius=scene.radius, threads=1,
                                       frame=frame, **settings))
    except (ValueError, RuntimeError) as e:
        return {"error": str(e), "refused": isinstance(e, ValueError)}
    out = {}
    for blur in blurs:
        ao = presets_mod.shared_blur(raw, scene.g, threads=1) if blur and raw.ndim == 2 else raw
        out[blur] = None if ao.ndim != 2 else {"scores": scorer(ao, scene), "digest": digest(ao)}
    return out


def evaluate(method: str, settings: dict, blur: bool, scenes: list[Scene], timing: Timing,
             on_scene=None, remote: dict | None = None, scorer=trial_scores) -> dict:
    """A trial of aolab tune or advise: per scene, the median method and blur times, their
    sum ``measured_ms``, that time scaled to a 1280x720 frame (``ms``: the budgets' unit, so
    that scenes of every size weigh alike; a crop's time is left as it is), the number of
    timed runs and ``scorer(ao, scene)`` (default :func:`trial_scores`). ``remote`` (scene ->
    :func:`score_remotely`'s result), when given, holds scores computed on Dask workers: the
    timed runs' output must have the same bits. A configuration whose first run exceeds
    ``timing.max_ms`` is timed by that single run (it is past every budget), on every scene;
    an RGB output is a ValueError. ``on_scene(name)`` is called before each scene."""
    out, single = {}, False
    for sc in scenes:
        if on_scene is not None:
            on_scene(sc.name)
        run = run_configuration(method, settings, sc, timing, single=single, grey=True)
        single = run.single
        got = score_outputs(run, sc, timing, [blur], scorer=scorer, blur_capped=True,
                            remote=(remote or {}).get(sc.name)).output(blur)
        row = {"method_ms": statistics.median(run.times),
               "blur_ms": statistics.median(got.blur_times) if blur else 0.0}
        row["measured_ms"] = row["method_ms"] + row["blur_ms"]
        row["ms"] = row["measured_ms"] * sc.time_scale
        row.update(got.scores)
        row["runs"] = len(run.times)
        out[sc.name] = row
    return out


# ----------------------------------------------------------------------------------------
# The whole-frame guard


def whole_frame_ok(all_mae: dict, ao_one: dict, default_mae: float | None = None) -> bool:
    """The whole-frame guard, so that darkening everything cannot win by the occluded error:
    ``all_mae`` (scene -> a configuration's whole-frame MAE; at least one scene) no worse than
    AO = 1's on any scene that has AO = 1's MAE in ``ao_one`` (a value of None or NaN, or
    AO = 1's NaN, fails), and its mean no worse than ``default_mae`` (the method's default's
    mean over the same scenes; None: no such bound)."""
    if not all_mae:
        return False
    for s, got in all_mae.items():
        limit = ao_one.get(s)
        if limit is not None and not (got is not None and got <= limit):
            return False
    if default_mae is None:
        return True
    return float(np.mean(list(all_mae.values()))) <= default_mae + 1e-12


# ----------------------------------------------------------------------------------------
# What the drivers share


def still_scenes(scenes: dict) -> list[str]:
    """The still scenes of ``scenes`` (name -> a study's scene info): neither a sequence nor
    a frame of one (a sequence's frames are scored as scenes of their own, but they are one
    camera path, not independent scenes, and would outweigh the others in a mean or a
    test)."""
    frames = {f for info in scenes.values() if (info or {}).get("sequence")
              for f in info.get("frame_scenes", [])}
    return [n for n, info in scenes.items()
            if not (info or {}).get("sequence") and n not in frames]
