"""Command-line values checked when they are read: argparse ``type=`` functions that name the
option and the text they refuse, the parsers of option texts (sizes, frames, crops, budgets,
thicknesses: a ValueError naming the option), the bounds they share, and ``Parser``, argparse
with two gaps closed. Shared by the ``aolab`` command (aolab.cli), the library modules that
take an option's text (aolab.cycles, aolab.study) and the bridge's entry point inside Blender
(blender_addon/aolab_blender/export/batch.py), none of which may import the command line: so
the parsers live here, in the lowest layer. They parse text into values and read no parsed
options: that is the command line's work."""

from __future__ import annotations

import argparse
import math
import re
import sys

from .values import beyond_float32


# --- option values, validated when the command line is read --------------------------------

#: The largest analytic scene side and report image width (16384 = 16K; a 100000-pixel side
#: would need tens of gigabytes).
MAX_SIDE = 16384
#: The most worker threads an option accepts (0 = all cores; a computation uses at most one
#: per band of 4 rows).
MAX_THREADS = 4096
#: The most timed or warm-up runs per configuration.
MAX_RUNS = 1000
#: The most samples per pixel Cycles accepts.
MAX_SAMPLES = 16777216


def _shown(text: str) -> str:
    """An option's text for a message: repr, shortened to keep the message one short line."""
    return repr(text) if len(text) <= 60 else repr(text[:57]) + "..."


def int_option(name: str, lo: int | None = None, hi: int | None = None, *,
               odd: bool = False, what: str = ""):
    """An argparse ``type=`` for an integer option in [lo, hi] (either end open when None),
    odd if ``odd``: the int, or argparse.ArgumentTypeError naming the option and the text."""
    if lo is not None and hi is not None:
        need = f"an integer in [{lo}, {hi}]"
    elif lo is not None:
        need = f"an integer >= {lo}"
    elif hi is not None:
        need = f"an integer <= {hi}"
    else:
        need = "an integer"
    need = ("an odd " + need[3:]) if odd else need
    need += f" ({what})" if what else ""

    def parse(text: str) -> int:
        try:
            value = int(text.strip())
        except (ValueError, TypeError):   # also an integer of more than 4300 digits
            raise argparse.ArgumentTypeError(
                f"{name} must be {need}, got {_shown(text)}") from None
        if ((lo is not None and value < lo) or (hi is not None and value > hi)
                or (odd and value % 2 == 0)):
            shown = str(value) if len(str(value)) <= 30 else f"{str(value)[:27]}..."
            raise argparse.ArgumentTypeError(f"{name} must be {need}, got {shown}")
        return value
    parse.__name__ = name   # argparse's own messages name the type
    return parse


def checked_type(parse, name: str):
    """An argparse ``type=`` from a parser that raises ValueError naming the option: argparse
    then prints the usage line and ``argument NAME: <the message>`` (also batch.py's)."""
    def convert(text: str):
        try:
            return parse(text)
        except ValueError as e:
            raise argparse.ArgumentTypeError(str(e)) from None
    convert.__name__ = name
    return convert


def int_list_option(name: str, hi: int):
    """An argparse ``type=`` for a comma-separated list of counts (rays or samples per pixel),
    each in [1, hi], or 'none' (the empty tuple)."""
    def convert(text: str) -> tuple[int, ...]:
        if text.strip().lower() == "none":
            return ()
        try:
            values = tuple(int(v) for v in text.split(","))
            if values and all(1 <= v <= hi for v in values):
                return values
        except ValueError:
            pass
        raise argparse.ArgumentTypeError(f"{name} must be comma-separated integers in "
                                         f"[1, {hi}] or 'none', got {text!r}")
    convert.__name__ = name
    return convert


def float_option(name: str, lo: float = 0.0, hi: float = math.inf, *,
                 lo_inclusive: bool = False, allow_inf: bool = False, unit: str = "",
                 float32: bool = False):
    """An argparse ``type=`` for a float option: finite (or +inf when ``allow_inf``), > lo
    (>= lo when ``lo_inclusive``) and <= hi, and with ``float32`` a value float32 holds (it
    becomes one in C++ or Blender, where 1e300 would be inf): the float, or
    argparse.ArgumentTypeError naming the option and the text."""
    unit = f" {unit}" if unit else ""
    if math.isinf(hi):
        need = f"{'>=' if lo_inclusive else '>'} {lo:g}{unit}"
    else:
        need = f"in {'[' if lo_inclusive else '('}{lo:g}, {hi:g}]{unit}"
    need = f"a number {need}" + (" or inf" if allow_inf else "")

    def parse(text: str) -> float:
        try:
            value = float(text.strip())
        except (ValueError, TypeError, OverflowError):
            value = math.nan
        ok = (value >= lo if lo_inclusive else value > lo) and value <= hi
        if not ok or (math.isinf(value) and not allow_inf):
            raise argparse.ArgumentTypeError(f"{name} must be {need}, got {_shown(text)}")
        beyond = beyond_float32(value) if float32 else None
        if beyond:
            raise argparse.ArgumentTypeError(
                f"{name} must be {need}, got {_shown(text)}, {beyond}")
        return value
    parse.__name__ = name
    return parse


def size_option(name: str):
    """An argparse ``type=`` for ``WxH`` with integers in [1, MAX_SIDE] (the analytic scenes'
    range): (width, height), or argparse.ArgumentTypeError naming the option and the text."""
    def parse(text: str) -> tuple[int, int]:
        size = split_size(text)
        if size is not None and all(1 <= v <= MAX_SIDE for v in size):
            return size
        raise argparse.ArgumentTypeError(f"{name} must be WxH with integers in [1, {MAX_SIDE}], "
                                         f"got {_shown(text)}")
    parse.__name__ = name
    return parse


# --- option texts read into values: a ValueError naming the option -----------------------

#: The largest render width or height (16384 = 16K, the largest side the rest of aolab
#: accepts, MAX_SIDE): one 100000x100000 frame of G-buffer passes would take hundreds of
#: gigabytes and Cycles would render it for days.
MAX_RESOLUTION = MAX_SIDE
#: The smallest render width or height: Blender's own minimum (RenderSettings.resolution_x
#: and resolution_y have a hard minimum of 4 in Blender 3.4 and 4.x). Blender raises a
#: smaller value to 4 without a word, so a 1x1 request would come back as a 4x4 reference.
MIN_RESOLUTION = 4
#: Blender's frame range (scene.frame_current's hard limits in 3.4 and 4.x).
MAX_FRAME = 1048574
#: The most frames one --frames names, and the most references one command renders (every
#: scene's frames together). A reference costs at least Blender's start-up, a second or more,
#: so 100000 of them are days of a machine's time already: a larger request is a mistyped
#: range, refused before anything is planned or submitted.
MAX_FRAMES = 100000
#: The largest budget ``--budget`` takes (ms): beyond it, advice is not about real time.
MAX_BUDGET_MS = 1e6
#: The largest finite thickness, in multiples of R, that --thickness takes: a shell a million
#: times R thick is a height field for any scene (inf says so), and a larger number such as
#: 1e300 would overflow the method's float thickness (it said "got inf").
MAX_THICKNESS_R = 1e6


def split_size(text) -> tuple[int, int] | None:
    """``WxH`` (either x, spaces around the numbers) as two integers of ASCII digits, or None
    for any other text."""
    parts = str(text).strip().lower().split("x")
    if len(parts) == 2 and all(p.strip().isascii() and p.strip().isdigit() for p in parts):
        try:
            return int(parts[0]), int(parts[1])
        except ValueError:   # more than 4300 digits
            return None
    return None


def check_resolution(resolution, name: str = "resolution") -> tuple[int, int]:
    """(width, height) as integers in [MIN_RESOLUTION, MAX_RESOLUTION]; else a ValueError
    naming ``name`` and the value."""
    try:
        w, h = resolution
        ok = all(not isinstance(v, bool) and int(v) == v and
                 MIN_RESOLUTION <= v <= MAX_RESOLUTION for v in (w, h))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"{name} must be a width and a height, integers in "
                         f"[{MIN_RESOLUTION}, {MAX_RESOLUTION}] (Blender renders at least "
                         f"{MIN_RESOLUTION}x{MIN_RESOLUTION}), got {resolution!r}")
    return int(w), int(h)


def parse_resolution(text: str, name: str = "--resolution") -> tuple[int, int]:
    """``WxH``: width and height integers in [MIN_RESOLUTION, MAX_RESOLUTION], else a
    ValueError naming ``name`` and the text."""
    size = split_size(text)
    if size is not None and all(MIN_RESOLUTION <= v <= MAX_RESOLUTION for v in size):
        return size
    raise ValueError(f"{name} must be WxH with integers in [{MIN_RESOLUTION}, "
                     f"{MAX_RESOLUTION}] (Blender renders at least "
                     f"{MIN_RESOLUTION}x{MIN_RESOLUTION}), got {text!r}")


def parse_frames(text: str, name: str = "--frames") -> list[int]:
    """``N``, ``S-E`` or ``S-E:STEP`` (E included, STEP >= 1; frames may be negative, as in
    Blender: ``-5--1``) -> the frame numbers; a ValueError naming ``name`` otherwise."""
    m = re.fullmatch(r"\s*(-?\d+)(?:\s*-\s*(-?\d+)(?:\s*:\s*(\d+))?)?\s*", str(text))
    if m:
        start = int(m.group(1))
        end = int(m.group(2)) if m.group(2) is not None else start
        step = int(m.group(3)) if m.group(3) is not None else 1
        if (step >= 1 and start <= end and -MAX_FRAME <= start and end <= MAX_FRAME
                and (end - start) // step < MAX_FRAMES):
            return list(range(start, end + 1, step))
    raise ValueError(f"{name} must be N, START-END or START-END:STEP with START <= END, STEP "
                     f">= 1, frames in [-{MAX_FRAME}, {MAX_FRAME}] and at most {MAX_FRAMES} of "
                     f"them, got {text!r}")


def parse_crop(text: str | None) -> tuple[int, int] | None:
    """--crop ``WxH``: a centred window's width and height, positive integers (the caller
    makes it an aolab.scenes.Crop); None for no text."""
    if not text:
        return None
    size = split_size(text)
    if size is None or min(size) < 1:
        raise ValueError(f"--crop must be WxH with positive integers, got {text!r}")
    return size


def parse_budget(text: str) -> float:
    """"16ms", "16 ms", "16" or "1e3" -> 16.0 (1000.0): a time per 1280x720 frame in
    (0, MAX_BUDGET_MS] ms (aolab advise); anything else is a ValueError naming it, with the
    bound in full (1000000, not 1e+06, which reads as the text it refuses)."""
    m = re.fullmatch(r"\s*((?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)\s*(?:ms)?\s*",
                     str(text))
    value = float(m.group(1)) if m else math.nan
    if not 0 < value <= MAX_BUDGET_MS:
        raise ValueError(f"--budget must be a time per 1280x720 frame in ms, more than 0 and at "
                         f"most {MAX_BUDGET_MS:.0f}, e.g. 16ms, 33ms or 100ms; got {text!r}")
    return value


def parse_thickness(text) -> float:
    """A thickness in multiples of R (aolab limits): a number in (0, MAX_THICKNESS_R], or inf
    (a height field); a ValueError naming --thickness otherwise."""
    try:
        v = float(str(text).strip())
    except ValueError:
        v = math.nan
    # Only "inf" itself asks for a height field: 1e309 is a number too large, not a wish.
    spelled_inf = str(text).strip().lower().lstrip("+") in ("inf", "infinity")
    if not (0 < v <= MAX_THICKNESS_R or (v == math.inf and spelled_inf)):
        raise ValueError(f"--thickness must be a multiple of R in (0, {MAX_THICKNESS_R:g}] or "
                         f"inf (a height field), got {str(text)!r}")
    return v


class Parser(argparse.ArgumentParser):
    """argparse with two gaps closed: Python 3.11's argparse drops a value ``--`` given as
    ``--OPT=--`` and stores an empty list without calling the option's ``type``, so the
    range check never runs. Here ``--OPT=--`` is refused like any other bad value. And its
    "unrecognized arguments" message shows them as typed, so a newline in one split the
    message over lines; here it is one line. Subcommand parsers are of this class too
    (add_subparsers makes them of the parent's class), each checking its own options."""

    def error(self, message):
        super().error(message.replace("\r", "\\r").replace("\n", "\\n"))

    def parse_known_args(self, args=None, namespace=None):
        for text in sys.argv[1:] if args is None else args:
            if text == "--":   # what follows is positional
                break
            option = text[:-3] if text.endswith("=--") else None
            if option in self._option_string_actions:
                self.error(f"argument {option}: expected one value, got '--'")
        return super().parse_known_args(args, namespace)
