"""Chebyshev AO: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MethodEntry, float_bound, int_bound


def _chebyshev_window(point: dict) -> dict | None:
    """Each window mode reads one of the two window settings: sweep that one, keep the other
    at its default (8, 64) so that no configuration is run twice under two names."""
    if point["kernel_mode"] == "adaptive" and point["kernel_radius"] != 8:
        return None
    if point["kernel_mode"] == "fixed" and point["max_kernel_radius"] != 64:
        return None
    return point


# Chebyshev AO — Chan & Im 2021. The paper sizes its window from the radius (k ∝ 1/d, §III,
# our depth-adaptive mode) and gives no quality levels; the cost is the window, so the
# presets cap the adaptive half-width at 16/32/64/128 px (64, the library default, = high).
# The sweep adds the fixed pixel windows and eq. 2 against eq. 3. No blur: the window
# average is already smooth.
ENTRY = MethodEntry(
    "chebyshev",
    presets={
        "low": {"kernel_mode": "adaptive", "max_kernel_radius": 16},
        "medium": {"kernel_mode": "adaptive", "max_kernel_radius": 32},
        "high": {"kernel_mode": "adaptive", "max_kernel_radius": 64},
        "ultra": {"kernel_mode": "adaptive", "max_kernel_radius": 128},
    },
    sweep={"kernel_mode": ["fixed", "adaptive"], "kernel_radius": [4, 8, 16, 32],
           "max_kernel_radius": [16, 32, 64, 128], "ignore_unoccluded": [True, False]},
    source="Chan & Im 2021, §III (depth-adaptive window); window caps ours",
    constraints=(_chebyshev_window,),
    tune_bounds={
        "kernel_radius": int_bound(1, 128, "fixed window half-width px (fixed mode only); log "
                                   "scale", log=True, when=lambda v: v["kernel_mode"] == "fixed"),
        "max_kernel_radius": int_bound(4, 256, "adaptive cap px (adaptive mode only): presets "
                                       "16-128; log scale", log=True,
                                       when=lambda v: v["kernel_mode"] == "adaptive"),
        "variance_bias": float_bound(1e-6, 1e-1, "b: the default 1e-4 two decades inside either "
                                     "way; log scale", log=True),
    },
)
