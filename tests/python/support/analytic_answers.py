"""Answers computed independently of the library, shared by the method tests."""
import numpy as np


def step_answer(a, h, radius, n=200_000):
    """AO of a floor point at distance a from the foot of a step of height h seen from
    straight above (t = 0), by quadrature over the azimuth θ. In azimuth θ towards the step
    the slab top's points lie at horizontal distances ≥ a/cos θ; the top edge, at
    r = sqrt((a/cos θ)² + h²), is both HBAO's horizon (eq. 3: sin h = h/r, W = 1 - r/R) and
    Pyramid HBAO's largest weighted contribution (eq. 8: W(r)·sin α = (1 - r/R)·h/r falls
    with r), counted only if r <= R. So both methods share A = 1 - mean over θ."""
    theta = (np.arange(n) + 0.5) / n * 2 * np.pi - np.pi
    c = np.cos(theta)
    r = np.where(c > 0, np.hypot(a / np.where(c > 0, c, 1), h), np.inf)
    within = r <= radius
    contrib = np.zeros_like(r)
    contrib[within] = h / r[within] * (1 - r[within] / radius)
    return 1 - contrib.mean()
