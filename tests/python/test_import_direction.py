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

import aolab

ROOT = Path(__file__).resolve().parents[2]
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
    assert SOURCE / "bridge" / "jobs.py" in files  # the subpackage is walked too
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
    from aolab.reference import bridge_script
    assert bridge_script() == ROOT / "blender_addon" / "aolab_blender" / "batch.py"
