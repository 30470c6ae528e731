"""VAO++: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MethodEntry, choice_bound, float_bound, int_bound, setting_on


# VAO++ — Bokšanský et al. 2017: the same sample counts with its extensions on (the
# library defaults: adaptive sampling, careful culling, range check, Poisson sets, its own
# cross-bilateral filter). The full sweep switches each speed extension and the range check,
# as Table 1 does. Colour bleeding (an RGB result, not scored) stays off.
ENTRY = MethodEntry(
    "vao_pp",
    presets={
        "low": {"samples": 4},
        "medium": {"samples": 8},
        "high": {"samples": 16},
        "ultra": {"samples": 32},
    },
    sweep={"samples": [2, 4, 8, 16, 32], "adaptive_sampling": [False, True],
           "culling": ["off", "careful"], "range_check": [False, True]},
    source="Bokšanský et al. 2017, Table 1 (2–32 samples; adaptive sampling, culling)",
    tune_bounds={
        "samples": choice_bound((2, 4, 8, 16, 32), "a power of two from 2 to 32, as the method "
                                "requires"),
        "adaptive_min_diameter": float_bound(1e-3, 0.1, "image heights (adaptive sampling only): "
                                             "the default 0.01 a decade inside; log scale",
                                             log=True, when=setting_on("adaptive_sampling")),
        "cull_threshold": float_bound(0.9, 1.0, "(culling on only) the default 0.998; below 0.9 "
                                      "most occluded pixels are culled",
                                      when=lambda v: v["culling"] != "off"),
        "filter_taps": int_bound(1, 15, "odd, as the method requires (filter on only); 15 taps "
                                 "span +-7 px, past 2 sigma of the largest useful sigma", step=2,
                                 when=setting_on("filter")),
        "filter_sigma": float_bound(0.5, 16.0, "px (filter on only): the default 4 inside; log "
                                    "scale", log=True, when=setting_on("filter")),
    },
    tune_fixed={
        "color_bleeding": (None, "an RGB result, which cannot be scored against grey AO"),
        "bleeding_sample_step": (None, "applies to colour bleeding only"),
        "luminance_sensitivity": (None, "an artistic effect (AO suppressed on bright "
                                  "surfaces) that the reference's AO does not have"),
        "luminance_threshold": (None, "applies with luminance_sensitivity only"),
        "luminance_width": (None, "applies with luminance_sensitivity only"),
        "luminance_sigma": (None, "applies with luminance_sensitivity only"),
        "luminance_mode": (None, "applies with luminance_sensitivity only"),
    },
    samples_per_pixel=lambda s: s.get("samples"),
)
