"""Pyramid HBAO: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MethodEntry, int_bound


# Pyramid HBAO — Astapov, Gaevoy, Sergeev 2021. §4 uses D = 8 directions and K = 3; Table 1
# (S and L per radius) did not survive the text extraction (docs/methods/pyramid_hbao.md),
# so S = 2/4/8 per level are ours (S = 4 is the library default). L = 0 derives the levels
# from R as §4 does. §3.5's Gaussian (sigma 1.5, 5 taps) is part of the method; the paper
# times the method without it, and so does the study (builtin switch off, shared blur on).
ENTRY = MethodEntry(
    "pyramid_hbao",
    presets={
        "low": {"directions": 4, "samples": 2, "blur": True},
        "medium": {"directions": 8, "samples": 4, "blur": True},
        "high": {"directions": 8, "samples": 8, "blur": True},
        "ultra": {"directions": 16, "samples": 8, "blur": True},
    },
    sweep={"directions": [4, 8, 16], "samples": [2, 4, 8], "reduction": [2, 3, 4],
           "attenuation": ["linear", "none"], "blur": [True]},
    source="Astapov et al. 2021, §4 (D = 8, K = 3); S per level ours (Table 1 lost)",
    builtin_blur="gaussian_filter",
    tune_bounds={
        "directions": int_bound(2, 64, "D: the paper's 8, up to the method's most (64); log "
                                "scale", log=True),
        "samples": int_bound(1, 64, "S per level: presets 2-8 (Table 1 lost), up to the "
                             "method's most; log scale", log=True),
        "levels": int_bound(0, 8, "L: 0 = from R (the paper); 8 levels of K >= 2 cover 256x "
                            "the pixel, beyond any R on screen"),
        "reduction": int_bound(2, 6, "K: the paper's 3, the sweep's 2-4; above 6 a level skips "
                               "most of the depth buffer"),
    },
)
