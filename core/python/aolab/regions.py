"""The image regions ``aolab compare`` scores apart, so that a reader sees where a method
fails (docs/comparison.md, "Regions").

Every region is a subset of the scored pixels: geometry (``GBuffer.valid_mask``) with a
finite reference. Definitions, with their constants:

- ``all``: every scored pixel.
- ``occluded``: the reference is below ``OCCLUDED_BELOW`` = 0.9.
- ``depth_edges``: within ``EDGE_DILATION`` = 2 px (Chebyshev distance: a 5x5 square) of an
  edge pixel. A geometry pixel is an edge pixel when one of its 4 neighbours is background,
  or holds depth differing by more than ``EDGE_RELATIVE_JUMP`` = 5 % of the smaller of the two.
- ``grazing``: |n . v| < ``GRAZING_BELOW`` = 0.3 (the surface is seen at more than 72.5
  degrees from its normal), n = ``GBuffer.prepared_normals()`` (the given normals repaired,
  estimated from depth where missing), v the unit vector from the point to the camera.
- ``creases`` (near-contact creases): some geometry pixel Q within ``CREASE_WINDOW`` = 4 px
  (a 9x9 square) lies within ``CREASE_GAP`` = R/4 of P in view space and above P's tangent
  plane at an elevation of at least ``CREASE_ELEVATION`` = 30 degrees:
  (Q - P) . n_P >= sin 30 deg |Q - P|. A plane has no such Q, a convex edge neither (its
  neighbours are below the tangent plane); a floor meeting a wall, an object resting on a
  floor, books in a shelf do.
- ``border``: within ``BORDER_FRACTION`` = 5 % of the image size of the edge: the first and
  last ceil(0.05 W) columns and ceil(0.05 H) rows, where screen-space methods lack data.
"""

from __future__ import annotations

import math

import numpy as np

from .scoring import scored_mask

REGIONS = ("all", "occluded", "depth_edges", "grazing", "creases", "border")

OCCLUDED_BELOW = 0.9
EDGE_RELATIVE_JUMP = 0.05
EDGE_DILATION = 2
GRAZING_BELOW = 0.3
CREASE_WINDOW = 4
CREASE_GAP_OF_RADIUS = 0.25
CREASE_ELEVATION_DEG = 30.0
BORDER_FRACTION = 0.05

DESCRIPTIONS = {
    "all": "every geometry pixel with a finite reference",
    "occluded": f"reference AO < {OCCLUDED_BELOW}",
    "depth_edges": f"within {EDGE_DILATION} px of a depth jump > {EDGE_RELATIVE_JUMP:.0%} "
                   "(relative to the nearer depth) or of the background",
    "grazing": f"|n·v| < {GRAZING_BELOW} (normal more than "
               f"{math.degrees(math.acos(GRAZING_BELOW)):.1f}° from the view direction)",
    "creases": f"a pixel within {CREASE_WINDOW} px and {CREASE_GAP_OF_RADIUS:g} R in view space "
               f"lies ≥ {CREASE_ELEVATION_DEG:g}° above the tangent plane (near-contact crease)",
    "border": f"within {BORDER_FRACTION:.0%} of the image width/height of the image edge",
}


def _shifted(a: np.ndarray, dy: int, dx: int, fill) -> np.ndarray:
    """b[y, x] = a[y + dy, x + dx], ``fill`` outside the image."""
    h, w = a.shape[:2]
    out = np.full_like(a, fill)
    ys, yd = (slice(dy, h), slice(0, h - dy)) if dy >= 0 else (slice(0, h + dy), slice(-dy, h))
    xs, xd = (slice(dx, w), slice(0, w - dx)) if dx >= 0 else (slice(0, w + dx), slice(-dx, w))
    if ys.stop > ys.start and xs.stop > xs.start:
        out[yd, xd] = a[ys, xs]
    return out


def dilate(mask: np.ndarray, radius: int) -> np.ndarray:
    """Square (Chebyshev) dilation of a boolean image by ``radius`` px, separably."""
    out = mask.copy()
    rows = out.copy()
    for d in range(1, radius + 1):
        rows |= _shifted(out, 0, d, False) | _shifted(out, 0, -d, False)
    out = rows.copy()
    for d in range(1, radius + 1):
        out |= _shifted(rows, d, 0, False) | _shifted(rows, -d, 0, False)
    return out


def depth_edge_pixels(depth: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Geometry pixels next to (4-neighbourhood) background or a relative depth jump."""
    d = np.where(valid, depth, np.nan).astype(np.float64)
    edge = np.zeros(valid.shape, bool)
    for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        q = _shifted(d, dy, dx, np.nan)
        q_valid = _shifted(valid, dy, dx, True)   # the image edge is not a depth edge
        with np.errstate(invalid="ignore"):
            jump = np.abs(q - d) > EDGE_RELATIVE_JUMP * np.fmin(q, d)
        edge |= valid & (jump | ~q_valid)
    return edge


def crease_pixels(positions: np.ndarray, normals: np.ndarray, valid: np.ndarray,
                  radius: float) -> np.ndarray:
    """Pixels with a nearby point (CREASE_WINDOW px, CREASE_GAP_OF_RADIUS·R) above their
    tangent plane at >= CREASE_ELEVATION_DEG."""
    gap = CREASE_GAP_OF_RADIUS * radius
    sin_e = math.sin(math.radians(CREASE_ELEVATION_DEG))
    p = np.where(valid[..., None], positions, np.nan).astype(np.float32)
    n = normals.astype(np.float32)
    out = np.zeros(valid.shape, bool)
    r = CREASE_WINDOW
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            if dx == 0 and dy == 0:
                continue
            diff = _shifted(p, dy, dx, np.nan) - p
            dist = np.sqrt(np.einsum("ijk,ijk->ij", diff, diff))
            height = np.einsum("ijk,ijk->ij", diff, n)
            with np.errstate(invalid="ignore"):
                out |= (dist > 0) & (dist <= gap) & (height >= sin_e * dist)
    return out & valid


def border_pixels(height: int, width: int) -> np.ndarray:
    bx = math.ceil(BORDER_FRACTION * width)
    by = math.ceil(BORDER_FRACTION * height)
    m = np.zeros((height, width), bool)
    m[:by, :] = m[-by:, :] = True
    m[:, :bx] = m[:, -bx:] = True
    return m


def occluded_pixels(valid: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """The ``occluded`` region: pixels of ``valid`` whose reference is below OCCLUDED_BELOW."""
    return valid & (np.nan_to_num(reference, nan=1.0) < OCCLUDED_BELOW)


def region_masks(g, reference: np.ndarray, radius: float) -> dict[str, np.ndarray]:
    """The boolean masks of :data:`REGIONS` for a G-buffer, its reference AO and R."""
    valid = scored_mask(g, reference)
    positions = np.asarray(g.view_positions())
    normals = np.asarray(g.prepared_normals())
    view = -positions
    with np.errstate(invalid="ignore", divide="ignore"):
        view /= np.linalg.norm(view, axis=2, keepdims=True)
        ndotv = np.abs(np.einsum("ijk,ijk->ij", normals, view))
    depth = np.asarray(g.depth)
    masks = {
        "all": valid,
        "occluded": occluded_pixels(valid, reference),
        "depth_edges": valid & dilate(depth_edge_pixels(depth, g.valid_mask()), EDGE_DILATION),
        "grazing": valid & (np.nan_to_num(ndotv, nan=1.0) < GRAZING_BELOW),
        "creases": valid & crease_pixels(positions, normals, g.valid_mask(), radius),
        "border": valid & border_pixels(*valid.shape),
    }
    return masks
