"""Chebyshev AO (Chan & Im 2021) through the registry: the two-level known answer of §II-B,
§III-A's screen-parallel floor, §III-B/C, far-away planes with millimetre relief
(numerically stable moments), background, the adaptive window. Open planes (§III-A's
screen-parallel plane, tilted planes by Jensen), threads and settings: test_conformance.py."""
import numpy as np
import pytest

import aolab

METHOD = "chebyshev"
EXACT = dict(variance_bias=0.0, range_check=False)  # eq. 3 alone
FIXED = "fixed"  # kernel_mode: a pixel window of kernel_radius


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
    ao = aolab.compute(METHOD, gbuffer(depth), radius=1.0, kernel_mode=FIXED, kernel_radius=r,
                       **EXACT)
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
    eq2 = aolab.compute(METHOD, g, radius=1.0, kernel_mode=FIXED, kernel_radius=4,
                        ignore_unoccluded=False, **EXACT)
    eq3 = aolab.compute(METHOD, g, radius=1.0, kernel_mode=FIXED, kernel_radius=4, **EXACT)
    assert eq2[:, 28:32].max() < 1 and (eq3[:, 28:32] == 1).all()
    np.testing.assert_array_equal(eq2[:, 32:], eq3[:, 32:])


def test_screen_parallel_floor_of_a_bowl_has_no_stains():
    # The bowl of Figure 2: a flat bottom facing the camera inside a raised rim. Away from the
    # rim (farther than the window) the bottom is exactly 1; next to it, occluded.
    depth = np.full((90, 160), 5.0, np.float32)
    depth[20:70, 30:130] = 6.0
    for variance_bias in (0.0, 1e-4):
        ao = aolab.compute(METHOD, gbuffer(depth), radius=0.5, kernel_mode=FIXED, kernel_radius=6,
                           variance_bias=variance_bias)
        assert np.isfinite(ao).all()
        assert (ao[27:63, 37:123] == 1).all()
        assert ao[21, 50] < 0.8 and ao[45, 31] < 0.8


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
    settings = dict(kernel_mode=FIXED, kernel_radius=4)
    a = aolab.compute(METHOD, gbuffer(near), radius=3 * ulp, **settings)
    b = aolab.compute(METHOD, gbuffer(far), radius=3 * far_ulp, **settings)
    assert a.min() < 0.9  # the relief is resolved: the grooves are occluded
    np.testing.assert_array_equal(a, b)  # bit-identical: only offsets are ever summed
    # The naive float32 moments cannot do this: M2 − M1² goes negative or far off.
    win = np.lib.stride_tricks.sliding_window_view(far, (9, 9))
    mean = win.mean(axis=(2, 3), dtype=np.float32)
    naive = (win * win).mean(axis=(2, 3), dtype=np.float32) - mean ** 2
    exact = win.astype(np.float64).var(axis=(2, 3))
    assert (naive < 0).any() or np.abs(naive - exact).max() > 100 * exact.max()


def test_background_never_enters_the_window():
    # A floor beside background: the background neither occludes nor counts.
    g = aolab.analytic_scene("step", 120, 80)
    depth = g.depth.copy()
    depth[:, 60:] = np.inf
    ao = aolab.compute(METHOD, aolab.GBuffer(depth, None, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy),
                       radius=1.0)
    assert (ao == 1).all()
    # A hole of background in the step image changes nothing on the far side of the edge
    # beyond the pixels whose window loses near samples.
    d = step_image()
    holed = d.copy()
    holed[:, 50:] = 1e10
    window = dict(kernel_mode=FIXED, kernel_radius=3, **EXACT)
    a = aolab.compute(METHOD, gbuffer(d), radius=1.0, **window)
    b = aolab.compute(METHOD, gbuffer(holed), radius=1.0, **window)
    np.testing.assert_array_equal(a[:, :45], b[:, :45])
    assert (b[:, 50:] == 1).all()


def test_range_check_fades_far_occluders():
    # A gap of 100 R in front: without §III-C the far side is dark, with it nearly open.
    d = step_image(near=1.0, far=101.0)
    g = gbuffer(d)
    window = dict(kernel_mode=FIXED, kernel_radius=4)
    off = aolab.compute(METHOD, g, radius=1.0, range_check=False, **window)
    on = aolab.compute(METHOD, g, radius=1.0, **window)
    assert off[20, 33] < 0.7
    assert on[20, 33] > 0.99
    # A gap within R is unaffected.
    d2 = step_image(near=2.0, far=2.5)
    np.testing.assert_array_equal(
        aolab.compute(METHOD, gbuffer(d2), radius=1.0, **window),
        aolab.compute(METHOD, gbuffer(d2), radius=1.0, range_check=False, **window))


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
