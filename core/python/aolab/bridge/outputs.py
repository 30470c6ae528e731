"""The files the bridge's export writes for its --out
(blender_addon/aolab_blender/export/batch.py, run by `aolab reference` and `aolab mesh`), and
the check, before Blender renders anything, that none of them is the scene being exported
or another of them (files.check_distinct). Plain paths, no bpy: testable without Blender."""

from __future__ import annotations

import os
from pathlib import Path

from ..util import files
from . import mesh


def export_files(out: str, *, passes: list[str], mesh_only: bool = False) -> dict:
    """{what: path} of every file an export to ``out`` writes: the .mesh and its .mesh.json
    with ``mesh_only``; else the merged EXR, its sidecar (``<stem>.json``, as the core
    names it) and, with the ``mesh`` pass, ``<stem>.mesh`` and its .mesh.json."""
    if mesh_only:
        return {"--out": out, "the mesh's JSON": mesh.json_path(out)}
    found = {"--out": out}
    if Path(out).name not in ("", ".", ".."):
        found["the sidecar"] = Path(out).with_suffix(".json")
    if "mesh" in passes:
        stem_mesh = os.path.splitext(out)[0] + ".mesh"
        found["the mesh"] = stem_mesh
        found["the mesh's JSON"] = mesh.json_path(stem_mesh)
    return found


def check_export(out: str, scene_files: dict, *, passes: list[str], mesh_only: bool = False,
                 peers: bool = False) -> None:
    """A ValueError naming both paths when a file the export writes is one of the scene's
    files (``scene_files``: {what: path}, e.g. the open .blend) or another of its files.
    With ``peers`` --out is a folder: it must not be a scene file."""
    writes = {"--out": out} if peers else export_files(out, passes=passes, mesh_only=mesh_only)
    files.check_distinct(reads=scene_files, writes=writes)
