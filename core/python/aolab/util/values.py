"""Python values checked before they cross into the compiled module: a whole number against
the C++ side's range (pybind would refuse one beyond a C ``int`` with its own TypeError and
a repr of every argument), a real number before its float32 conversion (which would turn
1e39 into inf, and 1e-46 into 0, silently). Each check is a ValueError naming the parameter
and quoting the value as given; the API (aolab, aolab.raytracing, aolab.motion) uses these
and nothing else."""

from __future__ import annotations

import math
import numbers
import struct

import numpy as np

#: The largest C++ ``int``: threads, sizes, taps and frames cross the boundary as one.
INT_MAX = 2**31 - 1
#: float32's largest finite value and its smallest normal one.
FLOAT32_MAX = float(np.finfo(np.float32).max)
FLOAT32_MIN_NORMAL = float(np.finfo(np.float32).tiny)


def shown(value) -> str:
    """``value`` as the caller wrote it, on one short line: numbers and bools as they print
    (1e+300, 2147483648, False: numpy 2's repr would say np.False_), anything else by its
    repr."""
    text = str(value) if isinstance(value, (numbers.Number, np.bool_)) else repr(value)
    text = text.replace("\n", " ")
    return text if len(text) <= 60 else text[:57] + "..."


def _is_bool(value) -> bool:
    return isinstance(value, (bool, np.bool_))


def whole_number(name: str, value, lo: int = 0, hi: int = INT_MAX, *, note: str = "") -> int:
    """``value`` as an int: a Python or numpy integer (a bool is not one) in [lo, hi]; else a
    ValueError naming ``name``. ``note`` follows the range ("(0 = all cores)")."""
    need = f"{name} must be a whole number in [{lo}, {hi}]{' ' + note if note else ''}"
    if _is_bool(value) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{need}, got {shown(value)} ({type(value).__name__})")
    if not lo <= int(value) <= hi:
        raise ValueError(f"{need}, got {shown(value)}")
    return int(value)


def threads(value, name: str = "threads") -> int:
    """A worker-thread count as the C++ side takes it: 0 (all cores) to INT_MAX; a negative
    one in the C++ side's words (docs/conventions.md, "Errors")."""
    if not _is_bool(value) and isinstance(value, numbers.Integral) and value < 0:
        raise ValueError(f"{name} must be >= 0 (0 = all cores), got {shown(value)}")
    return whole_number(name, value, 0, INT_MAX, note="(0 = all cores)")


def float32_number(name: str, value, *, positive: bool = False, allow_inf: bool = False,
                   need: str = "") -> float:
    """``value`` as a float, checked before anything converts it to float32: a real number
    (a Python or numpy int or float; a bool or a string is not one), finite, that float32
    holds (it does not round to inf); with ``positive``, > 0 and a normal float32 (a
    smaller one rounds towards 0); +inf only with ``allow_inf``, and only given as inf (not
    1e39, which float32 would make inf). ``need`` words the requirement ("a finite focal length
    > 0 px"); a ValueError naming ``name`` and quoting the value otherwise."""
    need = need or ("a finite number > 0" if positive else "a finite number")
    head = f"{name} must be {need}, got {shown(value)}"
    if _is_bool(value) or not isinstance(value, numbers.Real):
        raise ValueError(f"{head} ({type(value).__name__})")
    beyond = beyond_float32(value)
    if beyond:
        raise ValueError(f"{head}, {beyond}")
    v = float(value)
    if not (math.isfinite(v) or (allow_inf and v == math.inf)) or (positive and not v > 0):
        raise ValueError(head)
    if positive and v < FLOAT32_MIN_NORMAL:
        raise ValueError(f"{head}, below float32's smallest normal number, "
                         f"{FLOAT32_MIN_NORMAL:.8g}")
    return v


def beyond_float32(value) -> str | None:
    """"above float32's largest, 3.4028235e+38" (or below its lowest) when the real number
    ``value`` is finite and float32 would round it to an infinity; else None."""
    try:
        struct.pack("<f", float(value))   # float32's rounding; OverflowError past it
    except OverflowError:                 # (or an int beyond any float)
        side = "above float32's largest, " if value > 0 else "below float32's lowest, -"
        return f"{side}{FLOAT32_MAX:.8g}"
    return None


def intrinsics(fx, fy, cx, cy) -> tuple[float, float, float, float]:
    """Pinhole intrinsics in pixels as the G-buffer takes them (CameraIntrinsics::validate,
    core/base/camera.cpp), checked before float32: focal lengths > 0, centres finite."""
    focal = "a finite focal length > 0 px"
    return (float32_number("fx", fx, positive=True, need=focal),
            float32_number("fy", fy, positive=True, need=focal),
            float32_number("cx", cx, need="finite"), float32_number("cy", cy, need="finite"))


def float32_params(params: dict) -> None:
    """Checks each number among ``params`` (an analytic scene's, a mesh's) with
    float32_number: they end in float32 depths and vertices. Anything else is left to the
    C++ side, which names what a parameter must be."""
    for name, value in params.items():
        if isinstance(value, numbers.Real) and not _is_bool(value):
            float32_number(str(name), value)


def _exact(x: float) -> str:
    """A bound as the C++ side prints it (exact_number): 2147483647, 1e-12, 1e+30."""
    return str(int(x)) if float(x).is_integer() and abs(x) < 1e16 else repr(float(x))


def settings_as_given(settings: dict, describe) -> None:
    """Refuses, quoting it, a whole-number setting that a double cannot hold exactly (beyond
    2**53): the C++ side reads every setting as a double and would print 2**63 as
    9.223372036854776e+18. ``describe()`` gives the settings' descriptions (method_info's),
    asked only when there is such a value."""
    big = [name for name, v in settings.items()
           if isinstance(v, numbers.Integral) and not _is_bool(v) and abs(int(v)) > 2**53]
    if not big:
        return
    described = {d["name"]: d for d in describe()}
    for name in big:
        d = described.get(name, {})
        if "min" in d and "max" in d:
            unit = f" {d['unit']}" if d.get("unit") else ""
            raise ValueError(f"{name} must be in [{_exact(d['min'])}, {_exact(d['max'])}]{unit}, "
                             f"got {shown(settings[name])}")
