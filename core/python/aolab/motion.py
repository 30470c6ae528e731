"""Motion vectors from the cameras alone: each pixel's view-space point carried through the
world into the previous frame's camera (docs/conventions.md, "Motion vectors").

Right for a static scene seen by a moving camera; wrong wherever something moves by itself,
where only the bridge's Motion pass (Cycles' Vector pass, bridge/motion.py) is right.
"""

from __future__ import annotations

import numpy as np

from .util import values as checked


def _camera(source, what: str) -> tuple[np.ndarray, float, float, float, float]:
    """(camera_to_world 4x4 float64, fx, fy, cx, cy) of a G-buffer (its own intrinsics, which
    a crop moves, and its sidecar's camera_to_world) or of a sidecar dict; a ValueError
    naming ``what`` when one is missing or not finite; the intrinsics are checked as the
    G-buffer checks them (util.values.intrinsics), so that fx = 0 or "1" is refused."""
    side = source if isinstance(source, dict) else getattr(source, "sidecar", None)
    if not isinstance(side, dict):
        raise ValueError(f"{what} must be a G-buffer from aolab.load_gbuffer (with a sidecar) "
                         f"or a sidecar dict, got {type(source).__name__}")
    if side.get("camera_to_world") is None:
        raise ValueError(f"{what}: the sidecar has no camera_to_world, so the camera's motion "
                         "is unknown")
    try:
        m = np.asarray(side["camera_to_world"], dtype=np.float64)
        k = [side[key] if isinstance(source, dict) else getattr(source, key)
             for key in ("fx", "fy", "cx", "cy")]
    except (AttributeError, KeyError, TypeError, ValueError) as e:
        raise ValueError(f"{what}: the sidecar needs camera_to_world (4x4) and fx, fy, cx, cy "
                         f"as numbers ({e})") from None
    if m.shape != (4, 4) or not np.isfinite(m).all():
        raise ValueError(f"{what}: camera_to_world must be a finite 4x4 matrix, got "
                         f"{m.shape}")
    try:
        k = checked.intrinsics(*k)
    except ValueError as e:
        raise ValueError(f"{what}: {e}") from None
    if abs(np.linalg.det(m)) < 1e-12:
        raise ValueError(f"{what}: camera_to_world is singular")
    return (m, *k)


def camera_motion(previous, current) -> np.ndarray:
    """Motion vectors of ``current`` (a G-buffer from ``aolab.load_gbuffer``, with the
    sidecar's camera_to_world) from the cameras alone, in AO Lab's convention: float32
    (H, W, 2), (dx, dy) in pixels such that the point seen at pixel centre (i + 0.5, j + 0.5)
    now was at (i + 0.5 + dx, j + 0.5 + dy) in ``previous`` (y down), ``previous`` being the
    previous frame's G-buffer (its own fx, fy, cx, cy, so that two frames cropped alike give
    the motion in the crop, and its sidecar's camera_to_world) or a sidecar dict
    (camera_to_world, fx, fy, cx, cy). NaN on background and where the point lies behind the
    previous camera, and wherever the motion is not finite or beyond float32 (a camera moved
    by 1e300): the convention is finite or NaN, and no numpy warning is raised.

    The point X seen with depth d is carried by M = world_to_camera(previous) ·
    camera_to_world(current) and projected with the previous intrinsics:
    u = cx' + fx'·X'/d', v = cy' − fy'·Y'/d', d' = −Z'."""
    m_prev, fx, fy, cx, cy = _camera(previous, "previous")
    m_cur = _camera(current, "current")[0]
    if not hasattr(current, "view_positions"):
        raise ValueError("current must be a G-buffer (aolab.load_gbuffer), got "
                         f"{type(current).__name__}")
    points = np.asarray(current.view_positions(), dtype=np.float64)   # NaN on background
    h, w = points.shape[:2]
    centres_x = np.arange(w, dtype=np.float64) + 0.5
    centres_y = np.arange(h, dtype=np.float64)[:, None] + 0.5
    # Far cameras overflow float64 (inf - inf is NaN): those pixels become NaN below.
    with np.errstate(all="ignore"):
        carry = np.linalg.inv(m_prev) @ m_cur
        q = points @ carry[:3, :3].T + carry[:3, 3]
        d = -q[..., 2]
        u = cx + fx * q[..., 0] / d
        v = cy - fy * q[..., 1] / d
        motion = np.stack([u - centres_x, v - centres_y], axis=-1)
        keep = (d > 0) & (np.abs(motion) <= checked.FLOAT32_MAX).all(axis=-1)
    motion[~keep] = np.nan
    return motion.astype(np.float32)
