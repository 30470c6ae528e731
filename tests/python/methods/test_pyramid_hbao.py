"""Pyramid HBAO (Astapov, Frolov, Galaktionov 2021) against known answers: eq. 8 on a depth
step against quadrature, occlusion where HBAO finds it and none beyond the reach of the
samples, the paper's Gaussian, its settings table. Open planes, threads, settings errors,
normals and progress: test_conformance.py."""

import numpy as np

import aolab
from analytic_answers import step_answer

METHOD = "pyramid_hbao"
NO_NOISE = dict(rotation=False, random_directions=False, random_start=False,
                gaussian_filter=False)
# The depth buffer only (L = 1) with 1-pixel steps reaching past R: the method without its
# pyramid, as dense as HBAO's exact settings.
DENSE = dict(NO_NOISE, directions=64, levels=1, samples=64)


def test_depth_step_matches_quadrature_of_eq8():
    # `step`: floor at depth 50, a slab 0.5 nearer for x >= 0, 10° field of view.
    h, radius = 0.5, 1.0
    g = aolab.analytic_scene("step", 512, 64, step_height=h)
    p = g.view_positions()
    row = g.height // 2
    dense = aolab.compute(METHOD, g, radius=radius, **DENSE)
    pyramid = aolab.compute(METHOD, g, radius=radius, directions=64, **NO_NOISE)
    for a in (0.05, 0.15, 0.3, 0.5, 0.7):
        col = int(np.argmin(np.abs(p[row, :, 0] + a)))
        expected = step_answer(-p[row, col, 0], h, radius)
        # Without the pyramid: within 0.01, as HBAO (the first sample past the edge lies up
        # to a pixel beyond it; the slab's x-offsets scale by 49.5/50 against the floor's).
        assert abs(dense[row, col] - expected) < 0.01, (a, dense[row, col], expected)
        # With it, texels that straddle the edge average floor and slab into a ramp whose
        # points lie nearer to P than the edge: up to 0.06 more occlusion near the step (the
        # "dark halos" of §3.4), never less by more than 0.015 (measured: −0.051 … +0.001).
        assert -0.06 < pyramid[row, col] - expected < 0.015, (a, pyramid[row, col], expected)
    # The slab top sees nothing above it, whatever the level.
    assert dense[row, g.width // 2 + 2:].min() == 1.0
    assert pyramid[row, g.width // 2 + 2:].min() == 1.0
    # Without the pyramid, floor points whose edge lies beyond R see nothing (eq. 7).
    far = -p[row, :, 0] > np.sqrt(radius**2 - h**2) + 0.02
    assert dense[row, far].min() == 1.0


def footprint_reach_px(projected_radius, samples=4, reduction=3, start_min=0.5):
    """How far from P, in pixels, a texel that the march reads can extend: a read at
    distance t <= R·f/d on level l comes from a texel of side K^l containing the read, so
    its pixels lie within t + √2·K^l. The coarsest level reached within the projected
    radius is the one with the smallest start multiplier (m = 0.5): level l begins after
    m·S·(K^l − 1)/(K − 1) pixels."""
    def reach(r):
        level = 0
        while start_min * samples * (reduction ** (level + 1) - 1) / (reduction - 1) < r:
            level += 1
        return r + np.sqrt(2) * reduction ** level
    return np.vectorize(reach)(projected_radius)


def test_step_occlusion_ends_where_no_texel_reaches_the_slab():
    h, radius = 0.5, 1.0
    g = aolab.analytic_scene("step", 512, 64, step_height=h)
    p = g.view_positions()
    hbao = aolab.compute("hbao", g, radius=radius)
    ao = aolab.compute(METHOD, g, radius=radius, gaussian_filter=False)
    floor = np.zeros(ao.shape, bool)
    floor[:, : g.width // 2] = True
    # Occluded where HBAO is: every floor column HBAO darkens by 1 % on average.
    hbao_cols = hbao[:, : g.width // 2].mean(axis=0) < 0.99
    assert hbao_cols.sum() > 20
    assert (ao[:, : g.width // 2].mean(axis=0)[hbao_cols] < 0.99).all()
    # Exactly 1 where no texel read can contain a slab pixel (an image-space bound, derived
    # in footprint_reach_px: 1.65 R here; measured, the last occluded floor point lies
    # 0.95 R from the foot of the step).
    reach = footprint_reach_px(radius * g.fx / 50.0)
    cols = np.arange(g.width) + 0.5
    beyond = floor & ((g.width // 2 - cols) > reach)[None, :]
    assert beyond.sum() > 1000
    assert ao[beyond].min() == 1.0
    assert (-p[beyond][:, 0]).min() > radius  # the bound lies beyond R


def test_crease_is_occluded_near_its_line_and_open_beyond_reach():
    g = aolab.analytic_scene("crease", 200, 100)
    p = g.view_positions()
    dist = np.hypot(p[..., 1], p[..., 2] + 5)  # within either plane, to the crease line
    inner = np.zeros_like(dist, bool)
    inner[:, 40:160] = True  # away from the image sides, where samples leave the screen
    for radius in (0.25, 1.0):
        ao = aolab.compute(METHOD, g, radius=radius, gaussian_filter=False)
        hbao = aolab.compute("hbao", g, radius=radius)
        edges = np.arange(0, 1.0, 0.2) * radius
        bins = [ao[(dist >= lo) & (dist < lo + 0.2 * radius) & inner].mean() for lo in edges]
        hbins = [hbao[(dist >= lo) & (dist < lo + 0.2 * radius) & inner].mean() for lo in edges]
        # Occlusion fades with distance from the line, as HBAO's, and is stronger: eq. 8
        # weights the best occluder, not the highest one (HBAO's horizon on the other plane
        # lies towards R, where W is small).
        assert bins[0] < 0.9 and bins[0] < hbins[0]
        assert all(a < b for a, b in zip(bins, bins[1:])), bins
        # Mirror symmetry in y, row by row on average: single pixels differ by their noise
        # (up to 0.14 unfiltered), and the pyramid's texel grid starts at the top row.
        row_means = ao[:, 40:160].mean(axis=1)
        np.testing.assert_allclose(row_means, row_means[::-1], atol=0.01)
        dense = aolab.compute(METHOD, g, radius=radius, **DENSE)
        assert dense[dist > radius * 1.01].min() == 1.0  # without the pyramid: beyond R
    # With it: beyond the reach of the texels read (footprint_reach_px) from P's row to the
    # crease row (the image's middle), at R = 0.25 where that reach fits in the image.
    radius = 0.25
    ao = aolab.compute(METHOD, g, radius=radius, gaussian_filter=False)
    rows = np.abs(np.arange(g.height) + 0.5 - g.height / 2)[:, None]
    reach = footprint_reach_px(radius * g.fx / g.depth)
    beyond = rows > reach
    assert beyond.sum() > 2000
    assert ao[beyond].min() == 1.0


def test_floor_under_ceiling_beyond_radius_is_one():
    g = aolab.analytic_scene("ceiling", 256, 144, ceiling_height=1.0)
    assert aolab.compute(METHOD, g, radius=0.9).min() == 1.0


def test_occlusion_grows_with_radius():
    g = aolab.analytic_scene("blocks", 160, 90)
    means = [aolab.compute(METHOD, g, radius=r, **NO_NOISE).mean() for r in (0.1, 0.3, 1, 3)]
    assert all(a > b for a, b in zip(means, means[1:])), means


def test_gaussian_filter_is_on_by_default_and_is_gaussian_blur():
    g = aolab.analytic_scene("blocks", 160, 90)
    raw = aolab.compute(METHOD, g, radius=0.5, gaussian_filter=False)
    default = aolab.compute(METHOD, g, radius=0.5)
    np.testing.assert_array_equal(default, aolab.gaussian_blur(raw, g, sigma=1.5, taps=5))
    assert np.abs(np.diff(default, axis=1)).mean() < np.abs(np.diff(raw, axis=1)).mean()
    info = {s["name"]: s for s in aolab.method_info(METHOD)["settings"]}
    assert info["gaussian_filter"]["default"] is True


def test_settings_table():
    info = aolab.method_info(METHOD)
    assert info["needs_normal"]
    names = [s["name"] for s in info["settings"]]
    assert names == ["radius", "directions", "samples", "levels", "reduction", "attenuation",
                     "rotation", "random_directions", "random_start", "gaussian_filter", "seed",
                     "power"]
    defaults = {s["name"]: s["default"] for s in info["settings"]}
    assert defaults["directions"] == 8 and defaults["reduction"] == 3
    assert defaults["levels"] == 0 and defaults["samples"] == 4


def test_attenuation_none_is_the_references_weight():
    # W = 1 within R (the Cycles reference's cut-off) instead of eq. 7: never lighter, and
    # closer to the closed form beside a crease.
    g = aolab.analytic_scene("crease", 160, 90, radius=1.0)
    scored = g.valid_mask() & np.isfinite(g.reference)
    linear = aolab.compute(METHOD, g, radius=1.0)
    none = aolab.compute(METHOD, g, radius=1.0, attenuation="none")
    assert (none[scored] <= linear[scored] + 1e-6).all()
    assert (np.abs(none - g.reference)[scored].mean()
            < 0.5 * np.abs(linear - g.reference)[scored].mean())  # measured 0.020 vs 0.067
