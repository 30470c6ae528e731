"""Method settings as the Python side handles them: values from text (the command line's
``--set NAME=VALUE``), equality at the precision the methods store, and which values differ
from a method's defaults (the add-on passes only those). No bpy.

``aolab.method_info(method)["settings"]`` describes each setting as a dict with ``name``,
``type`` (``float``, ``int``, ``bool`` or ``choice``), ``default``, ``unit`` and
``description``; numbers and bools also have ``min`` and ``max``; a choice (e.g. lsao's
``falloff``) has ``choices``, its names, and a name as its default, and is set by name:
``aolab.compute("lsao", g, radius=1.0, falloff="clipped")``.
"""

from __future__ import annotations

import numpy as np

from . import _core

#: Settings every method has and that callers set once for all methods (the panel's R, the
#: scene's R in the study).
SHARED = ("radius",)

_TRUE = ("true", "on", "yes")
_FALSE = ("false", "off", "no")


def is_choice(s: dict) -> bool:
    """Whether a setting description is a choice among names."""
    return s.get("type") == "choice"


def described(method: str, *, shared: bool = False) -> list[dict]:
    """The method's setting descriptions, without the SHARED ones unless ``shared``."""
    return [s for s in _core.method_info(method)["settings"]
            if shared or s["name"] not in SHARED]


def by_name(method: str) -> dict[str, dict]:
    """The method's setting descriptions by name (the shared ones included)."""
    return {s["name"]: s for s in described(method, shared=True)}


def parse_value(text: str, setting: dict | None = None):
    """The value of ``--set NAME=TEXT``. A choice setting takes its name as it is; otherwise
    true/on/yes and false/off/no are bools, then an int, then a float; anything else is
    passed on as text, for aolab.compute to name what is wrong with it."""
    text = text.strip()
    if setting is not None and is_choice(setting):
        return text
    low = text.lower()
    if low in _TRUE:
        return True
    if low in _FALSE:
        return False
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


#: What a number or bool setting's text must be, for the message naming a bad one.
_KIND = {"int": "an integer", "float": "a number",
         "bool": "true or false (on/off, yes/no, 1/0)"}


def parse_assignments(pairs: list[str] | None, method: str | None = None) -> dict:
    """``["directions=16", "falloff=clipped"]`` -> a settings dict, each value read by
    parse_value with the method's description of that setting (when ``method`` is given).
    Raises ValueError for an item without ``=`` or without a key, and, when ``method``
    describes the setting, for text that is no value of its type (``directions=abc``,
    ``directions=``), naming the setting and the text. Ranges are left to aolab.compute."""
    known = by_name(method) if method is not None else {}
    out = {}
    for pair in pairs or []:
        if "=" not in pair:
            raise ValueError(f"expected KEY=VALUE, got {pair!r}")
        key, value = (part.strip() for part in pair.split("=", 1))
        if not key:
            raise ValueError(f"expected KEY=VALUE, got {pair!r}")
        setting = known.get(key)
        parsed = parse_value(value, setting)
        if setting is not None and isinstance(parsed, str) and setting["type"] in _KIND:
            raise ValueError(f"{key} must be {_KIND[setting['type']]}, got {value!r}")
        out[key] = parsed
    return out


def same_value(s: dict, a, b) -> bool:
    """Whether ``a`` and ``b`` are the same value of setting ``s`` as the method stores it:
    floats in single precision, choices by name."""
    if s["type"] == "float":
        return bool(np.float32(a) == np.float32(b))
    if s["type"] == "bool":
        return bool(a) == bool(b)
    if is_choice(s):
        return str(a) == str(b)
    return int(a) == int(b)


def plain(s: dict, value):
    """``value`` as the plain Python type of setting ``s`` (a Blender property's value, a
    numpy scalar): float, bool, int or a choice's name."""
    if s["type"] == "float":
        return float(value)
    if s["type"] == "bool":
        return bool(value)
    if is_choice(s):
        return str(value)
    return int(value)


def changed_settings(method: str, values: dict) -> dict:
    """The entries of ``values`` that differ from the method's defaults, as plain values.
    Blender keeps floats in single precision: a value equal to float32(default) is the
    default and is left to the C++ side, so untouched settings give exactly what the command
    line gives."""
    out = {}
    for s in described(method):
        if s["name"] in values and not same_value(s, values[s["name"]], s["default"]):
            out[s["name"]] = plain(s, values[s["name"]])
    return out


def describe_value(s: dict) -> str:
    """The allowed values of a setting in words: ``one of a, b, c``, ``false or true`` or
    ``range [lo, hi] unit``."""
    if is_choice(s):
        return "one of " + ", ".join(s["choices"])
    if s["type"] == "bool":
        return "false or true"
    unit = f" {s['unit']}" if s.get("unit") else ""
    return f"range [{s['min']:g}, {s['max']:g}]{unit}"
