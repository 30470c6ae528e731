"""Generated blocks of a committed Markdown page: the part between two marker lines that a
command rewrites (docs/results.md, docs/rtao.md, docs/blender_bridge.md), everything outside
them kept as written."""

from __future__ import annotations

import re
from pathlib import Path

from . import files

#: What text() escapes with a backslash: what would end a table cell ("|"), start HTML, code,
#: a link or emphasis, or escape the next character.
_SPECIAL = re.compile(r"([\\`*\[\]<>|&])")
_LINE_BREAKS = re.compile(r"[\r\n\u2028\u2029\x85\v\f]+")


def text(value) -> str:
    """A user's string (a scene's or a configuration's name) as inline Markdown that shows as
    written: one line (line breaks become spaces, so a table row stays one row), and each of
    \\ ` * [ ] < > | & escaped with a backslash."""
    return _SPECIAL.sub(r"\\\1", _LINE_BREAKS.sub(" ", str(value)))


def with_generated_block(path: Path, begin: str, end: str, body: str, *,
                         append_if_missing: bool = False) -> str:
    """The text of the Markdown file `path` with `body` between the marker lines `begin` and
    `end`, the rest as it was. A file without the markers is a ValueError naming them, or,
    with `append_if_missing`, gets the block at its end. Called with an empty body before a
    long run, it checks the file that write_generated_block will rewrite after it."""
    text = files.read_text(path, "Markdown")
    if begin in text and end in text:
        return text[:text.index(begin) + len(begin)] + "\n\n" + body + "\n\n" + \
            text[text.index(end):]
    if append_if_missing:
        return text.rstrip("\n") + "\n\n" + begin + "\n\n" + body + "\n\n" + end + "\n"
    raise ValueError(f"{path} has no {begin!r} ... {end!r} block to replace")


def write_generated_block(path: Path, begin: str, end: str, body: str, *,
                          append_if_missing: bool = False) -> None:
    """Replaces what lies between the marker lines `begin` and `end` of the Markdown file
    `path` with `body`, atomically (with_generated_block)."""
    text = with_generated_block(path, begin, end, body, append_if_missing=append_if_missing)
    files.write_text(path, text)
