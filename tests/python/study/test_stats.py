"""Intervals over scenes and paired comparisons (aolab.study.stats): known answers, the
bootstrap's coverage, properties, and their place in the study's means."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aolab.study import results as results_mod
from aolab.study import stats


def test_one_scene_has_no_interval_and_constant_scores_a_point():
    assert stats.bootstrap_interval([0.1]) is None
    assert stats.bootstrap_interval([]) is None
    assert stats.bootstrap_interval([0.2, None, math.nan]) is None   # one finite value
    assert stats.bootstrap_interval([0.25] * 7) == (0.25, 0.25)


def test_the_interval_is_deterministic():
    v = [0.1, 0.3, 0.2, 0.5, 0.05]
    assert stats.bootstrap_interval(v) == stats.bootstrap_interval(list(v))


def test_coverage_of_the_mean_is_near_95_percent():
    """Over 300 samples of 20 scenes from a skewed distribution with known mean 1, the
    interval holds the mean in 0.88-0.98 of them: the percentile bootstrap under-covers a
    little at 20 (about 0.92-0.94 in the literature); the band is four binomial standard
    errors wide."""
    rng = np.random.default_rng(7)
    hits = 0
    for _ in range(300):
        sample = rng.exponential(1.0, 20)
        lo, hi = stats.bootstrap_interval(sample, resamples=2000)
        hits += lo <= 1.0 <= hi
    assert 0.88 <= hits / 300 <= 0.98


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.0, 1.0, allow_nan=False), min_size=2, max_size=40))
def test_the_interval_lies_within_the_values_and_holds_their_mean(values):
    lo, hi = stats.bootstrap_interval(values, resamples=500)
    eps = 1e-12
    assert min(values) - eps <= lo <= hi <= max(values) + eps
    # the sample mean is inside unless nearly every resample misses it (not with 500)
    mean = float(np.mean(values))
    assert lo - 1e-9 <= mean <= hi + 1e-9 or hi - lo < 1e-9


def test_paired_known_answers():
    a = {f"s{i}": 0.1 for i in range(10)}
    b = {f"s{i}": 0.2 + 0.01 * i for i in range(10)}
    c = stats.paired(a, b)
    # a better on all ten: the exact two-sided signed-rank p is 2 / 2**10
    assert (c["n"], c["wins"], c["losses"], c["ties"]) == (10, 10, 0, 0)
    assert c["p"] == pytest.approx(2 / 2 ** 10) and c["real"]
    assert c["mean_diff"] == pytest.approx(-0.145)
    assert "real" in stats.verdict(c)
    same = stats.paired(a, dict(a))
    assert same["p"] == 1.0 and not same["real"] and same["ties"] == 10
    assert "noise" in stats.verdict(same)
    # only the scenes both have; one scene cannot be tested
    one = stats.paired({"x": 0.1, "y": 0.2}, {"x": 0.3})
    assert one["n"] == 1 and one["p"] is None and "too few" in stats.verdict(one)


def test_paired_alternating_differences_are_noise():
    a = {f"s{i}": 0.1 + (0.01 if i % 2 else -0.01) for i in range(12)}
    b = {f"s{i}": 0.1 for i in range(12)}
    c = stats.paired(a, b)
    assert c["wins"] == 6 and c["losses"] == 6 and not c["real"] and c["p"] > 0.5


def _row(scene, ms, all_mae, occ):
    metrics = {region: {m: 0.0 for m in results_mod.METRICS} for region in results_mod.REGIONS}
    metrics["all"]["mae"], metrics["occluded"]["mae"] = all_mae, occ
    return {"scene": scene, "kind": "method", "method": "m", "label": "default",
            "metrics": metrics, "total_ms": ms, "method_ms": ms, "blur_ms": 0.0}


def test_all_scenes_times_are_per_1280x720_frame_with_intervals():
    rows = [_row("big", 40.0, 0.05, 0.10), _row("small", 10.0, 0.07, 0.20),
            _row("small2", 12.0, 0.06, 0.15)]
    scale = {"big": 1.0, "small": 4.0, "small2": 4.0}     # 640x360 is a quarter of 1280x720
    (agg,) = results_mod.aggregate(rows, ["big", "small", "small2"], time_scale=scale)
    assert agg["total_ms"] == pytest.approx((40.0 + 40.0 + 48.0) / 3)
    assert agg["method_ms"] == pytest.approx((40.0 + 40.0 + 48.0) / 3)
    iv = agg["intervals"]
    assert iv["occluded_mae"][0] <= agg["metrics"]["occluded"]["mae"] <= iv["occluded_mae"][1]
    assert iv["total_ms"] == [pytest.approx(40.0), pytest.approx(48.0)] or \
        40.0 <= iv["total_ms"][0] <= iv["total_ms"][1] <= 48.0
    (alone,) = results_mod.aggregate(rows[:1], ["big"])
    assert alone["intervals"]["all_mae"] is None    # one scene: no spread to show
