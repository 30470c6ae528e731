#!/usr/bin/python3
"""Checks that the Python package stays readable: no module over MAX_MODULE_LINES lines and no
function (or method) over MAX_FUNCTION_LINES lines in core/python/aolab. A module that grows past
the limit is two modules; a function past it is phases that want names. scripts/lint.sh runs
this; it prints one line per breach and exits 1 if there is any."""
from __future__ import annotations

import ast
import sys
from pathlib import Path

MAX_MODULE_LINES = 800
MAX_FUNCTION_LINES = 80
PACKAGE = Path(__file__).resolve().parents[1] / "core" / "python" / "aolab"


def breaches(package: Path = PACKAGE) -> list[str]:
    """One line per module or function over its limit, with its length and the limit."""
    found = []
    for path in sorted(package.rglob("*.py")):
        if "vendor" in path.parts:   # third-party code shipped with the report, not ours
            continue
        text = path.read_text(encoding="utf-8")
        name = path.relative_to(package.parents[2])
        lines = len(text.splitlines())
        if lines > MAX_MODULE_LINES:
            found.append(f"{name}: {lines} lines > {MAX_MODULE_LINES}")
        for node in ast.walk(ast.parse(text, str(path))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION_LINES:
                    found.append(f"{name}:{node.lineno}: {node.name} is {length} lines "
                                 f"> {MAX_FUNCTION_LINES}")
    return found


def main() -> int:
    found = breaches()
    for line in found:
        print(f"size: {line}", file=sys.stderr)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
