"""``aolab mesh``: each scene's triangles as Cycles renders them, without a render, cached
(aolab.cycles)."""

from __future__ import annotations

from ..cycles.run import export_meshes
from .options import add_follow_symlinks_option
from .reference import delivery


def add_parser(sub):
    ms = sub.add_parser("mesh", help="export each scene's triangles as Cycles renders them "
                        "(no render; cached)",
                        description="Exports the world-space triangles of every object Cycles' "
                        "AO sees (modifiers, instances and visibility as for render) of each "
                        "scene (a .blend, a build script .py, or a reference_scenes/<name> "
                        "folder) with Blender in the background, without rendering, into "
                        "reference.mesh + reference.mesh.json in the reference cache. A scene "
                        "folder's manifest gives the resolution and camera, so the scene_hash "
                        "matches its reference.json (docs/blender_bridge.md).")
    ms.add_argument("scenes", nargs="+", metavar="SCENE")
    ms.add_argument("--out", help="also copy reference.mesh/.mesh.json here (one folder per "
                    "scene when several)")
    ms.add_argument("--resolution", help="WxH, overriding the scene's (it enters the "
                    "scene_hash, as for a reference)")
    ms.add_argument("--camera", help="camera object (default: manifest, else the scene camera)")
    ms.add_argument("--cache", help="cache folder (default $AOLAB_CACHE or "
                    "~/.cache/aolab/references)")
    ms.add_argument("--force", action="store_true", help="export even if cached")
    ms.add_argument("--quiet", action="store_true", help="no progress bar")
    add_follow_symlinks_option(ms)
    return ms


def run(args) -> int:
    return export_meshes(args.scenes, delivery(args), resolution=args.resolution,
                         camera=args.camera, follow_symlinks=args.follow_symlinks)
