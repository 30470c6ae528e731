"""The ``aolab`` command.

    aolab methods                         list the methods and their settings
    aolab analytic NAME OUT.exr           write an analytic scene's G-buffer (+ sidecar)
    aolab run METHOD INPUT [options]      compute AO for a G-buffer, write EXR + PNG, score it
    aolab rtao INPUT [options]            ray-traced AO against the scene's triangles (Embree)
    aolab rtao-check [SCENE...]           rtao at 1024 rays against the committed references
    aolab bridge-check [SCENE...]         this Blender's export against the committed references
    aolab bench [options]                 time a method (median of repeated runs)
    aolab bench-table [METHOD...]         every method's scalar code against its SIMD kernel
    aolab reference SCENE... [options]    render Cycles AO references with Blender (cached)
    aolab mesh SCENE... [options]         export each scene's triangles as rendered (cached)
    aolab limits [SCENE...] [options]     compute the screen-space limit of each scene (committed)
    aolab compare [SCENE...] [options]    score every method against the references: report
    aolab advise SCENE [--budget MS]      which method and preset for this scene within a budget
    aolab presets [METHOD...]             the named presets of each method and their settings
    aolab tune [options]                  search each method's settings for the Pareto front
    aolab radius-study [SCENE...]         HBAO, Pyramid HBAO and Scalable AO against the radius

INPUT is a G-buffer EXR with its sidecar JSON, or ``analytic:NAME`` for a built-in scene.

Errors: bad input never shows a traceback. A bad option value is refused when the command
line is read (the usage line, then ``argument --OPT: --OPT must be ..., got VALUE``; exit
status 2); any error while a command runs prints one line ``aolab: <message>`` (the
exception's type name when it has no message) on stderr and exits with status 2. Ctrl-C
exits with status 130 (compare, tune and reference keep their partial work first).
``aolab --debug COMMAND ...`` shows the Python traceback instead.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

import aolab

from ..util.arguments import Parser
from . import (advise, analytic, bench, bench_table, bridge_check, compare, limits, mesh,
               methods, presets, radius_study, reference, rtao, rtao_check, run, tune)

#: Every command, in the order of the list above: a module with ``add_parser(sub)`` (its
#: parser) and ``run(args)`` (its call: the exit status).
COMMANDS = (methods, analytic, run, rtao, rtao_check, bridge_check, bench, bench_table,
            reference, mesh, limits, compare, advise, presets, tune, radius_study)


# --- errors ---------------------------------------------------------------------------------

def error_message(e: BaseException) -> str:
    """One line for ``aolab: <message>``: the exception's message with its lines joined; an
    OSError as its reason and file; the type name in front unless the exception is a plain
    ValueError (the library's errors), an OSError or a SystemExit, and alone when there is no
    message (a MemoryError)."""
    if isinstance(e, OSError) and e.strerror:
        files = [f for f in (e.filename, getattr(e, "filename2", None)) if f is not None]
        text = e.strerror + "".join(
            f": {os.fsdecode(f) if isinstance(f, bytes) else str(f)!r}" for f in files)
    elif isinstance(e, SystemExit):
        text = "" if e.code is None else str(e.code)
    else:
        try:
            text = str(e)
        except Exception:   # a __str__ that fails itself
            text = ""
    text = " ".join(text.split())   # one line
    if text.startswith("aolab: "):
        text = text[len("aolab: "):]
    if not text:
        return type(e).__name__
    if type(e) is ValueError or isinstance(e, (OSError, SystemExit)):
        return text
    return f"{type(e).__name__}: {text}"


def _report(message: str) -> None:
    """``aolab: message`` on stderr, whatever the terminal's encoding."""
    line = f"aolab: {message}\n"
    encoding = getattr(sys.stderr, "encoding", None) or "utf-8"
    try:
        line = line.encode(encoding, "backslashreplace").decode(encoding)
    except LookupError:
        pass
    sys.stderr.write(line)
    sys.stderr.flush()


def _one_line_warnings(show):
    """A ``warnings.showwarning`` that prints an aolab warning (RtaoRangeWarning) as one line
    ``aolab: warning: <message>``, like the command's errors, and passes any other to
    ``show``."""
    def show_warning(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, aolab.RtaoRangeWarning):
            _report("warning: " + " ".join(str(message).split()))
        else:
            show(message, category, filename, lineno, file, line)
    return show_warning


def build_parser() -> argparse.ArgumentParser:
    p = Parser(prog="aolab", description=__doc__,
               formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--debug", action="store_true",
                   help="show the Python traceback of an error instead of the one-line "
                   "'aolab: <message>' (give it before the command: aolab --debug run ...)")
    sub = p.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.add_parser(sub).set_defaults(command_module=command)
    return p


def main(argv: list[str] | None = None) -> int:
    """The aolab command: the exit status. A bad option value returns 2 after argparse's usage
    line and message; an exception from a command prints ``aolab: <message>`` (one line) and
    returns 2, Ctrl-C returns 130, and ``--debug`` re-raises instead (docs/conventions.md,
    Errors)."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as e:   # a bad option value (2), --help (0): argparse printed why
        return e.code if isinstance(e.code, int) else 2
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _one_line_warnings(warnings.showwarning)
            return args.command_module.run(args)
    except KeyboardInterrupt:
        if args.debug:
            raise
        _report("interrupted")
        return 130
    except BrokenPipeError:   # aolab methods | head: the reader left; say nothing
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        return 141   # 128 + SIGPIPE, what a shell shows for a process the pipe ended
    except SystemExit as e:
        if e.code is None or isinstance(e.code, int) or args.debug:
            raise
        _report(error_message(e))   # SystemExit("message") from a command
        return 2
    except Exception as e:
        if args.debug:
            raise
        _report(error_message(e))
        return 2
