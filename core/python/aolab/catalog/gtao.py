"""GTAO: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MethodEntry, int_bound


# GTAO — Jimenez et al. 2016. The memo spreads one slice per pixel and frame over a 4x4
# spatial and a 6-frame temporal filter and gives no quality table; XeGTAO, the reference
# implementation, names four levels: slices 1/2/3/9 with 2/2/3/3 steps per side (its
# QualityLevel, default "High"), which are the presets. Its own denoiser stands in for the
# memo's filters; here the shared Gaussian does (timed apart). The full sweep adds denser
# slices and steps, XeGTAO's tuned falloff (0.615 of R) against the memo's hard cut, and the
# blur on and off.
ENTRY = MethodEntry(
    "gtao",
    presets={
        "low": {"slices": 1, "steps": 2, "blur": True},
        "medium": {"slices": 2, "steps": 2, "blur": True},
        "high": {"slices": 3, "steps": 3, "blur": True},
        "ultra": {"slices": 9, "steps": 3, "blur": True},
    },
    sweep={"slices": [1, 2, 3, 9, 16], "steps": [2, 3, 8], "falloff": [0.0, 0.615],
           "blur": [False, True]},
    source="XeGTAO quality levels (slices 1/2/3/9, steps 2/2/3/3); sweep ours",
    tune_bounds={
        "slices": int_bound(1, 64, "XeGTAO's quality levels use 1-9, the sweep 16, up to the "
                            "method's most (64); log scale", log=True),
        "steps": int_bound(1, 64, "per side of a slice: XeGTAO 2-3, the sweep 8; 64 x 64 is "
                           "past the largest budget; log scale", log=True),
    },
    tune_fixed={
        "multi_bounce": (None, "models interreflections, which Cycles' AO pass has not"),
        "albedo": (None, "applies with multi_bounce only"),
    },
    samples_per_pixel=lambda s: s["slices"] * 2 * s["steps"],
)
