"""What a method is scored on and how its error is shown, once for the command line, the
comparison study, its report and the add-on (no bpy).

- The scored pixels: geometry (``GBuffer.valid_mask``) where the reference is finite.
  ``aolab run``, ``aolab compare`` (its region "all") and the add-on's Compare score there.
- The signed error map (method − reference): white at 0, blue where the method is lighter
  (under-occlusion), red where it is darker (over-occlusion), full colour at
  |error| >= ERROR_SCALE, background grey.
- The noise of a ray-traced reference (:func:`reference_noise`): how far above its true value
  a method's MAE can read against a reference of N rays per pixel.
"""

from __future__ import annotations

import math

import numpy as np

#: The signed error maps saturate at ±ERROR_SCALE.
ERROR_SCALE = 0.25
#: Blue: lighter than the reference (under-occlusion); red: darker (over-occlusion).
LIGHTER_RGB = (0.1, 0.3, 0.9)
DARKER_RGB = (0.85, 0.1, 0.1)
#: Pixels that are not scored (background), in error maps.
BACKGROUND_GREY = 0.5


def scored_mask(g, reference: np.ndarray | None = None) -> np.ndarray:
    """The scored pixels: geometry of G-buffer ``g`` where ``reference`` (default: the
    G-buffer's own ``g.reference``) is finite. Without a reference, no pixel is scored."""
    if reference is None:
        reference = getattr(g, "reference", None)
    valid = np.asarray(g.valid_mask(), bool)
    if reference is None:
        return np.zeros_like(valid)
    return valid & np.isfinite(reference)


def nothing_to_score(g, reference: np.ndarray | None = None, where: str = "",
                     name: str = "reference.exr") -> str | None:
    """Why no pixel of the reference G-buffer ``g`` (called ``name``) can be scored against
    ``reference`` (default: ``g.reference``), or None: its frame is all background (the
    camera sees no object), or its AO pass is nowhere finite on geometry. ``where`` narrows
    the message (" in the 64x36 crop"). ``aolab compare``, ``aolab advise`` and the add-on's
    Compare and Advise say it alike."""
    valid = np.asarray(g.valid_mask(), bool)
    if not valid.any():
        return (f"{name} has no geometry pixel{where} (its depth is background "
                "everywhere: the camera sees no object), so there is nothing to score")
    if reference is None:
        reference = getattr(g, "reference", None)
    if reference is None or not np.isfinite(np.asarray(reference)[valid]).any():
        return (f"the AO pass of {name} has no finite value on any geometry pixel{where} "
                "(all NaN or infinite), so there is nothing to score against; render the "
                "reference again")
    return None


def require_scoreable(g, reference: np.ndarray | None = None, name: str = "reference.exr",
                      hint: str = "") -> None:
    """A ValueError saying :func:`nothing_to_score` (then ``hint``) when there is nothing to
    score: refused before any work, never answered with NaN scores."""
    problem = nothing_to_score(g, reference, name=name)
    if problem:
        raise ValueError(problem + hint)


def metrics_mask(g) -> np.ndarray | None:
    """``scored_mask(g)`` where there is something to score against, else None (no
    reference, or no finite reference on geometry)."""
    mask = scored_mask(g)
    return mask if mask.any() else None


def reference_noise(reference: np.ndarray, samples: int, mask: np.ndarray) -> float | None:
    """The mean absolute noise, over ``mask``, of a reference whose pixels are each the mean
    of ``samples`` binary rays (rtao, Cycles' AO pass): E|e| ≈ sqrt(2/pi)·sigma per pixel,
    sigma² = p(1 − p)/(N − 1) with p the reference's own value (N − 1: the unbiased estimate
    of an N-ray mean's variance from that mean itself). None when ``samples`` < 2 or no pixel
    is in ``mask``.

    What it bounds (docs/comparison.md, "Advise: the quick reference and its noise"): a
    method's MAE against a reference with zero-mean noise e reads high by E|d − e| − |d|,
    which lies in [0, E|e|] at every pixel (Jensen below, the triangle inequality above; d =
    method − noise-free AO): 0 where the method is far off, E|e| where it is exact. Stratified
    rays are less noisy than independent ones, so this is an upper estimate."""
    m = np.asarray(mask, bool)
    if samples < 2 or not m.any():
        return None
    p = np.clip(np.asarray(reference, np.float64)[m], 0.0, 1.0)
    sigma = np.sqrt(p * (1.0 - p) / (samples - 1))
    return float(math.sqrt(2.0 / math.pi) * np.mean(sigma))


def signed_error_rgb(err: np.ndarray, scale: float = ERROR_SCALE,
                     valid: np.ndarray | None = None) -> np.ndarray:
    """err = method − reference as RGB, (H, W) -> (H, W, 3): white at 0, blue when lighter
    (> 0, under-occlusion), red when darker (< 0, over-occlusion), full colour at
    |err| >= scale; BACKGROUND_GREY outside ``valid`` when given."""
    t = np.clip(np.abs(err) / scale, 0, 1)[..., None]
    colour = np.where(err[..., None] < 0, np.array(DARKER_RGB), np.array(LIGHTER_RGB))
    rgb = (1 - t) + t * colour
    if valid is not None:
        rgb[~np.asarray(valid, bool)] = BACKGROUND_GREY
    return rgb


def error_map(ao: np.ndarray, reference: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """The signed error map of ``ao`` against ``reference`` on ``valid`` pixels as float32
    RGB (the add-on's images)."""
    err = np.where(valid, ao - reference, 0.0).astype(np.float32)
    return signed_error_rgb(err, valid=valid).astype(np.float32)


def digest(ao: np.ndarray) -> str:
    """The SHA-256 of an output's float32 bits: the same configuration on the same inputs
    gives the same digest on every machine (the methods are deterministic), which is how the
    study checks the scores a Dask worker sent against the output it times here."""
    import hashlib
    return hashlib.sha256(np.ascontiguousarray(ao, np.float32).tobytes()).hexdigest()


def check_same_bits(theirs: str, ours: str, method: str, scene: str) -> None:
    """A ValueError unless ``ours`` (the :func:`digest` of the output timed here) is the digest
    ``theirs`` that a Dask worker sent with its scores: the scores are only this output's if
    the bits agree."""
    if theirs != ours:
        raise ValueError(f"{method} gave other bits on a worker than here on scene {scene} "
                         "(a nondeterministic configuration)")
