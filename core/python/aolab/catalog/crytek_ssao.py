"""Crytek SSAO: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MethodEntry, int_bound


# Crytek SSAO — Mittring 2007, §8.5.4.3: CryEngine 2 took 8 to 16 points per pixel and
# blurred away the 4x4 pattern of its reflection texture; low/medium = 8/16, high and ultra
# double them. The shared Gaussian stands in for the engine's blur (timed apart). The sweep
# adds the distributions, the range checks and the hemisphere variant.
ENTRY = MethodEntry(
    "crytek_ssao",
    presets={
        "low": {"samples": 8, "blur": True},
        "medium": {"samples": 16, "blur": True},
        "high": {"samples": 32, "blur": True},
        "ultra": {"samples": 64, "blur": True},
    },
    sweep={"samples": [8, 16, 32, 64], "distribution": ["centre", "uniform"],
           "range_check": ["smooth", "hard", "off"], "hemisphere": [False, True],
           "blur": [False, True]},
    source="Mittring 2007, §8.5.4.3 (8-16 points, a blur); high/ultra ours",
    tune_bounds={
        "samples": int_bound(4, 256, "N: CryEngine 2's 8-16 inside, up to the method's most "
                             "(256); log scale", log=True),
    },
    samples_per_pixel=lambda s: s.get("samples"),
)
