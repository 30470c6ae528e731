"""Known answers of the screen-space limit through the Python API: a bound (method_info
says so), the closed forms of the analytic scenes where the depth buffer holds every
occluder, exactly 1 on an open plane and at zero thickness, rays leaving the image
unoccluded. What every method shares is test_conformance.py's."""
import numpy as np

import aolab

METHOD = "screen_space_limit"


def crop(g, top, rows):
    """Rows [top, top + rows) of a G-buffer: the same view through a smaller window."""
    sl = slice(top, top + rows)
    return aolab.GBuffer(g.depth[sl].copy(), g.normal[sl].copy(), fx=g.fx, fy=g.fy, cx=g.cx,
                         cy=g.cy - top)


def rays_in_view(g, radius):
    """Pixels whose rays of length R all stay in the image and in front of the camera: the
    eight corners of the cube of half-side R about the point project inside the image."""
    p = g.view_positions()
    h, w = g.depth.shape
    ok = g.valid_mask().copy()
    for sx in (-1, 1):
        for sy in (-1, 1):
            for sz in (-1, 1):
                c = p + radius * np.array([sx, sy, sz], np.float32)
                with np.errstate(invalid="ignore", divide="ignore"):
                    d = -c[..., 2]
                    px = g.cx + g.fx * c[..., 0] / d
                    py = g.cy - g.fy * c[..., 1] / d
                    ok &= (d > 1e-3) & (px >= 0) & (px <= w) & (py >= 0) & (py <= h)
    return ok


def test_is_marked_as_a_bound():
    assert aolab.method_info(METHOD)["bound"] is True
    assert aolab.method_info("hbao")["bound"] is False
    assert "oracle" not in aolab.method_info(METHOD)
    assert METHOD in aolab.methods()


def test_wall_matches_the_closed_form_within_its_noise():
    # Floor and wall are both visible wherever a ray can meet them, so the limit is the
    # reference's integral. Tolerance: 4 binomial standard deviations of the mean over the
    # scored pixels, sqrt(sum p(1 - p)/N)/M, plus 2e-3 for the crease pixels' reconstruction.
    radius, rays = 0.5, 64
    g = aolab.analytic_scene("wall", 160, 90, radius=radius)
    ref = g.reference
    mask = rays_in_view(g, radius) & np.isfinite(ref)
    assert mask.sum() > 1000
    for thickness in (1e30, radius / 4):
        ao = aolab.compute(METHOD, g, radius=radius, rays=rays, thickness=thickness)
        p = ref[mask].astype(np.float64)
        sigma = np.sqrt((p * (1 - p) / rays).sum()) / mask.sum()
        assert abs(ao[mask].mean() - p.mean()) < 4 * sigma + 2e-3, thickness
        assert p.mean() < 0.95


def test_ceiling_matches_the_closed_form_within_its_noise():
    # The ceiling fills the top half of the image: every ray that reaches it within R does so
    # in view, and only those rays pass behind a visible pixel. The 32 rows about the horizon
    # hold the pixels whose rays stay in view; h = 1, R = 2: (h/R)² = 0.25.
    radius, rays = 2.0, 64
    g = crop(aolab.analytic_scene("ceiling", 256, 144, radius=radius), 56, 32)
    mask = rays_in_view(g, radius)
    assert mask.sum() > 1000
    ao = aolab.compute(METHOD, g, radius=radius, rays=rays)
    sigma = np.sqrt(0.25 * 0.75 / rays / mask.sum())
    assert abs(ao[mask].mean() - 0.25) < 4 * sigma + 2e-3


def test_open_plane_and_zero_thickness_give_one():
    for tilt in (0, 70):
        g = aolab.analytic_scene("plane", 96, 54, tilt=tilt, azimuth=40)
        ao = aolab.compute(METHOD, g, radius=2.0, rays=16)
        assert ao[g.valid_mask()].min() == 1.0
    g = aolab.analytic_scene("blocks", 96, 54)
    assert (aolab.compute(METHOD, g, radius=0.5, rays=16, thickness=0.0) == 1.0).all()
    ao = aolab.compute(METHOD, g, radius=0.5, rays=16)
    assert 0.0 <= ao.min() < 0.9 and ao.max() <= 1.0


def test_rays_leaving_the_image_are_unoccluded():
    # The wall scene cut just below its crease: the floor beside the cut is occluded in truth,
    # but the wall is out of the image, and a ray that leaves the image counts as a miss.
    g = aolab.analytic_scene("wall", 160, 90, radius=1.0)
    top = int(np.argmin(g.reference[:, 80])) + 2
    cut = crop(g, top, 90 - top)
    assert (g.reference[top] < 0.9).all()
    ao = aolab.compute(METHOD, cut, radius=1.0, rays=16)
    assert (ao[0] == 1.0).all()
