"""The add-on's modules stand in the order docs/blender_addon.md ("Modules") gives them, each
importing only modules below it, read from the source with import_graph.py (whose own tests,
and the add-on's no-circle and no-private-name checks, are in test_import_direction.py); the
headless export/ imports nothing of the panel, and of the panel only library.py imports
aolab; and the add-on loads without a built aolab."""
import ast
import json
import shutil
import subprocess
from pathlib import Path

import pytest
from import_graph import import_graph

ROOT = Path(__file__).resolve().parents[3]
ADDON = ROOT / "blender_addon" / "aolab_blender"
BLENDER = shutil.which("blender")
#: The add-on's modules, lowest first, as docs/blender_addon.md ("Modules") lists them: each
#: imports only modules before it here. "aolab_blender" is its __init__.py, "export" the
#: headless subpackage's.
ORDER = ("export.state", "export.compat", "export.scene_record", "export.mesh",
         "export.reference", "export.peers", "export.batch", "export",
         "hooks", "library", "images", "preferences", "properties", "inputs", "live",
         "operators", "ui", "aolab_blender")
EXPORT = "aolab_blender.export"


def imports_of(package_dir: Path, package: str) -> dict[str, set[str]]:
    """Module -> the modules of the package it imports."""
    return {name: set(m.imports) for name, m in import_graph(package_dir, package).items()}


def reachable(graph: dict[str, set[str]], start: str) -> set[str]:
    """The modules `start` imports, directly or through others."""
    seen, todo = set(), [start]
    while todo:
        for w in graph.get(todo.pop(), ()):
            if w not in seen:
                seen.add(w)
                todo.append(w)
    return seen


def test_every_addon_module_imports_only_modules_below_it():
    graph = imports_of(ADDON, "aolab_blender")
    rank = {("aolab_blender" if m == "aolab_blender" else f"aolab_blender.{m}"): i
            for i, m in enumerate(ORDER)}
    assert set(graph) == set(rank), "place every module of the add-on in ORDER (and the docs)"
    wrong = [f"{m} imports {t}" for m, targets in graph.items() for t in sorted(targets)
             if rank[t] > rank[m]]
    assert wrong == [], "imports against the order of ORDER:\n" + "\n".join(wrong)


def test_the_addon_modules_stand_where_the_docs_say():
    """scene_record below reference, mesh and peers; inputs below operators and live;
    properties reaches Live only through hooks, which imports nothing of the add-on."""
    graph = imports_of(ADDON, "aolab_blender")

    def below(module: str) -> set[str]:
        return reachable(graph, f"aolab_blender.{module}")

    users = {f"{EXPORT}.{m}" for m in ("reference", "mesh", "peers")}
    for m in users:
        assert f"{EXPORT}.scene_record" in reachable(graph, m), m
    assert not below("export.scene_record") & users
    for m in ("operators", "live"):
        assert "aolab_blender.inputs" in below(m), m
    assert not below("inputs") & {"aolab_blender.operators", "aolab_blender.live"}
    assert "aolab_blender.hooks" in below("properties")
    assert not below("properties") & {"aolab_blender.live", "aolab_blender.operators"}
    assert below("hooks") == set()


def test_the_headless_export_imports_nothing_of_the_panel():
    """export/ runs under `blender -b` without the panel: its modules reach only export/."""
    graph = imports_of(ADDON, "aolab_blender")
    for name in graph:
        if name == EXPORT or name.startswith(EXPORT + "."):
            outside = {m for m in reachable(graph, name)
                       if m != EXPORT and not m.startswith(EXPORT + ".")}
            assert outside == set(), (name, outside)


def test_of_the_panel_only_library_imports_aolab():
    """library.py is the panel's one (guarded) door to `aolab`; export/ imports it at the top,
    as it runs where aolab is (library.py imports export.scene_record guarded)."""
    found = []
    for path in sorted(ADDON.rglob("*.py")):
        if path.parent.name == "export" or path.name == "library.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) and
                     node.level == 0 else [])
            found += [f"{path.name}:{node.lineno} {n}" for n in names
                      if n == "aolab" or n.startswith("aolab.")]
    assert found == []


@pytest.mark.blender
@pytest.mark.skipif(BLENDER is None, reason="Blender is not installed "
                    "(scripts/install-deps.sh installs it)")
def test_the_addon_loads_without_aolab():
    """Only library.py imports `aolab` when the add-on loads, and it is guarded: without a
    built aolab the add-on registers and says so (tests/blender/not_built_check.py)."""
    res = subprocess.run([BLENDER, "-b", "--factory-startup", "-noaudio", "--python-exit-code",
                          "1", "--python", str(ROOT / "tests" / "blender" / "not_built_check.py")],
                         capture_output=True, text=True, timeout=300)
    lines = [line for line in res.stdout.splitlines() if line.startswith("RESULT ")]
    assert res.returncode == 0 and lines, res.stdout[-3000:] + res.stderr[-3000:]
    r = json.loads(lines[-1][len("RESULT "):])
    assert r["file"] == str(ADDON / "__init__.py")
    assert not r["available"] and "hidden by the test" in r["import_error"]
    assert r["aolab_modules"] == []
    assert r["not_built"] in " ".join(r["panel"])   # wrapped to the panel's width
    assert r["preview"]["result"] == ["CANCELLED"] and r["not_built"] in r["preview"]["message"]
    assert r["unregistered"]
