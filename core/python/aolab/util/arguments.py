"""Command-line values checked when they are read: argparse ``type=`` functions that name the
option and the text they refuse, the bounds they share, and ``Parser``, argparse with two gaps
closed. Shared by the ``aolab`` command (aolab.cli) and the bridge's entry point inside
Blender (blender_addon/aolab_blender/export/batch.py), which must not import the command line.
They parse text into values and read no parsed options: that is the command line's work."""

from __future__ import annotations

import argparse
import math
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
        parts = str(text).strip().lower().split("x")
        if len(parts) == 2 and all(p.strip().isascii() and p.strip().isdigit() for p in parts):
            w, h = (int(p) for p in parts)
            if 1 <= w <= MAX_SIDE and 1 <= h <= MAX_SIDE:
                return w, h
        raise argparse.ArgumentTypeError(f"{name} must be WxH with integers in [1, {MAX_SIDE}], "
                                         f"got {_shown(text)}")
    parse.__name__ = name
    return parse


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
