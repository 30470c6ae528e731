"""VAO: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MethodEntry, int_bound


# VAO — Szirmay-Kalos et al. 2010 as outlined in VAO++ §3: its one quality parameter is the
# number of disc samples; VAO++ Table 1 measures 2–32, so low/medium/high/ultra = 4/8/16/32.
# The per-pixel rotation leaves noise, which the shared Gaussian smooths (timed apart).
ENTRY = MethodEntry(
    "vao",
    presets={
        "low": {"samples": 4, "blur": True},
        "medium": {"samples": 8, "blur": True},
        "high": {"samples": 16, "blur": True},
        "ultra": {"samples": 32, "blur": True},
    },
    sweep={"samples": [2, 4, 8, 16, 32], "blur": [False, True]},
    source="VAO++ §3 and Table 1 (2–32 samples)",
    tune_bounds={
        "samples": int_bound(2, 64, "n: VAO++ Table 1 measures 2-32; 64, the method's most, "
                             "binds: its sample table ends there; log scale", log=True),
    },
    samples_per_pixel=lambda s: s.get("samples"),
)
