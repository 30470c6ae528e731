"""Quality presets and parameter sweeps of each method, for ``aolab compare``.

A method's entry names its presets (``low`` < ``medium`` < ``high`` < ``ultra``: more
samples, more time) and the grid of its quality parameters that the full sweep covers.
The radius is never set here: every method runs with the scene's R (the reference's AO
distance). Settings not named keep the method's defaults (``aolab.method_info``). A choice
setting is given by name (``"kernel_mode": "adaptive"``), as results.csv records it.

``blur`` is not a method setting: it asks for the shared separable Gaussian
(``aolab.gaussian_blur``, sigma 1.5 px, 5 taps: Pyramid HBAO §3.5) after the method, timed
apart from it, as the papers time their filters apart. A method whose own output already
includes that filter names the switch in ``builtin_blur``; the study turns the switch off
and applies the shared blur instead (Pyramid HBAO's ``gaussian_filter`` is that same
Gaussian, bit for bit: docs/methods/pyramid_hbao.md).

Adding a method takes a few lines::

    register("chebyshev",
             presets={"low": {...}, "medium": {...}, "high": {...}},
             sweep={"some_setting": [1, 2, 4], "blur": [False, True]},
             source="Author et al. year, Table 2")

A method from ``aolab.methods()`` with no entry runs once, at its defaults ("default").

The named presets of ``aolab.presets(method)`` (this module answers the call) are "default"
(the method's own defaults), these presets, and the tuned ones that ``aolab tune`` writes to
tuned_presets.json ("tuned-100ms": the best configuration found within 100 ms a frame;
docs/tuning.md); ``aolab.compute(..., preset=NAME)`` applies one.
"""

from __future__ import annotations

import itertools
import json
import os
import sys
import types
from dataclasses import dataclass, field
from pathlib import Path

from .util import files

#: Preset names, cheapest first. ``--sweep quick`` (the default study) runs the first two
#: beside the method's defaults and its tuned presets; ``high`` and ``ultra`` (the costly
#: ones: HBAO's high alone took a fifth of the study) are in ``--sweep presets``, so that
#: the default study stays within about five minutes on 2 cores.
PRESET_ORDER = ("low", "medium", "high", "ultra")
QUICK_PRESETS = ("low", "medium")
#: The configuration of a method without presets, and the add-on's menu entry for a method's
#: own defaults.
DEFAULT_PRESET = "default"

#: The shared blur's parameters (Pyramid HBAO §3.5; core/filters/blur.h defaults).
BLUR_SIGMA = 1.5
BLUR_TAPS = 5


@dataclass(frozen=True)
class MethodPresets:
    """Presets and full-sweep grid of one method."""
    presets: dict                 # name -> settings dict (may contain "blur")
    sweep: dict                   # setting -> list of values; the grid is their product
    source: str = ""              # where the values come from (paper, table, our choice)
    builtin_blur: str | None = None   # the method's own switch for the shared Gaussian
    constraints: tuple = field(default_factory=tuple)  # callables: settings -> settings|None


_REGISTRY: dict[str, MethodPresets] = {}


def register(method: str, *, presets: dict, sweep: dict, source: str = "",
             builtin_blur: str | None = None, constraints=()) -> None:
    """Declares the presets and sweep grid of ``method`` (see the module docstring)."""
    unknown = set(presets) - set(PRESET_ORDER)
    if unknown:
        raise ValueError(f"presets of {method} must be named from {PRESET_ORDER}, "
                         f"got {sorted(unknown)}")
    _REGISTRY[method] = MethodPresets(dict(presets), dict(sweep), source, builtin_blur,
                                      tuple(constraints))


def entry(method: str) -> MethodPresets | None:
    """The registered presets of ``method``, or None."""
    return _REGISTRY.get(method)


@dataclass(frozen=True)
class Setting:
    """One configuration of one method that the study runs."""
    method: str
    label: str          # preset name, or "k=v,k=v" for a sweep point
    settings: dict      # the method's own settings (no radius, no blur)
    blur: bool          # the shared Gaussian after the method, timed apart
    preset: str | None  # preset name when this is a preset

    def compute_settings(self) -> dict:
        """The keyword settings passed to ``aolab.compute`` (radius excepted)."""
        out = dict(self.settings)
        e = entry(self.method)
        if e is not None and e.builtin_blur is not None:
            out[e.builtin_blur] = False
        return out

    def recorded_settings(self) -> dict:
        """Every setting as recorded in results: the method's, the blur, and the builtin
        switch forced off when the shared blur replaces it."""
        out = self.compute_settings()
        out["blur"] = self.blur
        if self.blur:
            out["blur_sigma"] = BLUR_SIGMA
            out["blur_taps"] = BLUR_TAPS
        return out


def _split(method: str, values: dict) -> tuple[dict, bool]:
    values = dict(values)
    blur = bool(values.pop("blur", False))
    return values, blur


def preset_names(method: str) -> list[str]:
    """The method's presets, cheapest first (empty for a method without an entry)."""
    e = entry(method)
    return [] if e is None else [p for p in PRESET_ORDER if p in e.presets]


def preset_values(method: str, name: str) -> tuple[dict, bool]:
    """(the method's settings, shared blur on/off) of preset ``name`` as the study runs it:
    the method's builtin blur switch off where the shared blur replaces it; a tuned preset as
    tuned; DEFAULT_PRESET as every setting's default. The name is checked as
    ``aolab.compute(preset=...)`` checks it (:func:`settings_of`)."""
    values = settings_of(method, name)
    blur = bool(values.pop("blur", False))
    return values, blur


def _identity(method: str, values: dict, blur: bool) -> tuple:
    """What a configuration computes: its settings over the method's defaults (floats at the
    float32 precision the methods store them in), and the blur. Two configurations with the
    same identity are one, whether or not they name a default explicitly."""
    import numpy as np

    import aolab

    from .settings import described
    full = {}
    if method in aolab.methods():
        full = {s["name"]: s["default"] for s in described(method)}
    full.update(values)
    norm = {k: (float(np.float32(v)) if isinstance(v, float) else v) for k, v in full.items()}
    return tuple(sorted(norm.items())), blur


def _label(values: dict) -> str:
    return ",".join(f"{k}={int(v) if isinstance(v, bool) else v}" for k, v in values.items())


def settings_for(method: str, sweep: str = "quick") -> list[Setting]:
    """The configurations of ``method`` for a sweep: ``quick`` = the method's own defaults
    (DEFAULT_PRESET: the paper's), the presets low and medium and the tuned presets;
    ``presets`` = the defaults and every preset, tuned ones included; ``full`` = those and
    every point of the grid. A named configuration keeps its name even when it computes the
    same as another (the study runs the method once for both: compare._method_runs); grid
    points equal to a named one are left out."""
    if sweep not in ("quick", "presets", "full"):
        raise ValueError(f"sweep must be quick, presets or full, got {sweep!r}")
    e = entry(method)
    # A method whose own filter is the shared blur runs it as the shared blur, timed apart.
    default_blur = e is not None and e.builtin_blur is not None
    out = [Setting(method, DEFAULT_PRESET, {}, default_blur, DEFAULT_PRESET)]
    seen = {_identity(method, {}, default_blur)}
    if e is None:
        return out
    names = [p for p in PRESET_ORDER if p in e.presets and (sweep != "quick" or p in QUICK_PRESETS)]
    for name in names:
        values, blur = _split(method, e.presets[name])
        seen.add(_identity(method, values, blur))
        out.append(Setting(method, name, values, blur, name))
    for name, values in tuned_presets(method).items():
        values, blur = _split(method, values)
        seen.add(_identity(method, values, blur))
        out.append(Setting(method, name, values, blur, name))
    if sweep == "full" and e.sweep:
        keys = list(e.sweep)
        for combo in itertools.product(*(e.sweep[k] for k in keys)):
            point = dict(zip(keys, combo))
            for rule in e.constraints:
                point = rule(point)
                if point is None:
                    break
            if point is None:
                continue
            values, blur = _split(method, point)
            key = _identity(method, values, blur)
            if key in seen:
                continue
            seen.add(key)
            out.append(Setting(method, _label(point), values, blur, None))
    return out


# ---------------------------------------------------------------------------------------
# Named presets: the method's defaults, the study's presets and the tuned ones


#: Names of the tuned presets: TUNED_PREFIX + the time budget, e.g. "tuned-100ms".
TUNED_PREFIX = "tuned-"
#: The committed tuned presets (written by ``aolab tune``, docs/tuning.md), copied beside this
#: module by the build; $AOLAB_TUNED_PRESETS names another file.
TUNED_FILE = "tuned_presets.json"
#: The environment variable that names another tuned-presets file.
TUNED_ENV = "AOLAB_TUNED_PRESETS"
_tuned_cache: dict = {}


def tuned_file() -> Path:
    """The JSON file the tuned presets are read from."""
    return Path(os.environ.get(TUNED_ENV) or Path(__file__).with_name(TUNED_FILE))


def tuned_presets(method: str) -> dict:
    """The tuned presets of ``method`` from :func:`tuned_file`, cheapest budget first
    (name -> settings, "blur" included); {} when the file or the method's entry is absent.
    A file that is not what ``aolab tune`` writes is one ValueError naming the file and what
    is wrong with it (:func:`read_tuned`)."""
    path = tuned_file()
    try:
        stamp = path.stat().st_mtime_ns
    except FileNotFoundError:
        return {}
    except OSError as e:   # a part of the path is a file, a folder we may not enter, ...
        raise ValueError(f"tuned presets file {path}: cannot be read ({e.strerror}); fix or "
                         f"unset ${TUNED_ENV}") from None
    if _tuned_cache.get("key") != (str(path), stamp):
        _tuned_cache.clear()
        _tuned_cache.update(key=(str(path), stamp), data=read_tuned(path))
    found = _tuned_cache["data"].get(method, {})
    return {n: dict(found[n]) for n in sorted(found, key=budget_of)}


#: The JSON values a setting may have in a tuned preset (a choice setting is a name).
_SETTING_TYPES = (bool, int, float, str)


def read_tuned(path: Path) -> dict:
    """The tuned presets of the file at ``path`` as {method: {name: settings}}, after
    checking that it has the form ``aolab tune`` writes: {"methods": {METHOD: {"presets":
    {"tuned-<ms>ms": {SETTING: value, ...}}}}}. Anything else is one ValueError naming the
    file and the first thing wrong, instead of a Python error from deep inside a lookup
    ("'list' object has no attribute 'get'") that names no file."""
    where = f"tuned presets file {path}"
    try:
        data = json.loads(files.read_text(path, "tuned presets"))
    except json.JSONDecodeError as e:
        raise ValueError(f"{where} is unreadable: not JSON ({e})") from None
    except OSError as e:
        raise ValueError(f"{where}: cannot be read ({e.strerror or e})") from None
    # read_text's own ValueErrors (a folder, a FIFO, not UTF-8) name the file already.

    def need_object(value, what: str) -> dict:
        if not isinstance(value, dict):
            raise ValueError(f"{where}: {what} must be a JSON object, got {_json_kind(value)}")
        return value

    import aolab

    from .settings import described
    methods = need_object(need_object(data, "the file").get("methods", {}), '"methods"')
    out = {}
    for method, entry_ in methods.items():
        found = need_object(need_object(entry_, f"the entry of {method!r}").get("presets", {}),
                            f'"presets" of {method!r}')
        # A method this build lacks is kept unchecked (a file from a newer build); a known
        # one's settings are checked here, where the message can name the file.
        known = ({s["name"] for s in described(method)} | {"blur"}
                 if method in aolab.methods() else None)
        out[method] = {}
        for name, values in found.items():
            if _budget(name) is None:
                raise ValueError(f"{where}: preset name {name!r} of {method!r} must be "
                                 f"{TUNED_PREFIX}<ms>ms with a time budget > 0, e.g. "
                                 f"{TUNED_PREFIX}100ms")
            need_object(values, f"preset {name!r} of {method!r}")
            for key, value in values.items():
                if known is not None and key not in known:
                    raise ValueError(f"{where}: preset {name!r} of {method!r} sets {key!r}, "
                                     f"which is not a setting of {method} (settings: "
                                     f"{', '.join(sorted(known))})")
                blur = key == "blur"
                if not isinstance(value, bool if blur else _SETTING_TYPES):
                    need = "true or false" if blur else "a number, true, false or a name"
                    raise ValueError(f"{where}: setting {key!r} of preset {name!r} of "
                                     f"{method!r} must be {need}, got {_json_kind(value)}")
            out[method][name] = values
    return out


def _json_kind(value) -> str:
    """What a JSON value is, for a message: its kind and its (shortened) text."""
    kind = {dict: "an object", list: "a list", str: "a string", bool: "a boolean",
            type(None): "null"}.get(type(value), "a number")
    text = json.dumps(value)
    return f"{kind}, {text if len(text) <= 40 else text[:37] + '...'}"


def _budget(name) -> float | None:
    """The budget in ms of a tuned preset's name ("tuned-100ms" -> 100), None when ``name``
    is not such a name."""
    if not (isinstance(name, str) and name.startswith(TUNED_PREFIX) and name.endswith("ms")):
        return None
    try:
        ms = float(name[len(TUNED_PREFIX):-2])
    except ValueError:
        return None
    return ms if 0 < ms < float("inf") else None


def budget_of(name: str) -> float:
    """The time budget in ms of a tuned preset's name: "tuned-100ms" -> 100; a ValueError
    naming it when it is not one."""
    ms = _budget(name)
    if ms is None:
        raise ValueError(f"a tuned preset's name must be {TUNED_PREFIX}<ms>ms, got {name!r}")
    return ms


def names(method: str) -> list[str]:
    """Every named preset of ``method``: DEFAULT_PRESET (the method's own defaults), the
    study's presets cheapest first, then the tuned ones cheapest first (a bad tuned-presets
    file: its ValueError)."""
    return [DEFAULT_PRESET] + preset_names(method) + list(tuned_presets(method))


def named(method: str) -> dict:
    """Every named preset of ``method`` as name -> settings, each with its "blur" switch:
    DEFAULT_PRESET = every setting's default (``aolab.method_info``, R excepted); the study's
    presets as the study runs them (a builtin blur switch off where the shared blur replaces
    it); the tuned presets as ``aolab tune`` chose them."""
    out = {name: _builtin(method, name) for name in [DEFAULT_PRESET] + preset_names(method)}
    out.update(tuned_presets(method))
    return out


def _builtin(method: str, name: str) -> dict:
    """DEFAULT_PRESET or one of the study's presets (``name`` known to be one), "blur"
    included."""
    if name == DEFAULT_PRESET:
        from .settings import described
        return {**{s["name"]: s["default"] for s in described(method)}, "blur": False}
    values, blur = _split(method, entry(method).presets[name])
    return {**Setting(method, name, values, blur, name).compute_settings(), "blur": blur}


def presets_of(method: str) -> dict:
    """``aolab.presets(method)``: :func:`named`, after checking that ``method`` exists."""
    _check_method(method)
    return named(method)


def _check_method(method: str) -> None:
    import aolab
    if method not in aolab.methods():
        raise ValueError(f"method {method!r} is not one of {aolab.methods()}")


def settings_of(method: str, name: str) -> dict:
    """The settings of preset ``name`` ("blur" included). The one check of a preset name:
    ``aolab.compute(preset=...)``, every command's --preset and the add-on's preset menu go
    through it. A name matches exactly (``Medium`` is not ``medium``); an unknown one is a
    ValueError listing the method's presets.

    The built-in presets (DEFAULT_PRESET and the study's) never read the tuned-presets file,
    so a bad file does not take them away; a tuned or unknown name, and the listings
    (:func:`names`, :func:`named`), report a bad file (:func:`tuned_presets`)."""
    _check_method(method)
    if isinstance(name, str) and (name == DEFAULT_PRESET or name in preset_names(method)):
        return _builtin(method, name)
    builtin = [DEFAULT_PRESET] + preset_names(method)
    try:
        tuned = tuned_presets(method)
    except ValueError as e:
        if isinstance(name, str) and name.startswith(TUNED_PREFIX):
            raise
        # A mistyped built-in name is the user's first problem: say it, and the file's too.
        raise ValueError(f"preset {name!r} of {method} is not one of {builtin} (the tuned "
                         f"presets are left out: {e})") from None
    if name in tuned:
        return dict(tuned[name])
    raise ValueError(f"preset {name!r} of {method} is not one of {builtin + list(tuned)}")


class _CallableModule(types.ModuleType):
    """This module is also the function ``aolab.presets(method)`` (the package attribute and
    the submodule share the name, so the submodule answers the call)."""

    def __call__(self, method: str) -> dict:
        return presets_of(method)


sys.modules[__name__].__class__ = _CallableModule


# ---------------------------------------------------------------------------------------
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


register(
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
)

# Pyramid HBAO — Astapov, Gaevoy, Sergeev 2021. §4 uses D = 8 directions and K = 3; Table 1
# (S and L per radius) did not survive the text extraction (docs/methods/pyramid_hbao.md),
# so S = 2/4/8 per level are ours (S = 4 is the library default). L = 0 derives the levels
# from R as §4 does. §3.5's Gaussian (sigma 1.5, 5 taps) is part of the method; the paper
# times the method without it, and so does the study (builtin switch off, shared blur on).
register(
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
)


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
register(
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
)


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
register(
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
)

# VAO — Szirmay-Kalos et al. 2010 as outlined in VAO++ §3: its one quality parameter is the
# number of disc samples; VAO++ Table 1 measures 2–32, so low/medium/high/ultra = 4/8/16/32.
# The per-pixel rotation leaves noise, which the shared Gaussian smooths (timed apart).
register(
    "vao",
    presets={
        "low": {"samples": 4, "blur": True},
        "medium": {"samples": 8, "blur": True},
        "high": {"samples": 16, "blur": True},
        "ultra": {"samples": 32, "blur": True},
    },
    sweep={"samples": [2, 4, 8, 16, 32], "blur": [False, True]},
    source="VAO++ §3 and Table 1 (2–32 samples)",
)

# VAO++ — Bokšanský et al. 2017: the same sample counts with its extensions on (the
# library defaults: adaptive sampling, careful culling, range check, Poisson sets, its own
# cross-bilateral filter). The full sweep switches each speed extension and the range check,
# as Table 1 does. Colour bleeding (an RGB result, not scored) stays off.
register(
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
)

# GTAO — Jimenez et al. 2016. The memo spreads one slice per pixel and frame over a 4x4
# spatial and a 6-frame temporal filter and gives no quality table; XeGTAO, the reference
# implementation, names four levels: slices 1/2/3/9 with 2/2/3/3 steps per side (its
# QualityLevel, default "High"), which are the presets. Its own denoiser stands in for the
# memo's filters; here the shared Gaussian does (timed apart). The full sweep adds denser
# slices and steps, XeGTAO's tuned falloff (0.615 of R) against the memo's hard cut, and the
# blur on and off.
register(
    "gtao",
    presets={
        "low": {"slices": 1, "steps": 2, "blur": True},
        "medium": {"slices": 2, "steps": 2, "blur": True},
        "high": {"slices": 3, "steps": 3, "blur": True},
        "ultra": {"slices": 9, "steps": 3, "blur": True},
    },
    sweep={"slices": [1, 2, 3, 9, 16], "steps": [2, 3, 8], "falloff": [0.0, 0.615],
           "blur": [False, True]},
    source="XeGTAO quality levels (slices 1/2/3/9, steps 2/2/3/3); sweep ours",
)

# Visibility bitmask — Therrien, Levesque, Gilet 2023. The paper fixes 32 sectors and a
# constant thickness but no quality levels. Blender 4.2's EEVEE, which implements it, marches
# 2 slices per pixel with 8 steps per side by default (slice_len, fast_gi_step_count): that is
# `medium` (and the method's defaults); low halves the steps and takes one slice, high and
# ultra add a slice and 4 steps each. XeGTAO's 2-3 steps per side are too few here: a
# sample marks only the sectors between its front and back, so sparse samples leave gaps
# that GTAO's running maximum fills. The sweep adds the exact cosine weights and thicknesses
# from a sheet to a height field.
register(
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
)

# Alchemy AO — McGuire et al. 2011: its quality parameter is the tap count s. The paper's
# Figure 1 runs 12 taps at 1280x720 (the high preset, the method's default); the other
# levels halve and double around it as the paper's scalability goal (fewer taps on weaker
# hardware) describes, without a table of its own. The per-pixel rotation leaves noise that
# the paper's edge-aware filter removes; here the shared Gaussian does (timed apart).
register(
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
)

# SAO — McGuire, Mara, Luebke 2012: the tap count s again, with the z pyramid and the
# method's own depth-aware filter (`filter`, on in every preset: it is part of the method,
# unlike the shared Gaussian). Its reference implementation ships 9 taps (the default,
# medium) and later 11 and 19-20; low takes 4 as the cheapest spiral the table tunes.
register(
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
)

# Crytek SSAO — Mittring 2007, §8.5.4.3: CryEngine 2 took 8 to 16 points per pixel and
# blurred away the 4x4 pattern of its reflection texture; low/medium = 8/16, high and ultra
# double them. The shared Gaussian stands in for the engine's blur (timed apart). The sweep
# adds the distributions, the range checks and the hemisphere variant.
register(
    "crytek_ssao",
    presets={
        "low": {"samples": 8, "blur": True},
        "medium": {"samples": 16, "blur": True},
        "high": {"samples": 32, "blur": True},
        "ultra": {"samples": 64, "blur": True},
    },
    sweep={"samples": [8, 16, 32, 64], "distribution": ["centre", "uniform"],
           "range_check": ["smooth", "hard", "off"], "hemisphere": [False, True],
           "blur": [False, True]},
    source="Mittring 2007, §8.5.4.3 (8-16 points, a blur); high/ultra ours",
)
