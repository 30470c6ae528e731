"""Temporal accumulation through the Python API (docs/temporal.md): closed forms, properties
over random frames, motion and settings (hypothesis), the per-frame seed of every method and
the convergence of real methods over static frames."""
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings as hsettings, strategies as st

import aolab
from docs_settings import assert_docs_settings_table
from gil_support import ticks_while

DOC = Path(__file__).resolve().parents[3] / "docs" / "temporal.md"


def flat(w, h, depth=2.0):
    """A plane facing the camera: every history tap agrees in depth and normal."""
    normal = np.zeros((h, w, 3), np.float32)
    normal[..., 2] = 1
    return aolab.GBuffer(np.full((h, w), depth, np.float32), normal, fx=10, fy=10, cx=w / 2,
                         cy=h / 2)


def still(w, h):
    return np.zeros((h, w, 2), np.float32)


def test_static_scene_with_alpha_zero_is_the_mean(rng):
    # Each blend rounds to float once: 16 frames of values in [0, 1] stay within 1e-6.
    g, history = flat(12, 8), aolab.TemporalHistory()
    frames = rng.random((16, 8, 12), dtype=np.float32)
    for k, ao in enumerate(frames):
        out, dis = aolab.accumulate(ao, g, still(12, 8), history, alpha=0, clamp="off")
        np.testing.assert_allclose(out, frames[:k + 1].astype(np.float64).mean(0), atol=1e-6)
        assert dis.dtype == bool and dis.all() == (k == 0) and dis.any() == (k == 0)
        np.testing.assert_array_equal(history.length, k + 1)


def test_alpha_gives_the_closed_form_weighted_mean(rng):
    # K + 1 = floor(1/alpha) frames enter the running mean alike (while 1/(n+1) >= alpha),
    # then each with weight alpha (the float32 alpha the step holds).
    g, history, n = flat(6, 5), aolab.TemporalHistory(), 15
    alpha = float(np.float32(0.3))
    frames = rng.random((n, 5, 6), dtype=np.float32)
    for ao in frames:
        out, _ = aolab.accumulate(ao, g, still(6, 5), history, alpha=alpha, clamp="off")
    k = int(np.floor(1 / alpha)) - 1
    f = frames.astype(np.float64)
    want = (1 - alpha) ** (n - 1 - k) * f[:k + 1].mean(0)
    want += sum(alpha * (1 - alpha) ** (n - 1 - i) * f[i] for i in range(k + 1, n))
    np.testing.assert_allclose(out, want, atol=2e-6)


@hsettings(max_examples=60)
@given(dx=st.integers(-6, 6), dy=st.integers(-6, 6), seed=st.integers(0, 2**32 - 1))
def test_an_integer_pan_reads_the_shifted_history_exactly(dx, dy, seed):
    rng = np.random.default_rng(seed)
    w, h = 11, 9
    g, history = flat(w, h), aolab.TemporalHistory()
    a, b = rng.random((2, h, w), dtype=np.float32)
    aolab.accumulate(a, g, still(w, h), history, alpha=0, clamp="off")
    motion = np.empty((h, w, 2), np.float32)
    motion[...] = (dx, dy)
    out, dis = aolab.accumulate(b, g, motion, history, alpha=0, clamp="off")
    j, i = np.mgrid[0:h, 0:w]
    pi, pj = i + dx, j + dy
    inside = (pi >= 0) & (pi < w) & (pj >= 0) & (pj < h)
    past = a[np.clip(pj, 0, h - 1), np.clip(pi, 0, w - 1)].astype(np.float64)
    want = np.where(inside, (past + 0.5 * (b - past)).astype(np.float32), b)
    np.testing.assert_array_equal(out, want)
    np.testing.assert_array_equal(dis, ~inside)


def neighbourhood_range(ao, valid):
    """Min and max of ao over the geometry pixels of each 3x3 neighbourhood."""
    h, w = ao.shape
    lo = np.pad(np.where(valid, ao, np.inf), 1, constant_values=np.inf)
    hi = np.pad(np.where(valid, ao, -np.inf), 1, constant_values=-np.inf)

    def stack(padded, reduce):
        return reduce([padded[j:j + h, i:i + w] for j in range(3) for i in range(3)], axis=0)

    return stack(lo, np.min), stack(hi, np.max)


@hsettings(max_examples=80)
@given(w=st.integers(1, 24), h=st.integers(1, 10), frames=st.integers(1, 5),
       seed=st.integers(0, 2**32 - 1), alpha=st.floats(0, 1),
       clamp=st.sampled_from(["off", "minmax", "variance"]),
       depth_tolerance=st.floats(0, 10), normal_tolerance=st.floats(-1, 1),
       motion_scale=st.sampled_from([0.0, 0.7, 3.0, 40.0]))
def test_properties_over_random_frames(w, h, frames, seed, alpha, clamp, depth_tolerance,
                                       normal_tolerance, motion_scale):
    """For random depth (background included), normals, AO, motion (NaN and off-screen
    included) and settings: the result lies within the range of every input so far, and with
    a clamp within the current 3x3 neighbourhood's range; disoccluded pixels take the
    current frame exactly; frame 0 is disoccluded on every geometry pixel; background keeps
    the current value and is never flagged. The scalar code gives the SIMD kernel's bits."""
    rng = np.random.default_rng(seed)
    history, lo_all, hi_all = aolab.TemporalHistory(), np.inf, -np.inf
    scalar = aolab.TemporalHistory()
    for k in range(frames):
        depth = rng.choice(np.float32([1.0, 1.02, 1.5, 3.0, 1e10]), size=(h, w))
        normal = rng.normal(size=(h, w, 3)).astype(np.float32)
        g = aolab.GBuffer(depth, normal, fx=10, fy=10, cx=w / 2, cy=h / 2)
        valid = g.valid_mask()
        ao = rng.random((h, w), dtype=np.float32)
        lo_all, hi_all = min(lo_all, ao[valid].min(initial=np.inf)), max(
            hi_all, ao[valid].max(initial=-np.inf))
        motion = (rng.normal(size=(h, w, 2)) * motion_scale).astype(np.float32)
        motion[rng.random((h, w)) < 0.1] = np.nan
        chosen = dict(alpha=alpha, clamp=clamp, depth_tolerance=depth_tolerance,
                      normal_tolerance=normal_tolerance)
        out, dis = aolab.accumulate(ao, g, motion, history, **chosen)
        out_s, dis_s = aolab.accumulate(ao, g, motion, scalar, kernel="scalar", **chosen)
        np.testing.assert_array_equal(out.view(np.uint32), out_s.view(np.uint32))
        np.testing.assert_array_equal(dis, dis_s)
        np.testing.assert_array_equal(history.length, scalar.length)
        assert ((out[valid] >= lo_all) & (out[valid] <= hi_all)).all()
        np.testing.assert_array_equal(out[dis], ao[dis])
        np.testing.assert_array_equal(out[~valid], ao[~valid])
        assert not dis[~valid].any()
        if k == 0:
            np.testing.assert_array_equal(dis, valid)
        if clamp != "off":
            lo, hi = neighbourhood_range(ao, valid)
            assert ((out[valid] >= lo[valid]) & (out[valid] <= hi[valid])).all()


def test_same_bits_for_threads_1_2_8(rng):
    w, h = 37, 29
    results = []
    for threads in (1, 2, 8):
        history = aolab.TemporalHistory()
        g = flat(w, h)
        for k in range(4):
            ao = np.random.default_rng(k).random((h, w), dtype=np.float32)
            motion = np.random.default_rng(10 + k).uniform(-2, 2, (h, w, 2)).astype(np.float32)
            out, dis = aolab.accumulate(ao, g, motion, history, clamp="variance",
                                        threads=threads)
        results.append((out, dis, history.length, history.ao))
    for other in results[1:]:
        for a, b in zip(results[0], other):
            np.testing.assert_array_equal(a, b)


def test_gil_is_released_during_accumulate():
    w, h = 1920, 1080
    g, history = flat(w, h), aolab.TemporalHistory()
    ao = np.random.default_rng(0).random((h, w), dtype=np.float32)
    motion = np.full((h, w, 2), 0.5, np.float32)
    aolab.accumulate(ao, g, motion, history, threads=1)
    ticks = ticks_while(lambda: aolab.accumulate(ao, g, motion, history, threads=1))
    assert ticks > 5  # the main thread ran while the step did


def test_bad_values_are_value_errors_naming_them():
    g, history, ao = flat(6, 5), aolab.TemporalHistory(), np.full((5, 6), 0.5, np.float32)
    cases = [
        (dict(alpha=1.5), "alpha must be in [0, 1], got 1.5"),
        (dict(clamp="bogus"), "clamp must be one of off, minmax, variance, got 'bogus'"),
        (dict(max_history=0), "max_history must be in [1, 65535] frames, got 0"),
        (dict(nonsense=1), "unknown setting 'nonsense' for accumulate"),
    ]
    for kwargs, message in cases:
        with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")):
            aolab.accumulate(ao, g, still(6, 5), history, **kwargs)
    with pytest.raises(ValueError,
                       match=r"motion must be a 3-D array \(H, W, 2\), got \(5, 6, 3\)"):
        aolab.accumulate(ao, g, np.zeros((5, 6, 3), np.float32), history)
    with pytest.raises(ValueError, match=r"motion must have the size of depth \(6x5\), got 5x5"):
        aolab.accumulate(ao, g, still(5, 5), history)
    with pytest.raises(ValueError, match="threads must be >= 0"):
        aolab.accumulate(ao, g, still(6, 5), history, threads=-1)
    with pytest.raises(ValueError, match='kernel must be "simd" or "scalar", got fast'):
        aolab.accumulate(ao, g, still(6, 5), history, kernel="fast")
    assert history.empty
    aolab.accumulate(ao, g, still(6, 5), history)
    with pytest.raises(ValueError, match=r"history must be empty \(frame 0\) or from frames"):
        aolab.accumulate(np.zeros((4, 4), np.float32), flat(4, 4), still(4, 4), history)
    history.reset()
    assert history.empty and history.ao is None
    for args, name in [((-1, 0), "seed"), ((0, -2), "frame"), ((0, 1.5), "frame"),
                       ((True, 1), "seed"), ((2**31, 0), "seed")]:
        with pytest.raises(ValueError, match=f"^{name} must be"):
            aolab.frame_seed(*args)


def test_the_settings_are_described_and_copied_by_the_docs_page():
    settings = aolab.accumulate_settings()
    assert [s["name"] for s in settings] == ["alpha", "max_history", "depth_tolerance",
                                             "normal_tolerance", "clamp", "variance_gamma"]
    assert_docs_settings_table("accumulate", DOC, settings)


def seeded_methods():
    return [m for m in aolab.methods()
            if any(s["name"] == "seed" for s in aolab.method_info(m)["settings"])]


def test_frame_varies_every_seeded_method_and_frame_0_changes_nothing():
    g = aolab.analytic_scene("blocks", 64, 36)  # R = 1: every method sees occlusion here
    for method in aolab.methods():
        plain = aolab.compute(method, g, radius=1.0)
        np.testing.assert_array_equal(aolab.compute(method, g, radius=1.0, frame=0), plain)
        moved = aolab.compute(method, g, radius=1.0, frame=1)
        if method in seeded_methods():
            assert not np.array_equal(moved, plain), method
        else:
            np.testing.assert_array_equal(moved, plain)  # nothing random to vary
    with pytest.raises(ValueError, match="^frame must be"):
        aolab.compute("hbao", g, radius=0.5, frame=-1)
    assert aolab.frame_seed(7, 0) == 7
    assert len({aolab.frame_seed(7, k) for k in range(1, 200)}) == 199


def mean_error(a, b, valid):
    return float(np.abs(a - b)[valid].mean())


@pytest.mark.parametrize("method", seeded_methods())
def test_every_method_accumulated_over_static_frames_converges(method):
    """Each method at compute(frame=k), accumulated over 16 static frames with alpha = 0, is
    nearer its many-sample result (the mean of 64 frames at other seeds) than one frame is.
    The mean of N independent frames has 1/N of one frame's variance, so the error falls by
    about 1/4 from 1 to 16 frames (a bit less, as the 64-frame mean keeps its own noise);
    frames that repeated one pattern would not fall at all. Bound: 0.6."""
    g = aolab.analytic_scene("blocks", 64, 36)
    valid = g.valid_mask()
    many = np.mean([aolab.compute(method, g, radius=1.0, seed=aolab.frame_seed(4242, k))
                    for k in range(64)], axis=0)
    history, still_motion = aolab.TemporalHistory(), still(64, 36)
    for k in range(16):
        ao = aolab.compute(method, g, radius=1.0, frame=k)
        out, _ = aolab.accumulate(ao, g, still_motion, history, alpha=0, clamp="off")
        if k == 0:
            first = ao
    e1, e16 = mean_error(first, many, valid), mean_error(out, many, valid)
    print(f"{method}: one frame {e1:.4f}, 16 frames {e16:.4f}")
    assert e1 > 0, method
    assert e16 < 0.6 * e1, (method, e1, e16)


def test_accumulated_hbao_nears_hbao_with_many_directions():
    """HBAO with 8 directions, accumulated over 16 frames, against HBAO with 64 directions:
    the accumulated error is at most half of one frame's (measured in docs/temporal.md)."""
    g = aolab.analytic_scene("blocks", 96, 54)
    valid = g.valid_mask()
    reference = aolab.compute("hbao", g, radius=0.5, directions=64, seed=977)
    history = aolab.TemporalHistory()
    for k in range(16):
        ao = aolab.compute("hbao", g, radius=0.5, frame=k)
        out, _ = aolab.accumulate(ao, g, still(96, 54), history, alpha=0, clamp="off")
        if k == 0:
            first = ao
    e1, e16 = mean_error(first, reference, valid), mean_error(out, reference, valid)
    print(f"hbao 8 directions vs 64: one frame {e1:.4f}, 16 frames {e16:.4f}")
    assert e16 < 0.5 * e1


def test_a_camera_pan_reprojects_a_real_method():
    """A window sliding right over a wider render of `blocks` by 1 px per frame (a sensor
    shift: depth and normals stay, the content moves 1 px left, so dx = +1). HBAO accumulated
    with the motion converges on the occluded pixels as on a static scene (measured: 0.0132
    one frame, 0.0045 after 16), and exactly the entering column is disoccluded. With the
    sign of dx flipped every tap lands 2 px off and the error would not fall."""
    big, w = aolab.analytic_scene("blocks", 200, 90), 160

    def window(x0):
        return aolab.GBuffer(big.depth[:, x0:x0 + w].copy(), big.normal[:, x0:x0 + w].copy(),
                             fx=big.fx, fy=big.fy, cx=big.cx - x0, cy=big.cy)

    motion = np.zeros((90, w, 2), np.float32)
    motion[..., 0] = 1.0
    history = aolab.TemporalHistory()
    for k in range(16):
        g = window(k)
        ao = aolab.compute("hbao", g, radius=1.0, steps=32, frame=k)
        out, dis = aolab.accumulate(ao, g, motion, history, alpha=0.1)
        if k == 0:
            first = ao
        else:
            np.testing.assert_array_equal(dis[:, :-1], False)
            np.testing.assert_array_equal(dis[:, -1], g.valid_mask()[:, -1])
    reference = aolab.compute("hbao", g, radius=1.0, directions=64, steps=32, seed=977)
    occluded = g.valid_mask() & (reference < 0.99)
    first_reference = aolab.compute("hbao", window(0), radius=1.0, directions=64, steps=32,
                                    seed=977)
    e1 = float(np.abs(first - first_reference)[window(0).valid_mask() & (first_reference < 0.99)]
               .mean())
    e16 = float(np.abs(out - reference)[occluded].mean())
    print(f"pan: one frame {e1:.4f}, 16 frames {e16:.4f}")
    assert e16 < 0.5 * e1
