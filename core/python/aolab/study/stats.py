"""Uncertainty of means over scenes, as a referee asks for it: a 95 % bootstrap interval of
a mean over scenes, and the paired comparison of two configurations on the same scenes
(wins per scene and the Wilcoxon signed-rank test). Used by the comparison study, its report
and docs/results.md (docs/comparison.md, "Intervals and paired comparisons").

The scenes are the unit: each is one draw from the kinds of scenes users render, and the
pixels of one scene are not independent draws. So intervals resample scenes, and paired
tests pair scenes.
"""

from __future__ import annotations

import math

import numpy as np

#: The intervals' coverage.
LEVEL = 0.95
#: Bootstrap resamples: the interval's ends move by well under 1 % of its width between
#: seeds at this count.
RESAMPLES = 10_000
#: The bootstrap's seed: the same scores give the same interval.
SEED = 0
#: A paired difference is called real below this p-value of the Wilcoxon signed-rank test.
ALPHA = 0.05


def bootstrap_interval(values, level: float = LEVEL, resamples: int = RESAMPLES,
                       seed: int = SEED) -> tuple[float, float] | None:
    """The percentile bootstrap interval of the mean of ``values`` (one per scene; NaN and
    None left out), or None with fewer than two values: one scene has no spread to show."""
    v = np.array([x for x in values if x is not None and math.isfinite(x)], np.float64)
    if v.size < 2:
        return None
    rng = np.random.default_rng(seed)
    means = v[rng.integers(0, v.size, size=(resamples, v.size))].mean(axis=1)
    tail = (1.0 - level) / 2.0
    lo, hi = np.quantile(means, [tail, 1.0 - tail])
    return float(lo), float(hi)


def paired(a: dict, b: dict, alpha: float = ALPHA) -> dict:
    """Configuration a against b on the scenes both have (``a``, ``b``: scene -> error,
    lower is better): "n", "wins" (scenes where a is lower), "losses", "ties", "mean_diff"
    (mean of a − b), "p" (two-sided Wilcoxon signed-rank p-value, exact for small samples;
    1 when every difference is 0; None below 2 scenes) and "real" (p < alpha)."""
    common = [s for s in a if s in b and _finite(a[s]) and _finite(b[s])]
    d = np.array([a[s] - b[s] for s in common], np.float64)
    out = {"n": len(common), "wins": int((d < 0).sum()), "losses": int((d > 0).sum()),
           "ties": int((d == 0).sum()), "mean_diff": float(d.mean()) if d.size else None,
           "p": None, "real": False}
    if d.size < 2:
        return out
    if not np.any(d != 0):
        out["p"] = 1.0
        return out
    from scipy.stats import wilcoxon
    out["p"] = float(wilcoxon(d[d != 0]).pvalue)
    out["real"] = out["p"] < alpha
    return out


def _finite(x) -> bool:
    return x is not None and math.isfinite(x)


def verdict(comparison: dict) -> str:
    """A paired comparison in words: which differences are real and which are noise."""
    if comparison["p"] is None:
        return "too few scenes to tell"
    if comparison["real"]:
        return f"real (p = {comparison['p']:.3g})"
    return f"not distinguishable from noise (p = {comparison['p']:.2g})"
