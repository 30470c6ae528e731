"""The add-on's modules stand in the order docs/blender_addon.md ("Modules") gives them, each
importing only modules below it, read from the source with import_graph.py (whose own tests,
and the add-on's no-circle and no-private-name checks, are in test_import_direction.py); and
the add-on loads without a built aolab."""
import json
import shutil
import subprocess
from pathlib import Path

import pytest
from import_graph import import_graph

ROOT = Path(__file__).resolve().parents[2]
ADDON = ROOT / "blender_addon" / "aolab_blender"
BLENDER = shutil.which("blender")
#: The add-on's modules, lowest first, as docs/blender_addon.md ("Modules") lists them: each
#: imports only modules before it here. "aolab_blender" is its __init__.py.
ORDER = ("state", "compat", "images", "preferences", "hooks", "scene_record", "mesh_export",
         "export", "peers", "batch", "properties", "inputs", "live", "operators", "ui",
         "aolab_blender")


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
    """scene_record below export, mesh_export and peers; inputs below operators and live;
    properties reaches Live only through hooks, which imports nothing of the add-on."""
    graph = imports_of(ADDON, "aolab_blender")

    def below(module: str) -> set[str]:
        return reachable(graph, f"aolab_blender.{module}")

    for m in ("export", "mesh_export", "peers"):
        assert "aolab_blender.scene_record" in below(m), m
    assert not below("scene_record") & {"aolab_blender.export", "aolab_blender.mesh_export",
                                        "aolab_blender.peers"}
    for m in ("operators", "live"):
        assert "aolab_blender.inputs" in below(m), m
    assert not below("inputs") & {"aolab_blender.operators", "aolab_blender.live"}
    assert "aolab_blender.hooks" in below("properties")
    assert not below("properties") & {"aolab_blender.live", "aolab_blender.operators"}
    assert below("hooks") == set()


@pytest.mark.blender
@pytest.mark.skipif(BLENDER is None, reason="Blender is not installed "
                    "(scripts/install-deps.sh installs it)")
def test_the_addon_loads_without_aolab():
    """Only properties.py imports `aolab` when the add-on loads, and it is guarded: without a
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
