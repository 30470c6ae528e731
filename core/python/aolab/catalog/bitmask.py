"""The visibility bitmask: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MIP_DISTANCE_BOUND, MethodEntry, choice_bound, float_bound, int_bound


# Visibility bitmask — Therrien, Levesque, Gilet 2023. The paper fixes 32 sectors and a
# constant thickness but no quality levels. Blender 4.2's EEVEE, which implements it, marches
# 2 slices per pixel with 8 steps per side by default (slice_len, fast_gi_step_count): that is
# `medium` (and the method's defaults); low halves the steps and takes one slice, high and
# ultra add a slice and 4 steps each. XeGTAO's 2-3 steps per side are too few here: a
# sample marks only the sectors between its front and back, so sparse samples leave gaps
# that GTAO's running maximum fills. The sweep adds the exact cosine weights and thicknesses
# from a sheet to a height field.
ENTRY = MethodEntry(
    "bitmask",
    presets={
        "low": {"slices": 1, "steps": 4, "blur": True},
        "medium": {"slices": 2, "steps": 8, "blur": True},
        "high": {"slices": 3, "steps": 12, "blur": True},
        "ultra": {"slices": 4, "steps": 16, "blur": True},
    },
    sweep={"slices": [1, 2, 4], "steps": [4, 8, 16], "thickness": [0.1, 0.5, 1e30],
           "weighting": ["uniform", "cosine"], "blur": [False, True]},
    source="Blender 4.2 EEVEE horizon scan (2 slices, 8 steps per side) as medium; "
           "low/high/ultra ours",
    tune_bounds={
        "slices": int_bound(1, 32, "EEVEE marches 2 per pixel, the presets 1-4; 32 x 64 steps "
                            "is past the largest budget; log scale", log=True),
        "steps": int_bound(2, 64, "per side of a slice: EEVEE's 8, the presets 4-16; fewer leave "
                           "gaps between the samples' sectors; log scale", log=True),
        "sectors": choice_bound((8, 16, 32, 64), "N: the paper's 32 (one uint), halved, quartered "
                                "and doubled; the cost hardly depends on it"),
        "mip_distance": MIP_DISTANCE_BOUND,
        "thickness": float_bound(0.01, 100.0, "fraction of R: from a sheet to a height field "
                                 "(beyond 100 R nothing changes on the study's scenes); log scale",
                                 log=True),
    },
    samples_per_pixel=lambda s: s["slices"] * 2 * s["steps"],
)
