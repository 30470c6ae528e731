"""HBAO: what the study knows of it (aolab.catalog): its presets and
full-sweep grid, the bounds aolab tune searches its settings in, and the samples per pixel
its settings fix."""

from __future__ import annotations

from .kinds import MIP_DISTANCE_BOUND, MethodEntry, choice_bound, int_bound


# HBAO — Bavoil, Sainz, Dimitrov 2008. The talk's Figure 1 uses N_d = 8 directions and
# N_s = 8 steps (docs/methods/hbao.md, Settings); it has no table of quality levels, so low,
# high and ultra halve and double both counts (our choice). Its per-pixel random rotation and
# jitter trade banding for noise, which the talk leaves to a blur it does not specify: the
# presets apply the shared Gaussian (timed apart). The full sweep crosses the counts with both
# forms of the attenuation (eq. 3, the talk's; eq. 2, NVIDIA's incremental form), since the
# choice moves the error more than the sample counts do (docs/methods/hbao.md, step 10b), and
# with the reference's definitions (no attenuation, the cosine-weighted integral), blurred.
def _hbao_attenuation(point: dict) -> dict | None:
    """Without attenuation its two forms compute the same: keep one."""
    if point.get("attenuation") == "none" and point.get("incremental_attenuation"):
        return None
    return point


ENTRY = MethodEntry(
    "hbao",
    presets={
        "low": {"directions": 4, "steps": 4, "blur": True},
        "medium": {"directions": 8, "steps": 8, "blur": True},
        "high": {"directions": 16, "steps": 16, "blur": True},
        "ultra": {"directions": 32, "steps": 32, "blur": True},
    },
    sweep={"directions": [4, 8, 16, 32], "steps": [4, 8, 16, 32],
           "incremental_attenuation": [False, True], "attenuation": ["linear", "none"],
           "integral": ["uniform", "cosine"], "blur": [True]},
    source="Bavoil et al. 2008, Figure 1 (N_d = N_s = 8); other levels halve/double (ours)",
    constraints=(_hbao_attenuation,),
    tune_bounds={
        "directions": int_bound(2, 64, "N_d: up to the method's most (64); with many steps "
                                "far past the largest budget; log scale", log=True),
        "steps": int_bound(2, 64, "N_s: the same span as N_d; log scale", log=True),
        "mip_distance": MIP_DISTANCE_BOUND,
        "incremental_attenuation": choice_bound(
            (False, True), "eq. 2 or eq. 3: only with the linear attenuation (without any, both "
            "compute the same)", when=lambda v: v["attenuation"] == "linear"),
    },
    samples_per_pixel=lambda s: s["directions"] * s["steps"],
)
