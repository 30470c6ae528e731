"""The form of a method's entry in the catalog (``MethodEntry``) and of the bounds aolab tune
searches a setting in (``Param`` and its constructors). Nothing here imports the rest of
``aolab``: the catalog sits below the API, which reads it for ``aolab.presets``."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

#: Preset names, cheapest first (docs/comparison.md, "Presets").
PRESET_ORDER = ("low", "medium", "high", "ultra")


@dataclass(frozen=True)
class Param:
    """One searched setting: an int or float range (log-uniform where it spans decades) or a
    set of values; ``when`` (settings -> bool) makes it conditional on settings searched
    before it (it is then absent, at its default, when false); ``why`` explains the bound."""
    name: str
    kind: str                         # "int", "float" or "set"
    low: float = 0.0
    high: float = 0.0
    log: bool = False
    step: int = 1
    choices: tuple = ()
    when: Callable | None = None
    why: str = ""


def int_bound(low, high, why, log=False, step=1, when=None) -> Param:
    """An integer setting searched in [low, high]."""
    return Param("", "int", low, high, log, step, (), when, why)


def float_bound(low, high, why, log=False, when=None) -> Param:
    """A float setting searched in [low, high]."""
    return Param("", "float", low, high, log, 1, (), when, why)


def choice_bound(choices, why, when=None) -> Param:
    """A setting searched over ``choices``."""
    return Param("", "set", choices=tuple(choices), when=when, why=why)


def setting_on(name: str) -> Callable:
    """A ``when`` for a setting that matters only while the switch ``name`` is on."""
    return lambda v: bool(v[name])


#: Bounds of settings every method that has them shares (the shared ``power`` post-step).
SHARED_BOUNDS = {
    "power": float_bound(0.25, 4.0, "AO^p after the method: 1/4 to 4 covers the exponents of "
                         "shipping SSAO (1 to 4) and their inverses; log scale", log=True),
}


#: q of the depth MIP chain (`mip_distance`), searched alike for the methods that have it
#: (HBAO and the visibility bitmask).
MIP_DISTANCE_BOUND = choice_bound(
    (0, 4, 8, 16, 32), "q, px; 0 = off, the paper's. SAO's q is 8 (LOG_MAX_OFFSET 3), "
    "XeGTAO's about 10 (DepthMIPSamplingOffset 3.3); halved and doubled. It changes the "
    "output, so the search weighs its time against its error")


@dataclass(frozen=True)
class MethodEntry:
    """All the study knows of one method.

    - ``presets``: name (from PRESET_ORDER) -> settings, "blur" the shared Gaussian's switch;
    - ``sweep``: setting -> values; the full sweep is their product, filtered by
      ``constraints`` (callables: a point -> the point to run, or None to leave it out);
    - ``source``: where the values come from (paper, table, our choice);
    - ``builtin_blur``: the method's own switch for the shared Gaussian, if it has one;
    - ``tune_bounds``: setting -> Param, where aolab tune searches it (the settings' own
      ranges are far wider; a setting in no table is searched over its own range when that
      range is small, else kept at its default);
    - ``tune_fixed``: setting -> (value, or None for its default; why it is not searched);
    - ``samples_per_pixel``: full settings -> depth reads per pixel they fix, for aolab
      bench-table's samples per second (None where the cost is not per pixel)."""
    method: str
    presets: dict
    sweep: dict
    source: str = ""
    builtin_blur: str | None = None
    constraints: tuple = field(default_factory=tuple)
    tune_bounds: dict = field(default_factory=dict)
    tune_fixed: dict = field(default_factory=dict)
    samples_per_pixel: Callable | None = None

    def __post_init__(self):
        unknown = set(self.presets) - set(PRESET_ORDER)
        if unknown:
            raise ValueError(f"presets of {self.method} must be named from {PRESET_ORDER}, "
                             f"got {sorted(unknown)}")
        object.__setattr__(self, "constraints", tuple(self.constraints))
