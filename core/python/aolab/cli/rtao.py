"""``aolab rtao``: ray-traced AO of a G-buffer against its scene's triangles."""

from __future__ import annotations

import time
from pathlib import Path
from types import SimpleNamespace

import aolab

from ..raytracing import DEFAULT_RAYS as RTAO_DEFAULT_RAYS
from ..scenes import check_confined
from ..util import files
from ..util.arguments import int_option
from .common import (check_outputs, gbuffer_files, input_options, load_input, mesh_files,
                     output_stem, write_result)
from .options import add_follow_symlinks_option


def add_parser(sub):
    rt = sub.add_parser(
        "rtao", help="ray-traced AO of a G-buffer against its scene's triangles (Embree)",
        description="Cycles' AO integral traced on the CPU with Embree from every pixel of a "
        "G-buffer: stratified cosine-weighted rays, a hit within R occluding "
        "(docs/methods/rtao.md). The triangles are the mesh written beside the G-buffer "
        "(`aolab mesh`, or `aolab reference --passes depth,normal,mesh`), or --mesh.")
    rt.add_argument("input", help="G-buffer .exr (with sidecar), a reference_scenes/<name> "
                    "folder, or analytic:NAME (its planes as triangles)")
    input_options(rt, settings=False)
    rt.add_argument("--mesh", help="the scene's .mesh file (default: <stem>.mesh beside the "
                    "G-buffer); its scene hash must equal the G-buffer's")
    add_follow_symlinks_option(rt)
    rt.add_argument("--allow-unknown-scene", action="store_true",
                    help="trace a mesh whose scene cannot be checked: the mesh or the "
                    "G-buffer carries no scene hash (an analytic scene, a .mesh without its "
                    ".mesh.json); a hash that differs is refused all the same")
    rt.add_argument("--rays", type=int_option("--rays", 1, 65536), default=RTAO_DEFAULT_RAYS,
                    help=f"rays per pixel, 1 to 65536 (default {RTAO_DEFAULT_RAYS}, the "
                    "reference's samples)")
    rt.add_argument("--seed", type=int_option("--seed", 0, 2**31 - 1), default=0,
                    help="seed of the per-pixel jitter, 0 to 2^31 - 1 (default 0)")
    rt.add_argument("--out", help="output path without extension: writes OUT.exr and OUT.png "
                    "(default rtao_ao in the current folder)")
    rt.add_argument("--json", help="also write the result (timing, metrics) to this JSON file "
                    "(never an input, its sidecar or mesh, or an --out file: refused before "
                    "any work)")
    return rt


def run(args) -> int:
    """aolab rtao: ray-traced AO of a G-buffer against its scene's triangles."""
    spec = args.input
    if not spec.startswith("analytic:") and Path(spec).is_dir():
        check_confined(Path(spec), args.follow_symlinks)   # a reference_scenes/<name> folder
        spec = str(Path(spec) / "reference.exr")
    out = output_stem(args.out, "rtao")
    check_outputs(out, args.json, {**gbuffer_files(spec), **_mesh_files(spec, args.mesh)})
    g, radius = load_input(spec, args.radius, args.width, args.height)
    unknown = args.allow_unknown_scene
    if args.mesh:
        mesh = aolab.load_mesh(files.regular_file(args.mesh, "mesh"))
    elif spec.startswith("analytic:"):   # the scene's own planes, made here
        name = spec.split(":", 1)[1]
        mesh = SimpleNamespace(info={})
        mesh.vertices, mesh.triangles = aolab.analytic_scene_mesh(name)
    else:
        mesh = aolab.mesh_for_gbuffer(g, allow_unknown_scene=unknown)
    scene = aolab.ray_scene(mesh, g, threads=args.threads, allow_unknown_scene=unknown)
    t0 = time.perf_counter()
    ao = aolab.rtao(g, scene, radius=radius, rays=args.rays, seed=args.seed,
                    threads=args.threads, allow_unknown_scene=unknown)
    elapsed = time.perf_counter() - t0
    result = {"method": "rtao", "input": args.input, "width": g.width, "height": g.height,
              "radius": radius, "rays": args.rays, "seed": args.seed, "threads": args.threads,
              "triangles": scene.triangles, "build_seconds": scene.build_seconds,
              "seconds": elapsed}
    write_result(g, ao, out, result, args.json,
                 f"rtao: {g.width}x{g.height}, radius {radius:g}, {args.rays} rays per pixel, "
                 f"{scene.triangles} triangles: BVH {scene.build_seconds * 1000:.1f} ms, rays "
                 f"{elapsed * 1000:.1f} ms")
    return 0


def _mesh_files(spec: str, mesh: str | None) -> dict:
    """The mesh rtao reads: --mesh, else ``<stem>.mesh`` beside the G-buffer (as
    aolab.mesh_for_gbuffer finds it), each with its .mesh.json."""
    if mesh:
        return mesh_files(mesh, "--mesh")
    if spec.startswith("analytic:"):
        return {}
    return mesh_files(Path(spec).with_suffix(".mesh"), "the input's mesh")
