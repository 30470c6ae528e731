"""Chebyshev AO (Chan & Im 2021) through the registry: the two-level known answer of §II-B,
open planes, §III-A's screen-parallel plane, §III-B/C, far-away planes with millimetre
relief (numerically stable moments), depth-only input, background, threads, settings."""
import numpy as np
import pytest

import aolab
from docs_settings import assert_docs_settings_table

METHOD = "chebyshev"
EXACT = dict(variance_bias=0.0, range_check=False)  # eq. 3 alone


def gbuffer(depth, normal=None, f=None, **k):
    h, w = depth.shape
    f = f or float(max(w, h))
    return aolab.GBuffer(np.ascontiguousarray(depth, np.float32), normal, fx=f, fy=f,
                         cx=w / 2, cy=h / 2, **k)


def step_image(w=64, h=40, near=2.0, far=3.0, edge=32):
    depth = np.full((h, w), far, np.float32)
    depth[:, :edge] = near
    return depth


@pytest.mark.parametrize("r", [1, 3, 8])
def test_two_level_window_gives_the_unoccluded_fraction(r):
    # §II-B: with a fraction p of the window at d_< in front of the receiver at d_≥,
    # σ² = p(1 − p)Δ², d − μ = pΔ, and eq. 3 with ε = 0 gives exactly 1 − p.
    depth = step_image()
    ao = aolab.compute(METHOD, gbuffer(depth), radius=1.0, kernel_mode=0, kernel_radius=r, **EXACT)
    h, w = depth.shape
    for y in (r, h // 2):
        for x in range(32, 32 + r + 2):
            ry, rx = min(r, y, h - 1 - y), min(r, x, w - 1 - x)
            window = depth[y - ry:y + ry + 1, x - rx:x + rx + 1]
            p = np.mean(window < depth[y, x])
            assert ao[y, x] == pytest.approx(1 - p, abs=2e-6), (x, y)
    assert (ao[:, :32] == 1).all()  # eq. 3: the near side is never occluded (§III-B)


def test_eq2_outlines_both_sides():
    # Without §III-B (eq. 2 with (d − μ)²) the near side of the edge darkens too (Figure 2e).
    g = gbuffer(step_image())
    eq2 = aolab.compute(METHOD, g, radius=1.0, kernel_mode=0, kernel_radius=4, ignore_unoccluded=False, **EXACT)
    eq3 = aolab.compute(METHOD, g, radius=1.0, kernel_mode=0, kernel_radius=4, **EXACT)
    assert eq2[:, 28:32].max() < 1 and (eq3[:, 28:32] == 1).all()
    np.testing.assert_array_equal(eq2[:, 32:], eq3[:, 32:])


@pytest.mark.parametrize("settings", [
    {}, dict(variance_bias=0.0), dict(variance_bias=0.0, ignore_unoccluded=False),
    dict(kernel_mode=0, kernel_radius=20, variance_bias=0.0), dict(range_check=False),
    dict(max_kernel_radius=1024)])
@pytest.mark.parametrize("radius", [1e-3, 0.3, 1.0, 10.0, 1e9])
def test_screen_parallel_plane_is_exactly_one(settings, radius):
    # §III-A: σ² = 0 and μ = d make eq. 2 0/0 (Figure 2d's stains); ε, or with ε = 0 the limit,
    # gives P = 1 everywhere: no NaN, no stain, even with no bias at all.
    g = aolab.analytic_scene("plane", 192, 108, fov=80)
    ao = aolab.compute(METHOD, g, radius=radius, **settings)
    assert np.isfinite(ao).all()
    assert ao[g.valid_mask()].min() == 1.0


def test_screen_parallel_floor_of_a_bowl_has_no_stains():
    # The bowl of Figure 2: a flat bottom facing the camera inside a raised rim. Away from the
    # rim (farther than the window) the bottom is exactly 1; next to it, occluded.
    depth = np.full((90, 160), 5.0, np.float32)
    depth[20:70, 30:130] = 6.0
    for variance_bias in (0.0, 1e-4):
        ao = aolab.compute(METHOD, gbuffer(depth), radius=0.5, kernel_mode=0, kernel_radius=6,
                           variance_bias=variance_bias)
        assert np.isfinite(ao).all()
        assert (ao[27:63, 37:123] == 1).all()
        assert ao[21, 50] < 0.8 and ao[45, 31] < 0.8


@pytest.mark.parametrize("tilt, azimuth, fov", [
    (30, 45, 60), (60, 0, 90), (75, 120, 60), (85, 30, 60), (-85, 200, 120), (89, 90, 30)])
@pytest.mark.parametrize("radius", [0.3, 1.0, 1e30])
def test_tilted_open_plane_is_exactly_one(tilt, azimuth, fov, radius):
    # Planar depth of a plane is 1/(a + b·u + c·v): convex in the image, so over a symmetric
    # window μ ≥ d and eq. 3 gives 1 (Jensen). The window is clamped symmetrically at borders.
    g = aolab.analytic_scene("plane", 160, 90, tilt=tilt, azimuth=azimuth, fov=fov)
    for settings in ({}, dict(kernel_mode=0, kernel_radius=12)):
        ao = aolab.compute(METHOD, g, radius=radius, **settings)
        assert ao[g.valid_mask()].min() == 1.0, settings


def relief_plane(scale_exponent):
    """A plane facing the camera at depth 1.25·2^e with grooves 1-3 ulps deep: at 2^13 ≈ 1e4
    one ulp is 0.98 mm, at 2^17 ≈ 1.3e5 it is 15.6 mm (float32 holds nothing finer there).
    Scaling by a power of two is exact, so every scale holds the same geometry."""
    h, w = 48, 64
    base = np.float32(1.25)
    ulp = np.spacing(base)
    yy, xx = np.mgrid[0:h, 0:w]
    grooves = ((xx // 5) % 3 + (yy // 7) % 2).astype(np.float32)  # 0..3 ulps
    depth = (base + grooves * ulp).astype(np.float32)
    return depth * np.float32(2.0 ** scale_exponent), float(ulp) * 2.0 ** scale_exponent


@pytest.mark.parametrize("exponent", [13, 17])
def test_far_plane_with_millimetre_relief_matches_the_near_one(exponent):
    near, ulp = relief_plane(0)
    far, far_ulp = relief_plane(exponent)
    assert 1e4 <= far.mean() or exponent != 13
    settings = dict(kernel_mode=0, kernel_radius=4)
    a = aolab.compute(METHOD, gbuffer(near), radius=3 * ulp, **settings)
    b = aolab.compute(METHOD, gbuffer(far), radius=3 * far_ulp, **settings)
    assert a.min() < 0.9  # the relief is resolved: the grooves are occluded
    np.testing.assert_array_equal(a, b)  # bit-identical: only offsets are ever summed
    # The naive float32 moments cannot do this: M2 − M1² goes negative or far off.
    win = np.lib.stride_tricks.sliding_window_view(far, (9, 9))
    naive = (win * win).mean(axis=(2, 3), dtype=np.float32) - win.mean(axis=(2, 3), dtype=np.float32) ** 2
    exact = win.astype(np.float64).var(axis=(2, 3))
    assert (naive < 0).any() or np.abs(naive - exact).max() > 100 * exact.max()


def test_depth_only_and_normals_are_never_read():
    assert aolab.method_info(METHOD)["needs_normal"] is False
    g = aolab.analytic_scene("blocks", 160, 90)
    depth_only = aolab.GBuffer(g.depth, None, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy)
    a = aolab.compute(METHOD, depth_only, radius=0.5)
    b = aolab.compute(METHOD, g, radius=0.5)
    np.testing.assert_array_equal(a, b)
    assert a.min() < 0.9


def test_background_never_enters_the_window():
    # A floor beside background: the background neither occludes nor counts.
    g = aolab.analytic_scene("step", 120, 80)
    depth = g.depth.copy()
    depth[:, 60:] = np.inf
    ao = aolab.compute(METHOD, aolab.GBuffer(depth, None, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy), radius=1.0)
    assert (ao == 1).all()
    # A hole of background in the step image changes nothing on the far side of the edge
    # beyond the pixels whose window loses near samples.
    d = step_image()
    holed = d.copy()
    holed[:, 50:] = 1e10
    a = aolab.compute(METHOD, gbuffer(d), radius=1.0, kernel_mode=0, kernel_radius=3, **EXACT)
    b = aolab.compute(METHOD, gbuffer(holed), radius=1.0, kernel_mode=0, kernel_radius=3, **EXACT)
    np.testing.assert_array_equal(a[:, :45], b[:, :45])
    assert (b[:, 50:] == 1).all()


def test_range_check_fades_far_occluders():
    # A gap of 100 R in front: without §III-C the far side is dark, with it nearly open.
    d = step_image(near=1.0, far=101.0)
    g = gbuffer(d)
    off = aolab.compute(METHOD, g, radius=1.0, kernel_mode=0, kernel_radius=4, range_check=False)
    on = aolab.compute(METHOD, g, radius=1.0, kernel_mode=0, kernel_radius=4)
    assert off[20, 33] < 0.7
    assert on[20, 33] > 0.99
    # A gap within R is unaffected.
    d2 = step_image(near=2.0, far=2.5)
    np.testing.assert_array_equal(
        aolab.compute(METHOD, gbuffer(d2), radius=1.0, kernel_mode=0, kernel_radius=4),
        aolab.compute(METHOD, gbuffer(d2), radius=1.0, kernel_mode=0, kernel_radius=4, range_check=False))


def test_adaptive_window_follows_depth():
    # k ∝ 1/d: the same step twice as far with the same R has a window half as wide.
    f = 64.0
    for far in (4.0, 8.0):
        d = step_image(near=far - 0.5, far=far)
        ao = aolab.compute(METHOD, gbuffer(d, f=f), radius=0.5, **EXACT)
        row = ao[20]
        dark = np.nonzero(row[32:] < 1)[0]
        r = round(0.5 * f / far)
        assert len(dark) == r, (far, dark)


def test_variance_bias_lightens_and_radius_scales():
    g = aolab.analytic_scene("blocks", 160, 90)
    a = aolab.compute(METHOD, g, radius=0.5, variance_bias=0.0)
    b = aolab.compute(METHOD, g, radius=0.5, variance_bias=0.1)
    assert b.mean() > a.mean() and (b >= a).all()
    means = [aolab.compute(METHOD, g, radius=r).mean() for r in (0.1, 0.3, 0.6)]
    assert means[0] > means[1] > means[2]


def test_same_bits_for_any_thread_count():
    g = aolab.analytic_scene("blocks", 320, 180)
    for settings in ({}, dict(kernel_mode=0, kernel_radius=9, ignore_unoccluded=False)):
        a = aolab.compute(METHOD, g, radius=0.5, threads=1, **settings)
        b = aolab.compute(METHOD, g, radius=0.5, threads=2, **settings)
        c = aolab.compute(METHOD, g, radius=0.5, threads=7, **settings)
        assert a.tobytes() == b.tobytes() == c.tobytes()


@pytest.mark.parametrize("name, value", [
    ("kernel_mode", 2), ("kernel_radius", -1), ("kernel_radius", 1.5), ("max_kernel_radius", 1025),
    ("variance_bias", -1e-3), ("variance_bias", np.nan), ("range_check", 2), ("ignore_unoccluded", 0.5)])
def test_bad_settings_are_valueerror_naming_them(name, value):
    g = aolab.analytic_scene("plane", 16, 9)
    with pytest.raises(ValueError, match=name):
        aolab.compute(METHOD, g, radius=1.0, **{name: value})


def test_unknown_setting_lists_the_valid_ones():
    g = aolab.analytic_scene("plane", 16, 9)
    with pytest.raises(ValueError, match="unknown setting 'seed' for chebyshev.*variance_bias"):
        aolab.compute(METHOD, g, radius=1.0, seed=3)


def test_progress_and_cancel():
    g = aolab.analytic_scene("blocks", 320, 180)
    p = aolab.Progress()
    aolab.compute(METHOD, g, radius=0.5, progress=p)
    assert p.total > 0 and p.done == p.total
    c = aolab.Progress()
    c.cancel()
    with pytest.raises(aolab.Cancelled):
        aolab.compute(METHOD, g, radius=0.5, progress=c)


def test_docs_settings_table_is_the_field_table():
    assert_docs_settings_table(METHOD)
