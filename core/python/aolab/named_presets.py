"""The named presets of each method and the configurations the study runs.

A method's named presets (``aolab.presets(method)``) are "default" (the method's own
defaults), the presets of its catalog entry (``low`` < ``medium`` < ``high`` < ``ultra``:
more samples, more time; aolab.catalog) and the tuned ones that ``aolab tune`` writes to
tuned_presets.json ("tuned-100ms": the best configuration found within 100 ms a frame;
docs/tuning.md); ``aolab.compute(..., preset=NAME)`` applies one. ``settings_for`` lists the
configurations of a sweep: the named presets and, for the full sweep, the points of the
entry's grid. The radius is never set here: every method runs with the scene's R. A choice
setting is given by name (``"kernel_mode": "adaptive"``), as results.csv records it.

``blur`` is not a method setting: it asks for the shared separable Gaussian
(``aolab.gaussian_blur``, sigma 1.5 px, 5 taps: Pyramid HBAO §3.5) after the method, timed
apart from it, as the papers time their filters apart. A method whose own output already
includes that filter names the switch in ``builtin_blur``; the study turns the switch off
and applies the shared blur instead (Pyramid HBAO's ``gaussian_filter`` is that same
Gaussian, bit for bit: docs/methods/pyramid_hbao.md).
"""

from __future__ import annotations

import itertools
import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import _core, catalog
from .catalog.kinds import PRESET_ORDER
from .settings import described
from .util import files
from .util import values as checked

#: Preset names, cheapest first (catalog/kinds.py). ``--sweep quick`` (the default study) runs
#: the first two beside the method's defaults and its tuned presets; ``high`` and ``ultra``
#: (the costly ones: HBAO's high alone took a fifth of the study) are in ``--sweep presets``,
#: so that the default study stays within about five minutes on 2 cores.
QUICK_PRESETS = ("low", "medium")
#: The configuration of a method without presets, and the add-on's menu entry for a method's
#: own defaults.
DEFAULT_PRESET = "default"

#: The shared blur's parameters (Pyramid HBAO §3.5; core/filters/blur.h defaults).
BLUR_SIGMA = 1.5
BLUR_TAPS = 5


def shared_blur(ao, gbuffer, threads: int = 0) -> np.ndarray:
    """``ao`` after the shared blur (BLUR_SIGMA, BLUR_TAPS), as the study and the tuner run
    and time it after a configuration with ``blur``."""
    return np.asarray(_core.gaussian_blur(ao, gbuffer, sigma=BLUR_SIGMA, taps=BLUR_TAPS,
                                          threads=checked.threads(threads)))


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
        e = catalog.entry(self.method)
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
    e = catalog.entry(method)
    return [] if e is None else [p for p in PRESET_ORDER if p in e.presets]


def preset_values(method: str, name: str) -> tuple[dict, bool]:
    """(the method's settings, shared blur on/off) of preset ``name`` as the study runs it:
    the method's builtin blur switch off where the shared blur replaces it; a tuned preset as
    tuned; DEFAULT_PRESET as every setting's default. The name is checked as
    ``aolab.compute(preset=...)`` checks it (:func:`settings_of`)."""
    values = settings_of(method, name)
    blur = bool(values.pop("blur", False))
    return values, blur


def identity(method: str, values: dict, blur: bool) -> tuple:
    """What a configuration computes: its settings over the method's defaults (floats at the
    float32 precision the methods store them in), and the blur. Two configurations with the
    same identity are one, whether or not they name a default explicitly."""
    full = {}
    if method in _core.methods():
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
    e = catalog.entry(method)
    # A method whose own filter is the shared blur runs it as the shared blur, timed apart.
    default_blur = e is not None and e.builtin_blur is not None
    out = [Setting(method, DEFAULT_PRESET, {}, default_blur, DEFAULT_PRESET)]
    seen = {identity(method, {}, default_blur)}
    if e is None:
        return out
    names = [p for p in PRESET_ORDER if p in e.presets and (sweep != "quick" or p in QUICK_PRESETS)]
    for name in names:
        values, blur = _split(method, e.presets[name])
        seen.add(identity(method, values, blur))
        out.append(Setting(method, name, values, blur, name))
    for name, values in tuned_presets(method).items():
        values, blur = _split(method, values)
        seen.add(identity(method, values, blur))
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
            key = identity(method, values, blur)
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

    methods = need_object(need_object(data, "the file").get("methods", {}), '"methods"')
    out = {}
    for method, entry_ in methods.items():
        found = need_object(need_object(entry_, f"the entry of {method!r}").get("presets", {}),
                            f'"presets" of {method!r}')
        # A method this build lacks is kept unchecked (a file from a newer build); a known
        # one's settings are checked here, where the message can name the file.
        known = ({s["name"] for s in described(method)} | {"blur"}
                 if method in _core.methods() else None)
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
        return {**{s["name"]: s["default"] for s in described(method)}, "blur": False}
    values, blur = _split(method, catalog.entry(method).presets[name])
    return {**Setting(method, name, values, blur, name).compute_settings(), "blur": blur}


def presets_of(method: str) -> dict:
    """``aolab.presets(method)``: :func:`named`, after checking that ``method`` exists."""
    _check_method(method)
    return named(method)


def _check_method(method: str) -> None:
    if method not in _core.methods():
        raise ValueError(f"method {method!r} is not one of {_core.methods()}")


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
