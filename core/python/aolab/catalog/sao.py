"""SAO: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MethodEntry, float_bound, int_bound, setting_on


# SAO — McGuire, Mara, Luebke 2012: the tap count s again, with the z pyramid and the
# method's own depth-aware filter (`filter`, on in every preset: it is part of the method,
# unlike the shared Gaussian). Its reference implementation ships 9 taps (the default,
# medium) and later 11 and 19-20; low takes 4 as the cheapest spiral the table tunes.
ENTRY = MethodEntry(
    "sao",
    presets={
        "low": {"samples": 4},
        "medium": {"samples": 9},
        "high": {"samples": 11},
        "ultra": {"samples": 20},
    },
    sweep={"samples": [4, 9, 11, 20, 40], "falloff": ["alchemy", "smooth"],
           "filter": [False, True]},
    source="SAO reference implementation (9, 11, 19-20 taps); low ours",
    tune_bounds={
        "samples": int_bound(2, 98, "s: the reference's 9-20 inside, up to the method's most "
                             "(98); log scale", log=True),
        "intensity": float_bound(0.1, 10.0, "sigma in units of r: the default 1 a decade inside "
                                 "either way; log scale", log=True),
        "contrast": float_bound(0.5, 4.0, "k: 1 the paper's; log scale", log=True),
        "bias": float_bound(1e-4, 0.2, "beta in units of r: the reference's 0.03 inside; log "
                            "scale", log=True),
        "epsilon": float_bound(1e-4, 0.5, "in units of r^2: the reference's 0.01 inside; log "
                               "scale", log=True),
        "log_max_offset": int_bound(0, 6, "q': the reference's 3; its note: below 3 taps share "
                                    "texels, above 5 the levels go unused"),
        "max_mip_level": int_bound(0, 8, "L_max: the reference's 5; 8 levels reach 256 px"),
        "filter_radius": int_bound(1, 8, "taps per side (filter on only): the reference's 4 "
                                   "inside", when=setting_on("filter")),
        "filter_stride": int_bound(1, 4, "px between taps (filter on only): the reference's 2",
                                   when=setting_on("filter")),
        "filter_sigma": float_bound(0.5, 8.0, "taps (filter on only): the reference's 3 inside; "
                                    "log scale", log=True, when=setting_on("filter")),
        "edge_sharpness": float_bound(0.1, 10.0, "(filter on only) the reference's 1 a decade "
                                      "inside either way; log scale", log=True,
                                      when=setting_on("filter")),
    },
    tune_fixed={
        "turns": (None, "0 = the paper's low-discrepancy tau for s; other turns only line "
                  "the taps up"),
    },
    samples_per_pixel=lambda s: s.get("samples"),
)
