"""The add-on's modules import one way (docs/blender_addon.md, "Modules"): no circle among the
modules of blender_addon/aolab_blender, and no module takes another's private (`_name`) name.
Read from the source (every import statement parsed, at any depth: inside functions too), so
that no Blender is needed. The checker itself is tested first, on small packages written for
the test, so that a pass on the add-on means something."""
import ast
import json
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ADDON = ROOT / "blender_addon" / "aolab_blender"
BLENDER = shutil.which("blender")
#: The add-on's modules, lowest first, as docs/blender_addon.md ("Modules") lists them: each
#: imports only modules before it here. "aolab_blender" is its __init__.py.
ORDER = ("state", "compat", "images", "preferences", "hooks", "scene_record", "mesh_export",
         "export", "peers", "batch", "properties", "inputs", "live", "operators", "ui",
         "aolab_blender")


def module_files(package_dir: Path, package_name: str) -> dict[str, Path]:
    """Every module of the package in `package_dir` by its dotted name (the package's
    __init__.py, and a subpackage's, by the package's own name)."""
    out = {}
    for path in sorted(Path(package_dir).rglob("*.py")):
        parts = list(path.relative_to(package_dir).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join([package_name, *parts])] = path
    return out


def _resolve(node: ast.ImportFrom, module: str, is_package: bool) -> str:
    """The absolute name `from ... import` reads from (relative levels resolved)."""
    if node.level == 0:
        return node.module or ""
    base = module.split(".")[:len(module.split(".")) + is_package - node.level]
    return ".".join(base + ([node.module] if node.module else []))


def _within(name: str, modules) -> str | None:
    """`name`, or the nearest package above it, when that is a module of the package."""
    parts = name.split(".")
    while parts and ".".join(parts) not in modules:
        parts.pop()
    return ".".join(parts) or None


def _is_private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def read_imports(package_dir: Path, package_name: str) -> tuple[dict, dict]:
    """({module: set of modules of the package it imports}, {module: ["line: what", ...]
    private names of other modules it takes}). Covered: `import p.x`, `import p.x as y`,
    `from . import x`, `from .x import y`, `from p.x import y`, `from p import x`, wherever
    they stand; private: `from .x import _y` and `x._y` where x names a module of the
    package (a private module itself, `from . import _x`, is no private name of another)."""
    files = module_files(package_dir, package_name)
    graph, private = {}, {}
    for name, path in files.items():
        is_package = path.name == "__init__.py"
        imports, taken, bound = set(), [], {}   # bound: local name -> module it names
        tree = ast.parse(path.read_text(), str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    target = _within(alias.name, files)
                    if target is None:
                        continue
                    imports.add(target)
                    top = alias.name.split(".")[0]
                    bound[alias.asname or top] = target if alias.asname else top
            elif isinstance(node, ast.ImportFrom):
                source = _resolve(node, name, is_package)
                for alias in node.names:
                    submodule = f"{source}.{alias.name}"
                    if submodule in files:
                        imports.add(submodule)
                        bound[alias.asname or alias.name] = submodule
                        continue
                    target = _within(source, files)
                    if target is None:
                        continue
                    imports.add(target)
                    if _is_private(alias.name):
                        taken.append(f"{node.lineno}: from {source} import {alias.name}")
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                    and node.value.id in bound and _is_private(node.attr) \
                    and f"{bound[node.value.id]}.{node.attr}" not in files:
                taken.append(f"{node.lineno}: {node.value.id}.{node.attr}")
        imports.discard(name)
        graph[name], private[name] = imports, taken
    return graph, private


def import_graph(package_dir: Path, package_name: str) -> dict[str, set[str]]:
    """Every module of the package with the modules of the package it imports."""
    return read_imports(package_dir, package_name)[0]


def private_names(package_dir: Path, package_name: str) -> list[str]:
    """`module:line: what` for every private name a module takes from another."""
    return [f"{m}:{t}" for m, found in read_imports(package_dir, package_name)[1].items()
            for t in found]


def find_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import circles: every strongly connected component of more than one module
    (Tarjan's algorithm), its modules sorted; the components in the order found."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while not component or component[-1] != v:
                component.append(stack.pop())
                on_stack.discard(component[-1])
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def reachable(graph: dict[str, set[str]], start: str) -> set[str]:
    """The modules `start` imports, directly or through others."""
    seen, todo = set(), [start]
    while todo:
        for w in graph.get(todo.pop(), ()):
            if w not in seen:
                seen.add(w)
                todo.append(w)
    return seen


def package(tmp_path: Path, files: dict[str, str]) -> Path:
    root = tmp_path / "pkg"
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)
    return root


# ---- the checker, on packages written for the test ----

def test_the_graph_has_every_kind_of_import(tmp_path):
    root = package(tmp_path, {
        "__init__.py": "from . import a\n",
        "a.py": "import os\nimport pkg.b\nfrom .c import thing\n",
        "b.py": "from pkg.c import thing as other\nfrom pkg import d\nimport numpy as np\n",
        "c.py": "def f():\n    from . import d\n    if True:\n        import pkg.sub.e as e\n",
        "d.py": "try:\n    from .sub.e import x\nexcept ImportError:\n    pass\n",
        "sub/__init__.py": "from ..a import y\n",
        "sub/e.py": "from .. import d, a\nfrom . import f\n",
        "sub/f.py": "x = 'import pkg.a'\n",
    })
    assert import_graph(root, "pkg") == {
        "pkg": {"pkg.a"}, "pkg.a": {"pkg.b", "pkg.c"}, "pkg.b": {"pkg.c", "pkg.d"},
        "pkg.c": {"pkg.d", "pkg.sub.e"}, "pkg.d": {"pkg.sub.e"}, "pkg.sub": {"pkg.a"},
        "pkg.sub.e": {"pkg.d", "pkg.a", "pkg.sub.f"}, "pkg.sub.f": set()}


def test_a_circle_is_found_at_any_depth(tmp_path):
    """export <-> mesh_export as the add-on had it: each side imports the other inside a
    function; and a longer circle through three modules."""
    root = package(tmp_path, {
        "__init__.py": "",
        "export.py": "def f():\n    from . import mesh_export\n",
        "mesh_export.py": "def g():\n    from . import export  # it imports this module\n",
        "operators.py": "from . import properties\n",
        "live.py": "from . import operators\n",
        "properties.py": "def _live():\n    from . import live\n",
        "ui.py": "from . import operators\n",
    })
    graph = import_graph(root, "pkg")
    assert find_cycles(graph) == [["pkg.export", "pkg.mesh_export"],
                                  ["pkg.live", "pkg.operators", "pkg.properties"]]
    graph["pkg.properties"].clear()
    assert find_cycles(graph) == [["pkg.export", "pkg.mesh_export"]]
    graph["pkg.mesh_export"].clear()
    assert find_cycles(graph) == []
    assert reachable(graph, "pkg.ui") == {"pkg.operators", "pkg.properties"}


def test_private_names_are_found(tmp_path):
    root = package(tmp_path, {
        "__init__.py": "",
        "export.py": "_common_settings = 1\n",
        "peers.py": "from .export import (render_to,\n    _common_settings)\n",
        "live.py": "from . import export, _core\nimport pkg.export as ex\n"
                   "x = export._common_settings\ny = ex._hidden\nz = export.__name__\n"
                   "w = _core.value\n",
        "_core.py": "",
        "own.py": "_mine = 1\nprint(_mine)\n",
    })
    assert private_names(root, "pkg") == [
        "pkg.live:3: export._common_settings", "pkg.live:4: ex._hidden",
        "pkg.peers:1: from pkg.export import _common_settings"]


# ---- the add-on ----

def test_the_addon_has_no_import_circle():
    graph = import_graph(ADDON, "aolab_blender")
    assert {"aolab_blender.export", "aolab_blender.live"} <= set(graph)
    cycles = find_cycles(graph)
    assert cycles == [], "import circles in the add-on:\n" + "\n".join(map(str, cycles))


def test_no_addon_module_takes_another_modules_private_name():
    found = private_names(ADDON, "aolab_blender")
    assert found == [], "private names taken from another module:\n" + "\n".join(found)


def test_every_addon_module_imports_only_modules_below_it():
    graph = import_graph(ADDON, "aolab_blender")
    rank = {("aolab_blender" if m == "aolab_blender" else f"aolab_blender.{m}"): i
            for i, m in enumerate(ORDER)}
    assert set(graph) == set(rank), "place every module of the add-on in ORDER (and the docs)"
    wrong = [f"{m} imports {t}" for m, targets in graph.items() for t in sorted(targets)
             if rank[t] > rank[m]]
    assert wrong == [], "imports against the order of ORDER:\n" + "\n".join(wrong)


def test_the_addon_modules_stand_where_the_docs_say():
    """scene_record below export, mesh_export and peers; inputs below operators and live;
    properties reaches Live only through hooks, which imports nothing of the add-on."""
    graph = import_graph(ADDON, "aolab_blender")

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
