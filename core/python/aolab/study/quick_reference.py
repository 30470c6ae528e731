"""The reference a scene's methods are scored against when there is no time for Cycles: rtao
at a few rays per pixel against the scene's triangles (the `mesh` pass), with its noise
stated — and the Cycles reference in the same form, so that what scores against either says
which it was (docs/comparison.md, "Advise: the quick reference and its noise").

rtao computes Cycles' AO integral (docs/methods/rtao.md): at N rays each pixel is the mean of
N binary visibilities, so the quick reference differs from the noise-free AO by zero-mean
noise of standard deviation about sqrt(AO(1 − AO)/N), and every MAE against it reads high by
at most its mean absolute noise (aolab.scoring.reference_noise). At 64 rays on 320x180 it
takes a fraction of a second; the Cycles reference takes minutes.

The N rays are traced as two independent halves (seeds 0 and 1) and averaged, so that how
much a given output's MAE reads high can also be estimated from the output itself
(Reference.inflation): that bound, unlike the reference's noise, is small where the output
is far from the truth, as most outputs are on most pixels.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass

import numpy as np

import aolab

from ..regions import occluded_pixels
from ..scoring import reference_noise, scored_mask

#: The quick reference's rays per pixel by default (the panel's and `aolab advise`'s).
QUICK_RAYS = 64
#: The fewest rays the quick reference takes: its noise is estimated from the reference
#: itself, which needs N >= 2 (an unbiased variance of the N-ray mean).
MIN_RAYS = 2
#: The kinds of reference a scene is scored against.
CYCLES, QUICK = "cycles", "quick"


@dataclass
class Reference:
    """The AO a scene is scored against, and what it is: ``kind`` CYCLES (the G-buffer's own
    AO pass) or QUICK (rtao), its ``samples`` per pixel, its noise over the scored pixels
    (``noise``) and over the occluded region (``noise_occluded``; scoring.reference_noise,
    None when unknown), and for the quick one its two independent ``halves`` (their rays
    and images), the seconds its rays and its BVH took and rtao's range warning, if any."""
    kind: str
    ao: np.ndarray
    samples: int
    noise: float | None
    noise_occluded: float | None
    seconds: float | None = None
    build_seconds: float | None = None
    triangles: int | None = None
    warning: str | None = None
    halves: tuple | None = None   # ((rays, image), (rays, image))

    def inflation(self, ao: np.ndarray, mask: np.ndarray) -> float | None:
        """An upper estimate of how much higher the MAE of ``ao`` over ``mask`` reads against
        this reference than against the noise-free AO; None without halves or pixels.

        Against a reference of noise e with spread s, an output off by d at a pixel reads
        E|d − e| = |d| + s·φ(|d|/s) for normal e, φ(u) = sqrt(2/π)·exp(−u²/2) − 2u·Φ(−u),
        which falls with u: so the inflation at spread k·s is at least k times the one at s
        (k ≥ 1). Each half has the spread k_i = sqrt(N/N_i) times the whole's (√2 for equal
        halves), so (mean MAE against the halves − MAE against the whole) / (mean k_i − 1)
        is, in expectation, at least the whole's inflation: exact where the output is exact,
        near 0 where it is far off."""
        m = np.asarray(mask, bool)
        if self.halves is None or not m.any():
            return None
        x = ao[m].astype(np.float64)
        whole = float(np.mean(np.abs(x - self.ao[m])))
        halves = [float(np.mean(np.abs(x - image[m]))) for _, image in self.halves]
        k = np.mean([math.sqrt(self.samples / rays) for rays, _ in self.halves])
        return max(0.0, (float(np.mean(halves)) - whole) / (k - 1.0))

    @property
    def label(self) -> str:
        """"quick (rtao 64 rays)" or "Cycles 1024 spp", as the panel and the command label
        the scores."""
        return label(self.kind, self.samples)

    def info(self) -> dict:
        """Everything but the images, for JSON."""
        return {"kind": self.kind, "label": self.label, "samples": self.samples,
                "noise": self.noise, "noise_occluded": self.noise_occluded,
                "seconds": self.seconds, "build_seconds": self.build_seconds,
                "triangles": self.triangles, "warning": self.warning,
                "halves": [n for n, _ in self.halves] if self.halves else None}


def label(kind: str, samples: int) -> str:
    """What the scores are against; an AO pass whose sidecar records no samples (an analytic
    scene's closed form, a G-buffer from elsewhere) is not called a 0-spp Cycles render."""
    if kind == QUICK:
        return f"quick (rtao {samples} rays)"
    return f"Cycles {samples} spp" if samples > 0 else "the G-buffer's AO pass (samples unknown)"


def _with_noise(g, kind: str, ao: np.ndarray, samples: int, **extra) -> Reference:
    valid = scored_mask(g, ao)
    return Reference(kind, ao, samples, reference_noise(ao, samples, valid),
                     reference_noise(ao, samples, occluded_pixels(valid, ao)), **extra)


def cycles(g) -> Reference:
    """The G-buffer's own AO pass (a reference.exr), with the samples its sidecar records (0
    when it records none: the noise is then unknown)."""
    if getattr(g, "reference", None) is None:
        raise ValueError("the G-buffer has no AO pass to score against")
    try:
        samples = int((g.sidecar or {}).get("samples") or 0)
    except (TypeError, ValueError):
        samples = 0
    return _with_noise(g, CYCLES, np.asarray(g.reference, np.float32), samples)


def quick(g, mesh=None, *, radius: float, rays: int = QUICK_RAYS, threads: int = 0) -> Reference:
    """rtao at ``rays`` per pixel on G-buffer ``g`` against ``mesh`` (default: the
    `.mesh` exported beside it, aolab.mesh_for_gbuffer; paired by scene hash), as two
    independent halves (rays // 2 at seed 0, the rest at seed 1) averaged. A G-buffer on
    which rtao's ray offset reaches R is a ValueError saying so; where it exceeds 1 % of R the
    warning is kept in the result."""
    if not (isinstance(rays, int) and MIN_RAYS <= rays <= 65536):
        raise ValueError(f"the quick reference's rays must be an integer in [{MIN_RAYS}, "
                         f"65536] (its noise is estimated from itself), got {rays!r}")
    if mesh is None:
        mesh = aolab.mesh_for_gbuffer(g)
    scene = aolab.ray_scene(mesh, g, threads=threads)
    offsets = aolab.rtao_range(g, scene, radius=radius, threads=threads)
    if offsets["refusal"]:
        raise ValueError(offsets["refusal"])
    halves = []
    with warnings.catch_warnings():   # kept in the result instead, once
        warnings.simplefilter("ignore", aolab.RtaoRangeWarning)
        t0 = time.perf_counter()
        for seed, n in enumerate((rays // 2, rays - rays // 2)):
            halves.append((n, aolab.rtao(g, scene, radius=radius, rays=n, seed=seed,
                                         threads=threads)))
        seconds = time.perf_counter() - t0
    ao = (sum(n * image.astype(np.float64) for n, image in halves) / rays).astype(np.float32)
    return _with_noise(g, QUICK, ao, rays, seconds=seconds, build_seconds=scene.build_seconds,
                       triangles=scene.triangles, warning=offsets["warning"],
                       halves=tuple(halves))
