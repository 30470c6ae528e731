"""The import graph of a Python package, read from its source: which of its modules each
module imports, at any depth (inside functions and try blocks too), and what else the
imports take: another module's private names, and the modules bound to a name whose private
attributes a module then reads. Used by test_import_direction.py for `aolab` and the add-on.

A module is named by its dotted path (``aolab.study.compare``); a package by its own
(``aolab.study``, its ``__init__.py``). ``from P import X`` is an import of the module
``P.X`` when that is a module of the package, else of ``P`` (X a name defined in P).
Importing a package's submodule also runs the package's ``__init__``, but that edge is
Python's, not the module's: it is not counted, so a package ``__init__`` that imports its
submodules does not make a circle with each of them.
"""
from __future__ import annotations

import ast
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class Module:
    name: str
    is_package: bool
    imports: dict = field(default_factory=dict)   # target module -> first line importing it
    private: list = field(default_factory=list)   # "line: text" for each private name taken


def module_names(root: Path, package: str) -> dict[str, Path]:
    """Every module of the package whose folder is ``root``, by dotted name."""
    out = {}
    for path in sorted(root.rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join([package] + parts)] = path
    return out


def _absolute(node: ast.ImportFrom, module: str, is_package: bool) -> str:
    """The absolute module name of a ``from ... import`` (relative ones resolved)."""
    if node.level == 0:
        return node.module or ""
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    base = base[:len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _deepest(name: str, modules) -> str | None:
    """``name`` or its nearest parent that is a module of the package."""
    parts = name.split(".")
    while parts:
        candidate = ".".join(parts)
        if candidate in modules:
            return candidate
        parts.pop()
    return None


def read_module(name: str, path: Path, modules) -> Module:
    """The imports of one module of the package, and the private names it takes."""
    is_package = path.name == "__init__.py"
    found = Module(name, is_package)
    tree = ast.parse(path.read_text(), str(path))
    bound = {}   # local name -> module of the package it is bound to

    def add(target: str | None, line: int) -> None:
        if target is not None and target != name:
            found.imports.setdefault(target, line)

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                target = _deepest(alias.name, modules)
                add(target, node.lineno)
                if target is not None:
                    local = alias.asname or alias.name.split(".")[0]
                    bound[local] = target if alias.asname else alias.name.split(".")[0]
        elif isinstance(node, ast.ImportFrom):
            source = _absolute(node, name, is_package)
            for alias in node.names:
                sub = f"{source}.{alias.name}"
                if sub in modules:
                    add(sub, node.lineno)
                    bound[alias.asname or alias.name] = sub
                    continue
                target = _deepest(source, modules)
                add(target, node.lineno)
                if target is not None and alias.name.startswith("_") \
                        and not alias.name.startswith("__"):
                    found.private.append(f"{node.lineno}: from {source} import {alias.name}")
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.value.id in bound and node.attr.startswith("_") \
                and not node.attr.startswith("__") \
                and f"{bound[node.value.id]}.{node.attr}" not in modules:
            found.private.append(f"{node.lineno}: {node.value.id}.{node.attr}")
    return found


def import_graph(root: Path, package: str, extensions=()) -> dict[str, Module]:
    """Every module of the package at ``root`` with what it imports of the package.
    ``extensions`` names its compiled modules (``aolab._core``), which have no source here
    but are modules all the same: importing one is not taking a private name."""
    modules = module_names(root, package)
    known = set(modules) | set(extensions)
    return {name: read_module(name, path, known) for name, path in modules.items()}


def find_cycles(graph: dict[str, Module]) -> list[list[str]]:
    """The import circles of the graph: each strongly connected component of more than one
    module (Tarjan's algorithm), as its modules sorted."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph[v].imports:
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out
