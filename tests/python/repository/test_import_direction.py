"""Doors open one way: the bpy side (blender_addon/aolab_blender) imports `aolab`, and
`aolab` never imports bpy, Blender's other modules or the add-on. Checked on the source
(every import statement of core/python/aolab, parsed) and on the built package (every
module imported in a fresh interpreter, which must then hold none of them)."""
import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import aolab
from import_graph import find_cycles, import_graph, module_names

ROOT = Path(__file__).resolve().parents[3]
SOURCE = ROOT / "core" / "python" / "aolab"
#: Top-level modules `aolab` must not import: Blender's API and the add-on.
FORBIDDEN = ("bpy", "bmesh", "mathutils", "aolab_blender")
#: Calls that import a module named by a string.
IMPORT_CALLS = ("import_module", "__import__", "find_spec")


def forbidden_imports(source: str, filename: str = "<source>") -> list[str]:
    """`file:line name` for every import of a FORBIDDEN module in ``source``: import and
    from-import statements (at any depth: in functions, try blocks), and import_module /
    __import__ / find_spec calls with a literal name."""
    found = []

    def check(name: str | None, node) -> None:
        if name and name.split(".")[0] in FORBIDDEN:
            found.append(f"{filename}:{node.lineno} {name}")

    for node in ast.walk(ast.parse(source, filename)):
        if isinstance(node, ast.Import):
            for alias in node.names:
                check(alias.name, node)
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            check(node.module, node)
        elif isinstance(node, ast.Call) and node.args:
            func = node.func
            called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            first = node.args[0]
            if called in IMPORT_CALLS and isinstance(first, ast.Constant) \
                    and isinstance(first.value, str):
                check(first.value, node)
    return found


def source_files() -> list[Path]:
    return sorted(SOURCE.rglob("*.py"))


def test_the_checker_finds_every_kind_of_import():
    snippet = "\n".join([
        "import bpy", "import os, bmesh.types", "from mathutils import Vector",
        "def f():", "    from aolab_blender import export", "    import importlib.util",
        "    importlib.util.find_spec('aolab_blender')", "    __import__('bpy')",
        "from . import bpy_free", "import bpyx", "x = 'import bpy'"])
    assert [f.split(" ", 1)[1] for f in forbidden_imports(snippet)] == [
        "bpy", "bmesh.types", "mathutils", "aolab_blender", "aolab_blender", "bpy"]


def test_source_never_imports_blender_or_the_addon():
    files = source_files()
    assert SOURCE / "jobs" / "tasks.py" in files  # the subpackages are walked too
    found = [f for path in files
             for f in forbidden_imports(path.read_text(), str(path.relative_to(ROOT)))]
    assert found == [], "aolab must not import Blender's modules or the add-on:\n" + \
        "\n".join(found)


def test_every_module_imports_without_blender_or_the_addon():
    """A fresh interpreter imports every module of the package this test uses (the build's),
    found by pkgutil.walk_packages; none of FORBIDDEN may be loaded then."""
    package_root = str(Path(aolab.__file__).resolve().parents[1])
    probe = f"""
import importlib, json, pkgutil, sys
import aolab
names = [m.name for m in pkgutil.walk_packages(aolab.__path__, "aolab.")]
for name in names:
    importlib.import_module(name)
print(json.dumps({{"modules": names, "loaded": [n for n in {FORBIDDEN!r} if n in sys.modules],
                  "file": aolab.__file__}}))
"""
    env = dict(os.environ, PYTHONPATH=package_root)
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         env=env, timeout=120)
    assert res.returncode == 0, res.stdout + res.stderr
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert out["file"].startswith(package_root)
    assert out["loaded"] == []
    # Every source module is in the build (subpackages copied) and was imported.
    expected = {"aolab." + ".".join(p.relative_to(SOURCE).with_suffix("").parts)
                for p in source_files() if p.name != "__init__.py"}
    expected |= {"aolab." + ".".join(p.parent.relative_to(SOURCE).parts)
                 for p in source_files() if p.name == "__init__.py" and p.parent != SOURCE}
    assert expected <= set(out["modules"]), sorted(expected - set(out["modules"]))


def test_the_addon_is_not_beside_the_package():
    """The build puts no copy of the add-on beside aolab (on Blender's sys.path it would
    shadow the installed add-on of the same name); it records where its source is."""
    package_root = Path(aolab.__file__).resolve().parents[1]
    assert not (package_root / "aolab_blender").exists()
    from aolab.cycles.blender import bridge_script
    assert bridge_script() == ROOT / "blender_addon" / "aolab_blender" / "export" / "batch.py"


# --- One way inside the package and the add-on ------------------------------------------------

ADDON = ROOT / "blender_addon" / "aolab_blender"

#: The layers of `aolab`, lowest first (docs/architecture.md, "The aolab package"): a module
#: imports modules of its own layer or below, never above. A name matches a module and every
#: module below it; the first match counts.
LAYERS = (
    ("aolab._core", "aolab._build_info", "aolab.util"),
    ("aolab.bridge",),
    ("aolab.catalog",),
    ("aolab.settings", "aolab.scoring", "aolab.regions", "aolab.raytracing",
     "aolab.named_presets", "aolab.motion"),
    ("aolab",),                      # the API: aolab/__init__.py
    ("aolab.scenes",),
    ("aolab.cycles",),
    ("aolab.study",),
    ("aolab.checks", "aolab.benchmarks"),
    ("aolab.jobs",),
    ("aolab.cli", "aolab.__main__"),
)
#: Modules outside the command line that may import argparse, and why. Nothing else reads an
#: argparse Namespace.
#: The package's compiled modules.
EXTENSIONS = ("aolab._core",)
ARGPARSE_OUTSIDE_CLI = {
    "aolab.util.arguments": "the option types themselves, shared with the bridge's entry point",
    "aolab.jobs.reference_job": "a child process's own entry point (python3 -m)",
}


def layer_of(module: str) -> int:
    for rank, names in enumerate(LAYERS):
        if any(module == n or (n != "aolab" and module.startswith(n + ".")) for n in names):
            return rank
    raise AssertionError(f"{module} is in no layer of LAYERS: add it")


def make_package(tmp_path: Path, files: dict) -> Path:
    root = tmp_path / "pkg"
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)
    return root


def test_the_graph_checker_finds_circles_at_any_depth(tmp_path):
    root = make_package(tmp_path, {
        "__init__.py": "from . import a\n",
        "a.py": "from .sub import b\n",
        "sub/__init__.py": "",
        "sub/b.py": "def f():\n    from ..a import thing\n",     # inside a function
        "c.py": "import pkg.sub.b\nfrom pkg import a\n",
    })
    graph = import_graph(root, "pkg")
    assert graph["pkg.a"].imports.keys() == {"pkg.sub.b"}
    assert graph["pkg.c"].imports.keys() == {"pkg.sub.b", "pkg.a"}
    assert find_cycles(graph) == [["pkg.a", "pkg.sub.b"]]


def test_the_graph_checker_finds_private_names(tmp_path):
    root = make_package(tmp_path, {
        "__init__.py": "",
        "a.py": "_hidden = 1\n",
        "b.py": "from .a import _hidden\nfrom . import _core\n",
        "c.py": "from . import a\nx = a._hidden\ny = a.__name__\n",
        "_core.py": "",
    })
    graph = import_graph(root, "pkg")
    assert graph["pkg.b"].private == ["1: from pkg.a import _hidden"]   # _core: a module
    assert graph["pkg.c"].private == ["2: a._hidden"]
    assert find_cycles(graph) == []


@pytest.mark.parametrize("where,package", [(SOURCE, "aolab"), (ADDON, "aolab_blender")])
def test_no_import_circle(where, package):
    cycles = find_cycles(import_graph(where, package, EXTENSIONS))
    assert cycles == [], f"import circles in {package}:\n" + "\n".join(map(str, cycles))


@pytest.mark.parametrize("where,package", [(SOURCE, "aolab"), (ADDON, "aolab_blender")])
def test_no_module_takes_another_modules_private_name(where, package):
    graph = import_graph(where, package, EXTENSIONS)
    found = [f"{m.name}:{p}" for m in graph.values() for p in m.private]
    assert found == [], "private names taken from another module:\n" + "\n".join(found)


def test_aolab_imports_only_its_own_layer_or_below():
    graph = import_graph(SOURCE, "aolab", EXTENSIONS)
    wrong = [f"{m.name} (layer {layer_of(m.name)}) imports {t} (layer {layer_of(t)}), line {n}"
             for m in graph.values() for t, n in m.imports.items()
             if layer_of(t) > layer_of(m.name)]
    assert wrong == [], "imports against the layers:\n" + "\n".join(wrong)


def test_only_the_command_line_imports_the_command_line():
    """Nothing in `aolab` outside aolab.cli, nor the add-on, imports aolab.cli; and only the
    modules of ARGPARSE_OUTSIDE_CLI import argparse outside it."""
    graph = import_graph(SOURCE, "aolab", EXTENSIONS)
    wrong = [f"{m.name} imports {t}" for m in graph.values() for t in m.imports
             if t.startswith("aolab.cli") and layer_of(m.name) != layer_of("aolab.cli")]
    for path in sorted(ADDON.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            wrong += [f"{path.relative_to(ROOT)}:{node.lineno} imports {n}" for n in names
                      if n == "aolab.cli" or n.startswith("aolab.cli.")]
    for name, path in module_names(SOURCE, "aolab").items():
        if layer_of(name) == layer_of("aolab.cli") or name in ARGPARSE_OUTSIDE_CLI:
            continue
        if any(isinstance(node, ast.Import) and any(a.name == "argparse" for a in node.names)
               for node in ast.walk(ast.parse(path.read_text()))):
            wrong.append(f"{name} imports argparse")
    assert wrong == [], "\n".join(wrong)
