"""Alchemy AO: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MethodEntry, float_bound, int_bound


# Alchemy AO — McGuire et al. 2011: its quality parameter is the tap count s. The paper's
# Figure 1 runs 12 taps at 1280x720 (the high preset, the method's default); the other
# levels halve and double around it as the paper's scalability goal (fewer taps on weaker
# hardware) describes, without a table of its own. The per-pixel rotation leaves noise that
# the paper's edge-aware filter removes; here the shared Gaussian does (timed apart).
ENTRY = MethodEntry(
    "alchemy",
    presets={
        "low": {"samples": 4, "blur": True},
        "medium": {"samples": 8, "blur": True},
        "high": {"samples": 12, "blur": True},
        "ultra": {"samples": 24, "blur": True},
    },
    sweep={"samples": [4, 8, 12, 24, 48], "falloff": ["alchemy", "smooth"],
           "blur": [False, True]},
    source="McGuire et al. 2011, Figure 1 (12 taps); other levels ours",
    tune_bounds={
        "samples": int_bound(2, 98, "s: the paper's 12 inside, up to the method's most (98, "
                             "its spiral table); log scale", log=True),
        "intensity": float_bound(0.1, 10.0, "sigma in units of r: the default 1 a decade inside "
                                 "either way; log scale", log=True),
        "contrast": float_bound(0.5, 4.0, "k: 1 the paper's; power (searched for every method) "
                                "does the same, so a narrow span; log scale", log=True),
        "bias": float_bound(1e-6, 1e-2, "beta per unit of depth: the paper's 1e-4 two decades "
                            "inside; log scale", log=True),
        "epsilon": float_bound(1e-6, 1e-1, "in units of r^2: the paper's 1e-4 inside; log scale",
                               log=True),
    },
    tune_fixed={
        "turns": (None, "0 = the SAO paper's low-discrepancy tau for s; other turns only "
                  "line the taps up"),
    },
    samples_per_pixel=lambda s: s.get("samples"),
)
