"""The check that a method's docs page copies its settings field table exactly: the rows of
the `## Settings` table of docs/methods/<method>.md against
aolab.method_info(method)["settings"]. A row is

    | `name` | type | default | [min, max] | unit | description |     (float, int)
    | `name` | bool | true | false, true | unit | description |
    | `name` | choice | default-name | a, b, c | unit | description |
"""
from pathlib import Path

import numpy as np

import aolab

DOCS = Path(__file__).resolve().parents[3] / "docs" / "methods"


def docs_rows(method: str, page: Path | None = None) -> list[list[str]]:
    """The cells of every setting row of the docs page's `## Settings` table (the method's
    page unless `page` names another)."""
    text = (page or DOCS / f"{method}.md").read_text()
    section = text.split("\n## Settings\n", 1)[1].split("\n## ", 1)[0]
    return [[c.strip() for c in line.strip().strip("|").split("|")]
            for line in section.splitlines() if line.startswith("| `")]


def assert_docs_settings_table(method, page: Path | None = None, settings=None):
    """`settings` (the method's unless given, as for a shared step's page) against the rows of
    `page` (the method's page unless given)."""
    rows = docs_rows(method, page)
    settings = aolab.method_info(method)["settings"] if settings is None else settings
    assert [r[0].strip("`") for r in rows] == [s["name"] for s in settings]
    for (name, kind, default, rng, unit, meaning), s in zip(rows, settings):
        assert (kind, unit, meaning) == (s["type"], s["unit"], s["description"]), name
        if kind == "bool":
            assert (default, rng) == ("true" if s["default"] else "false", "false, true"), name
        elif kind == "choice":
            assert default == s["default"], name
            assert [c.strip() for c in rng.split(",")] == list(s["choices"]), name
        else:
            assert np.float32(float(default)) == np.float32(s["default"]), name
            lo, hi = (float(v) for v in rng.strip("[]").split(","))
            assert (np.float32(lo), np.float32(hi)) == (np.float32(s["min"]),
                                                        np.float32(s["max"])), name


def settings_table(method: str, settings=None) -> str:
    """The Markdown table for the docs, from the field table (the method's unless `settings`
    gives another's)."""
    lines = ["| setting | type | default | range | unit | meaning |", "|---|---|---|---|---|---|"]
    for s in aolab.method_info(method)["settings"] if settings is None else settings:
        if s["type"] == "bool":
            default, rng = ("true" if s["default"] else "false"), "false, true"
        elif s["type"] == "choice":
            default, rng = s["default"], ", ".join(s["choices"])
        else:
            def num(v):
                return str(int(v)) if s["type"] == "int" else f"{v:.7g}".replace("e+", "e")
            default, rng = num(s["default"]), f"[{num(s['min'])}, {num(s['max'])}]"
        lines.append(f"| `{s['name']}` | {s['type']} | {default} | {rng} | {s['unit']} | "
                     f"{s['description']} |")
    return "\n".join(lines)
