"""aolab.metrics and aolab._core.ssim_map against numpy formulas and scikit-image.

SSIM must match skimage.metrics.structural_similarity(a, b, data_range=1.0,
gaussian_weights=True, sigma=1.5, use_sample_covariance=False) — the settings skimage documents
as matching Wang et al. 2004 — to SSIM_TOLERANCE. skimage is fed float64 copies of the float32
images we score: its float32 path filters in float32, whose rounding in E[a²] − E[a]² would be
skimage's error, not ours.
"""

import math

import numpy as np
import pytest
from scipy import ndimage
from skimage.metrics import structural_similarity

import aolab
from aolab import _core

# Mean SSIM agreement with scikit-image (the requirement; we observe < 1e-14).
SSIM_TOLERANCE = 1e-4
# Per-pixel agreement of the float32 SSIM map with skimage's float64 map: float32 rounding of
# values in [-1, 1] plus the difference of filter summation orders.
SSIM_MAP_TOLERANCE = 1e-5
# mae/rmse/bias against numpy in float64: both sum float64 differences, in different orders.
STAT_TOLERANCE = 1e-10


def skimage_ssim(a, b, full=False):
    return structural_similarity(a.astype(np.float64), b.astype(np.float64), data_range=1.0,
                                 gaussian_weights=True, sigma=1.5,
                                 use_sample_covariance=False, full=full)


def blobs(shape, centres, rng=None):
    """An AO-like image: 1 (unoccluded) with dark Gaussian blobs (contact shadows, creases)."""
    h, w = shape
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    ao = np.ones(shape)
    for cx, cy, radius, depth in centres:
        ao -= depth * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * radius ** 2))
    if rng is not None:
        ao += rng.normal(0, 0.03, shape)  # Monte Carlo-like noise
    return np.clip(ao, 0, 1).astype(np.float32)


def image_pairs():
    rng = np.random.default_rng(1234)
    pairs = {}
    # Uniform random noise, 64 x 48 (width x height): independent, and correlated.
    a = rng.random((48, 64), dtype=np.float32)
    pairs["noise_independent"] = (a, rng.random((48, 64), dtype=np.float32))
    pairs["noise_correlated"] = (a, np.clip(a + rng.normal(0, 0.1, a.shape), 0, 1)
                                 .astype(np.float32))
    # Smooth gradients: little structure, the C2 stabiliser matters.
    y, x = np.mgrid[0:50, 0:70].astype(np.float64)
    g1 = (0.2 + 0.6 * x / 69).astype(np.float32)
    g2 = (0.1 + 0.5 * x / 69 + 0.3 * (y / 49) ** 2).astype(np.float32)
    pairs["gradients"] = (g1, g2)
    # AO-like: a clean reference and a noisy, slightly shifted, under-occluding estimate.
    ref = blobs((60, 80), [(20, 15, 6, 0.7), (55, 40, 10, 0.5), (70, 10, 3, 0.9)])
    est = blobs((60, 80), [(21, 15, 6, 0.6), (54, 41, 9, 0.45), (70, 10, 3, 0.7)],
                rng=rng)
    pairs["ao_blobs"] = (est, ref)
    # Non-square 37 x 101, both orientations.
    n1 = rng.random((101, 37), dtype=np.float32)
    pairs["tall_37x101"] = (n1, np.clip(n1 * 0.8 + 0.1 * rng.random(n1.shape), 0, 1)
                            .astype(np.float32))
    n2 = rng.random((37, 101), dtype=np.float32)
    pairs["wide_101x37"] = (n2, np.clip(n2 + rng.normal(0, 0.2, n2.shape), 0, 1)
                            .astype(np.float32))
    return pairs


PAIRS = image_pairs()


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_ssim_matches_skimage(name):
    a, b = PAIRS[name]
    ours = aolab.metrics(a, b)["ssim"]
    assert ours == pytest.approx(skimage_ssim(a, b), abs=SSIM_TOLERANCE)
    assert aolab.metrics(b, a)["ssim"] == ours  # symmetric, bit for bit


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_ssim_map_matches_skimage_full(name):
    a, b = PAIRS[name]
    _, expected = skimage_ssim(a, b, full=True)
    ours = _core.ssim_map(a, b)
    assert ours.dtype == np.float32 and ours.shape == a.shape
    np.testing.assert_allclose(ours, expected, rtol=0, atol=SSIM_MAP_TOLERANCE)
    assert ours.max() <= 1.0


def scipy_ssim_map(a, b):
    """SSIM map straight from scipy's gaussian_filter (mode 'reflect'), for images skimage
    refuses (smaller than its 11 x 11 window)."""
    a = a.astype(np.float64)
    b = b.astype(np.float64)

    def f(x):
        return ndimage.gaussian_filter(x, sigma=1.5, truncate=3.5, mode="reflect")

    ua, ub = f(a), f(b)
    va, vb, vab = f(a * a) - ua * ua, f(b * b) - ub * ub, f(a * b) - ua * ub
    c1, c2 = 0.01 ** 2, 0.03 ** 2
    return ((2 * ua * ub + c1) * (2 * vab + c2)) / ((ua ** 2 + ub ** 2 + c1) * (va + vb + c2))


@pytest.mark.parametrize("shape", [(3, 4), (1, 1), (2, 9), (12, 5)])
def test_small_images_use_repeated_reflection(shape):
    rng = np.random.default_rng(7)
    a = rng.random(shape, dtype=np.float32)
    b = np.clip(a + rng.normal(0, 0.2, shape), 0, 1).astype(np.float32)
    ours = _core.ssim_map(a, b)
    assert np.all(np.isfinite(ours))
    np.testing.assert_allclose(ours, scipy_ssim_map(a, b), rtol=0, atol=SSIM_MAP_TOLERANCE)
    # No interior: the mean is over every pixel (documented fallback).
    expected = scipy_ssim_map(a, b)
    if min(shape) < 11:
        assert aolab.metrics(a, b)["ssim"] == pytest.approx(expected.mean(),
                                                            abs=SSIM_MAP_TOLERANCE)


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_error_statistics_match_numpy(name):
    ao, ref = PAIRS[name]
    m = aolab.metrics(ao, ref)
    d = ao.astype(np.float64) - ref.astype(np.float64)
    mse = np.mean(d ** 2)
    assert m["count"] == ao.size
    assert m["mae"] == pytest.approx(np.mean(np.abs(d)), abs=STAT_TOLERANCE)
    assert m["rmse"] == pytest.approx(math.sqrt(mse), abs=STAT_TOLERANCE)
    assert m["bias"] == pytest.approx(np.mean(d), abs=STAT_TOLERANCE)
    assert m["psnr"] == pytest.approx(10 * math.log10(1 / mse), abs=1e-8)
    assert set(m) == {"mae", "rmse", "psnr", "bias", "ssim", "count"}


def test_identical_images():
    a = PAIRS["ao_blobs"][1]
    m = aolab.metrics(a, a)
    assert m["mae"] == 0 and m["rmse"] == 0 and m["bias"] == 0
    assert m["psnr"] == math.inf
    assert m["ssim"] == 1.0


@pytest.mark.parametrize("offset", [0.05, -0.2])
def test_constant_offset(offset):
    ref = PAIRS["ao_blobs"][1] * np.float32(0.5) + np.float32(0.25)
    ao = (ref.astype(np.float64) + offset).astype(np.float32)
    m = aolab.metrics(ao, ref)
    assert m["mae"] == pytest.approx(abs(offset), abs=1e-6)
    assert m["rmse"] == pytest.approx(abs(offset), abs=1e-6)
    assert m["bias"] == pytest.approx(offset, abs=1e-6)  # positive = brighter = under-occlusion
    assert m["psnr"] == pytest.approx(-20 * math.log10(abs(offset)), abs=1e-4)


def masked_reference(ao, ref, mask):
    """Our documented masked SSIM, rebuilt from skimage: background set to 1 in both, S
    averaged over masked pixels inside the 5-pixel crop."""
    a = np.where(mask, ao, 1).astype(np.float64)
    b = np.where(mask, ref, 1).astype(np.float64)
    _, s = skimage_ssim(a, b, full=True)
    interior = np.zeros_like(mask)
    interior[5:-5, 5:-5] = True
    return s[mask & interior].mean()


def test_mask_matches_numpy_and_skimage():
    ao, ref = PAIRS["ao_blobs"]
    h, w = ao.shape
    y, x = np.mgrid[0:h, 0:w]
    mask = (x - 40) ** 2 + (y - 30) ** 2 < 25 ** 2  # a round object on background
    ao = ao.copy()
    ao[~mask] = np.nan  # background values must not matter at all
    m = aolab.metrics(ao, ref, mask)
    d = ao[mask].astype(np.float64) - ref[mask].astype(np.float64)
    assert m["count"] == int(mask.sum())
    assert m["mae"] == pytest.approx(np.mean(np.abs(d)), abs=STAT_TOLERANCE)
    assert m["rmse"] == pytest.approx(math.sqrt(np.mean(d ** 2)), abs=STAT_TOLERANCE)
    assert m["bias"] == pytest.approx(np.mean(d), abs=STAT_TOLERANCE)
    assert m["ssim"] == pytest.approx(masked_reference(ao, ref, mask), abs=SSIM_TOLERANCE)


@pytest.mark.parametrize("dtype", [bool, np.uint8, np.float32, np.float64, np.int32])
def test_mask_dtypes_are_accepted(dtype):
    ao, ref = PAIRS["noise_correlated"]
    mask = np.zeros(ao.shape, dtype=bool)
    mask[10:40, 5:50] = True
    expected = aolab.metrics(ao, ref, mask.astype(np.float32))
    assert aolab.metrics(ao, ref, mask.astype(dtype)) == expected
    assert expected["count"] == 30 * 45


def test_all_ones_mask_equals_no_mask():
    ao, ref = PAIRS["gradients"]
    assert aolab.metrics(ao, ref, np.ones(ao.shape, bool)) == aolab.metrics(ao, ref)


def test_thread_count_does_not_change_bits():
    ao, ref = PAIRS["tall_37x101"]
    mask = ao > 0.3
    one = _core.metrics(ao, ref, mask, threads=1)
    for threads in (2, 3, 0):
        assert _core.metrics(ao, ref, mask, threads=threads) == one
        np.testing.assert_array_equal(_core.ssim_map(ao, ref, threads=threads),
                                      _core.ssim_map(ao, ref, threads=1))


def test_errors_name_the_parameter():
    ao, ref = PAIRS["noise_independent"]
    with pytest.raises(ValueError, match=r"^reference must have the size of ao \(64x48\)"):
        aolab.metrics(ao, ref[:, :30])
    with pytest.raises(ValueError, match=r"^mask must have the size of ao"):
        aolab.metrics(ao, ref, np.ones((48, 63), bool))
    with pytest.raises(ValueError, match=r"^ao must be a 2-D array"):
        aolab.metrics(ao[..., None], ref)
    with pytest.raises(ValueError, match=r"^reference must be a 2-D array"):
        aolab.metrics(ao, ref[0])
    with pytest.raises(ValueError, match=r"^mask must select at least one pixel, got 0"):
        aolab.metrics(ao, ref, np.zeros(ao.shape, bool))
    with pytest.raises(ValueError, match=r"^threads must be >= 0"):
        _core.metrics(ao, ref, threads=-1)
    with pytest.raises(ValueError, match=r"^b must have the size of a"):
        _core.ssim_map(ao, ref[:10])


def test_non_finite_scored_pixel_is_reported():
    ao, ref = (p.copy() for p in PAIRS["noise_independent"])
    ref[3, 5] = np.nan
    ref[7, 1] = np.inf
    with pytest.raises(ValueError, match=r"^reference must be finite .*\(x=5, y=3\), got nan"):
        aolab.metrics(ao, ref)
    ao[0, 2] = np.inf
    with pytest.raises(ValueError, match=r"^ao must be finite .*\(x=2, y=0\), got inf"):
        aolab.metrics(ao, ref)
    # Not scored: fine.
    mask = np.isfinite(ao) & np.isfinite(ref)
    assert aolab.metrics(ao, ref, mask)["count"] == ao.size - 3
