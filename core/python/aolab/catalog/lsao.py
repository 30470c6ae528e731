"""Line-sweep AO: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MethodEntry, float_bound, int_bound


def _lsao_directions(point: dict) -> dict:
    """LSAO's K must be 8 x template size (§5.2 aligned directions); template size 0 (uniform
    directions) leaves K free."""
    point = dict(point)
    if point["template_size"] > 0:
        point["directions"] = 8 * point["template_size"]
    return point


# Line-sweep AO — Timonen 2013. The paper's own configurations (docs/methods/lsao.md,
# Settings): Figure 1, K = 8 (n = 1, stride 2, D_L = 2.12) = low; Figure 13, K = 16 with
# stride 2 and D_L = 2.46 = medium's cheaper sibling, not a preset; Figure 11 and Table 2,
# K = 16 (n = 2, D_S = 2.43, D_L = 1.64) = medium, the library default. high (n = 3, K = 24,
# D_L = 1.2) and ultra (n = 4, K = 32, D_L = 1) are ours: denser in both directions and
# lines. The gather already averages K directions; no blur.
ENTRY = MethodEntry(
    "lsao",
    presets={
        "low": {"template_size": 1, "directions": 8, "template_stride": 2, "line_spacing": 2.12},
        "medium": {"template_size": 2, "directions": 16, "template_stride": 1,
                   "line_spacing": 1.64},
        "high": {"template_size": 3, "directions": 24, "template_stride": 1,
                 "line_spacing": 1.2},
        "ultra": {"template_size": 4, "directions": 32, "template_stride": 1,
                  "line_spacing": 1.0},
    },
    sweep={"template_size": [1, 2, 3, 4], "template_stride": [1, 2],
           "line_spacing": [1.0, 1.64, 2.46], "falloff": ["rational", "cutoff"]},
    source="Timonen 2013, Figure 1 (low), Figure 11 / Table 2 (medium); high, ultra ours",
    constraints=(_lsao_directions,),
    tune_bounds={
        "template_size": int_bound(0, 8, "n: 0 = uniform directions; up to the method's most "
                                   "(8, K = 64); K = 8n is set from it (the entry's constraint)"),
        "directions": int_bound(4, 64, "K of uniform directions (template size 0 only): the span "
                                "of the aligned sets, up to the method's most; log scale", log=True,
                                when=lambda v: v["template_size"] == 0),
        "step": float_bound(1.0, 4.0, "D_S of uniform directions in px (template size 0 only): "
                            "the paper's 2.43 inside; log scale", log=True,
                            when=lambda v: v["template_size"] == 0),
        "template_stride": int_bound(1, 3, "m (aligned sets only): the paper uses 1 and 2",
                                     when=lambda v: v["template_size"] > 0),
        "line_spacing": float_bound(1.0, 4.0, "D_L in px: the paper's 1.64-2.46 inside; wider "
                                    "lines miss thin geometry; log scale", log=True),
        "tangent_sin": float_bound(-1.0, 0.0, "sin t of the fixed tangent, its whole range",
                                   when=lambda v: v["tangent_strategy"] != "real"),
        "gather_depth_tolerance": float_bound(0.01, 1.0, "relative: 0.1 the default, 1 = any "
                                              "depth counts; log scale", log=True),
        "hull_search": int_bound(0, 32, "stack entries: 16 removes the thin-geometry misses for "
                                 "~1.8x the time (docs/methods/lsao.md); 32 is twice that"),
    },
)
