"""Alchemy AO (McGuire et al. 2011) and SAO (McGuire, Mara, Luebke 2012) through the Python
API: the shared estimator (SAO at full resolution, unfiltered, is Alchemy), nothing within r
gives exactly 1, the wall's occlusion near the crease, the contrast exponent, SAO's z pyramid
and filter, the SIMD kernel against the scalar oracle. Open planes, threads, GIL, cancellation
and settings: test_conformance.py; hard inputs and a scene scaled with its radius:
test_stability.py."""
import numpy as np

import aolab


def blocks():
    return aolab.analytic_scene("blocks", 128, 72)


def test_sao_at_full_resolution_unfiltered_is_alchemy():
    g = blocks()
    shared = dict(radius=0.5, samples=10, bias=0.0, epsilon=1e-3, falloff="smooth")
    a = aolab.compute("alchemy", g, **shared)
    s = aolab.compute("sao", g, max_mip_level=0, filter=False, **shared)
    assert np.array_equal(a, s)


def test_nothing_within_the_radius_is_one():
    g = aolab.analytic_scene("ceiling", 192, 108, ceiling_height=1.0)
    for method in ("alchemy", "sao"):
        assert aolab.compute(method, g, radius=0.9).min() == 1.0


def test_wall_occludes_only_near_the_crease():
    g = aolab.analytic_scene("wall", 192, 108, radius=1.0)
    ref, valid = g.reference, g.valid_mask()
    for method in ("alchemy", "sao"):
        ao = aolab.compute(method, g, radius=1.0, **({"filter": False} if method == "sao" else {}))
        far = valid & (ref == 1.0)
        near = valid & (ref < 0.8)
        assert (ao[far] == 1.0).mean() > 0.999, method
        assert ao[near].mean() < 0.95, method


def test_contrast_is_an_exponent():
    g = blocks()
    a = aolab.compute("alchemy", g, radius=0.5).astype(np.float64)
    b = aolab.compute("alchemy", g, radius=0.5, contrast=3.0)
    assert np.abs(b - a ** 3).max() < 1e-6


def test_sao_pyramid_and_filter_keep_the_mean():
    g = blocks()
    full = aolab.compute("sao", g, radius=0.5, max_mip_level=0, filter=False)
    mip = aolab.compute("sao", g, radius=0.5, log_max_offset=0, filter=False)
    filtered = aolab.compute("sao", g, radius=0.5, log_max_offset=0)
    assert abs(full.mean() - mip.mean()) < 0.01
    assert abs(filtered.mean() - mip.mean()) < 0.005
    # the filter smooths the rotation's noise: neighbours differ less
    assert np.abs(np.diff(filtered, axis=1)).mean() < np.abs(np.diff(mip, axis=1)).mean()


def test_simd_kernel_matches_the_scalar_oracle():
    # The tolerances of tests/cpp/methods/{alchemy,sao}/*_simd_test.cpp (docs/methods/
    # alchemy.md, "SIMD kernel"): float rounding on almost every pixel; on a few, an ulp moves
    # one tap across a texel edge or across |v| = r, by at most its share c*sigma/s of A.
    g = aolab.analytic_scene("blocks", 203, 117)
    for method, samples in (("alchemy", 8), ("sao", 9)):
        for falloff, c in (("alchemy", 2.0), ("smooth", 5.0)):
            kw = dict(radius=0.25, samples=samples, falloff=falloff)
            simd = aolab.compute(method, g, kernel="simd", **kw).astype(np.float64)
            scalar = aolab.compute(method, g, kernel="scalar", **kw)
            d = np.sort(np.abs(simd - scalar).ravel())
            assert d.mean() <= 1e-5, (method, falloff)
            assert d[int(0.999 * (d.size - 1))] <= 1e-3, (method, falloff)
            assert d[-1] <= c / samples, (method, falloff)
            assert np.array_equal(aolab.compute(method, g, kernel="simd", threads=1, **kw),
                                  aolab.compute(method, g, kernel="simd", threads=2, **kw))
