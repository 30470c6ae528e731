"""Exporting a G-buffer and rendering the Cycles AO reference of a scene's camera (bpy).

One call, export_reference(), makes two Cycles CPU renders at filter_width 0.01 (pixel-centre
values: one ray position per pixel; docs/blender_facts.md, "Pixel filter"):
1. the G-buffer: only the passes asked for (Depth always; Normal, DiffCol, Emit, Vector as
   needed; the Vector pass becomes AO Lab's motion vectors, bridge/motion.py),
   gbuffer_samples samples (depth comes from sample 0; at this filter width normals and
   colours are the pixel-centre values, so 1 sample is exact);
2. the reference: the AO pass alone at `spp` samples, adaptive sampling off (it judges noise
   on Combined and stops the AO pass early), denoising off, max_bounces 0, AO distance R,
   shadow_terminator_geometry_offset 0 on every object, lights hidden, DOF and motion blur off.
It merges both into one EXR (normals converted to view space) with a sidecar JSON, and with
the `mesh` pass also writes the scene's triangles as rendered beside it (mesh.py); it
restores every setting it touched, whether it succeeds, fails or is cancelled. The camera
record, content hash and errors it shares with mesh.py and peers.py are
scene_record.py's.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
import time

import bpy

from aolab.util import files
from aolab.bridge import exr, motion
from aolab.bridge.constants import BACKGROUND_DEPTH, BRIDGE_VERSION
from aolab.bridge.passes import GEOMETRY_PASSES, PASSES

from . import mesh
from .scene_record import (BridgeError, Cancelled, camera_record, content_hash,
                           evaluation_settings, scene_camera)
from .state import SettingsRestorer

FILTER_WIDTH = 0.01        # the minimum: one ray position per pixel, no mixing across edges


def _common_settings(rs: SettingsRestorer, scene, view_layer, cam, radius: float) -> None:
    r, c = scene.render, scene.cycles
    evaluation_settings(rs, scene, cam)
    for attr, value in [("use_border", False), ("use_compositing", False),
                        ("use_sequencer", False), ("use_motion_blur", False),
                        ("use_single_layer", True),
                        ("use_file_extension", True)]:
        rs.set(r, attr, value)
    rs.set(r.image_settings, "file_format", "OPEN_EXR_MULTILAYER")
    rs.set(r.image_settings, "color_depth", "32")
    rs.set(r.image_settings, "exr_codec", "ZIP")
    for attr, value in [("use_adaptive_sampling", False), ("use_denoising", False),
                        ("max_bounces", 0), ("filter_width", FILTER_WIDTH), ("seed", 0),
                        ("use_animated_seed", False), ("sample_offset", 0),
                        ("use_layer_samples", "IGNORE")]:
        rs.set(c, attr, value)
    rs.set(cam.data.dof, "use_dof", False)
    for obj in scene.objects:
        rs.set(obj.cycles, "shadow_terminator_geometry_offset", 0.0)
    if scene.world is None:
        world = bpy.data.worlds.new("AOLab temporary world")
        rs.set(scene, "world", world)
        rs.on_restore(lambda: bpy.data.worlds.remove(world))
    rs.set(scene.world.light_settings, "distance", radius)
    for attr in view_layer.cycles.bl_rna.properties.keys():
        if attr.startswith("use_pass_") or attr == "denoising_store_passes":
            rs.set(view_layer.cycles, attr, False)


def enable_only_passes(rs: SettingsRestorer, view_layer, wanted: set[str]) -> None:
    """Turns on the view-layer passes in `wanted` (property names) and off every other."""
    for attr in view_layer.bl_rna.properties.keys():
        if attr.startswith("use_pass_") and attr != "use_pass_combined":
            rs.set(view_layer, attr, attr in wanted)


RENDER_SLOT_NAME = "AO Lab"


def _keep_render_result(rs: SettingsRestorer) -> None:
    """Renders replace the pixels of the active slot of the "Render Result" image. If the user
    has one, ours go to a slot of its own ("AO Lab", created once and reused) and the user's
    active slot is restored; if not, the image our render creates is removed afterwards."""
    image = next((im for im in bpy.data.images if im.type == "RENDER_RESULT"), None)
    if image is None:
        def remove_created():
            for im in [im for im in bpy.data.images if im.type == "RENDER_RESULT"]:
                bpy.data.images.remove(im)
        rs.on_restore(remove_created)
        return
    slots = image.render_slots
    index = next((i for i, slot in enumerate(slots) if slot.name == RENDER_SLOT_NAME), None)
    if index is None:
        slots.new(name=RENDER_SLOT_NAME)
        index = len(slots) - 1
    rs.set(slots, "active_index", index)


def render_to(rs: SettingsRestorer, scene, path: str) -> float:
    """Renders the scene's frame to the still image `path`; the seconds it took."""
    rs.set(scene.render, "filepath", path)
    t0 = time.perf_counter()
    result = bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - t0
    if "FINISHED" not in result or not os.path.exists(path):
        raise BridgeError(f"Cycles did not write {path} (render returned {set(result)})")
    return seconds


@contextlib.contextmanager
def render_session(scene, cam, radius: float, out_dir: str, prefix: str, checkpoint):
    """Yields (temporary folder in out_dir, SettingsRestorer) with the reference's render
    settings applied (the "prepare" stage); on exit every setting is restored and the folder
    removed, whatever happened."""
    view_layer = bpy.context.view_layer
    with tempfile.TemporaryDirectory(prefix=prefix, dir=out_dir) as tmp, \
            SettingsRestorer() as rs:
        # Registered first, so it runs last: re-evaluate with the restored settings.
        rs.on_restore(view_layer.update)
        checkpoint("prepare")
        _keep_render_result(rs)
        _common_settings(rs, scene, view_layer, cam, radius)
        view_layer.update()  # matrix_world of objects moved since the last evaluation
        yield tmp, rs


def motion_layer(channels: dict, depth):
    """AO Lab's motion (H, W, 2) from the G-buffer render's Vector pass (written with motion
    blur off, as _common_settings has it: with motion blur on it holds zeros), or None
    without one."""
    vector = exr.find_pass(channels, "Vector", PASSES["motion"][2])
    if vector is None or depth is None:
        return None
    return motion.from_cycles_vector(vector, depth, BACKGROUND_DEPTH)


def export_reference(scene, out_exr: str, *, radius: float, spp: int, passes: list[str],
                     gbuffer_samples: int = 1, camera_name: str | None = None,
                     cancel=None, report=print, extra: dict | None = None) -> dict:
    """Renders the G-buffer `passes` and the AO reference of `scene` into `out_exr` (+ the
    sidecar `<stem>.json`) and returns the sidecar. `cancel()` is polled between stages
    (Cancelled is raised); `report(stage)` announces each stage. Settings are restored in
    every case."""
    if not (math.isfinite(radius) and radius > 0):
        raise BridgeError(f"radius must be a finite number > 0 (the AO distance in scene "
                          f"units), got {radius}")
    if spp < 1 or gbuffer_samples < 1:
        raise BridgeError(f"spp and gbuffer_samples must be >= 1, got {spp}, {gbuffer_samples}")
    known = list(PASSES) + list(GEOMETRY_PASSES)
    unknown = [p for p in passes if p not in known]
    if unknown:
        raise BridgeError(f"passes must be among {', '.join(known)}, got {unknown}")
    cam = scene_camera(scene, camera_name)
    view_layer = bpy.context.view_layer

    def checkpoint(stage: str):
        if cancel is not None and cancel():
            raise Cancelled()
        report(stage)

    out_dir = os.path.dirname(os.path.abspath(out_exr))
    os.makedirs(out_dir, exist_ok=True)
    with render_session(scene, cam, radius, out_dir, "aolab-render-", checkpoint) as (tmp, rs):
        record = camera_record(scene, cam)
        scene_hash = content_hash(scene, cam)

        checkpoint("gbuffer")
        rs.set(scene.cycles, "samples", gbuffer_samples)
        enable_only_passes(rs, view_layer, {PASSES[p][0] for p in passes if p in PASSES})
        gbuffer_path = os.path.join(tmp, "gbuffer.exr")
        t_gbuffer = render_to(rs, scene, gbuffer_path)

        checkpoint("reference")
        rs.set(scene.cycles, "samples", spp)
        enable_only_passes(rs, view_layer, {"use_pass_ambient_occlusion"})
        for obj in scene.objects:  # AO alone: no light is simulated
            if obj.type == "LIGHT":
                rs.set(obj, "hide_render", True)
        reference_path = os.path.join(tmp, "reference.exr")
        t_reference = render_to(rs, scene, reference_path)

        mesh_file = None
        if "mesh" in passes:
            checkpoint("mesh")
            mesh_path = os.path.splitext(out_exr)[0] + ".mesh"
            mesh.write_scene_mesh(rs, scene, view_layer, mesh_path, record, scene_hash, extra)
            mesh_file = os.path.basename(mesh_path)

        checkpoint("merge")
        g = exr.read_channels(gbuffer_path)
        a = exr.read_channels(reference_path)
        layers = [("Depth", exr.find_pass(g, "Depth", ("Z",)), "float")]
        if "normal" in passes:
            n = exr.find_pass(g, "Normal", ("X", "Y", "Z"))
            normal = exr.world_to_view_normals(n, record["camera_to_world"])
            layers.append(("Normal", normal, "half"))
        ao = exr.find_pass(a, "AO", ("R", "G", "B"))
        depth = layers[0][1]
        if ao is not None and depth is not None:
            # Cycles writes AO 0 where nothing is hit; AO Lab's convention is 1 there
            # (docs/conventions.md), so images and unmasked metrics agree with the methods.
            ao[~(depth[..., 0] < BACKGROUND_DEPTH)] = 1.0
        layers.append(("AO", ao, "half"))
        if "diffuse_color" in passes:
            layers.append(("DiffCol", exr.find_pass(g, "DiffCol", ("R", "G", "B")), "half"))
        if "emission" in passes:
            layers.append(("Emit", exr.find_pass(g, "Emit", ("R", "G", "B")), "half"))
        if "motion" in passes:
            layers.append(("Motion", motion_layer(g, depth), "float"))
        missing = [name for name, data, _ in layers if data is None]
        if missing:
            raise BridgeError(f"the render lacks the passes {missing}; channels: "
                              f"{sorted(g) + sorted(a)}")

        sidecar = {
            **record,
            "ao_distance": radius,
            "samples": spp,
            "background_depth": BACKGROUND_DEPTH,
            "normal_space": "view",
            "passes": passes + ["ao"],
            "render": {"engine": "CYCLES", "device": "CPU", "reference_samples": spp,
                       "gbuffer_samples": gbuffer_samples, "use_adaptive_sampling": False,
                       "use_denoising": False, "max_bounces": 0, "filter_width": FILTER_WIDTH,
                       "shadow_terminator_geometry_offset": 0.0, "seed": 0,
                       "lights_hidden": True, "dof": False, "motion_blur": False,
                       "ao_distance": radius},
            "render_time": {"gbuffer": t_gbuffer, "reference": t_reference},
            "blender_version": bpy.app.version_string,
            "scene": scene.name,
            "view_layer": view_layer.name,
            "scene_hash": scene_hash,
            "bridge_version": BRIDGE_VERSION,
            **({"mesh_file": mesh_file} if mesh_file else {}),
            # Cycles' Vector pass looks one frame back, whatever the sequence's step
            # (docs/blender_facts.md, "The Vector pass").
            **({"motion_previous_frame": scene.frame_current - 1} if "motion" in passes
               else {}),
            **(extra or {}),
        }
        # The EXR and its sidecar go into place together: a full disk leaves neither half.
        sidecar_path = os.path.splitext(out_exr)[0] + ".json"
        files.write_together([
            (out_exr, exr.encode_multilayer(out_exr, layers, view_layer=view_layer.name)),
            (sidecar_path, json.dumps(sidecar, indent=1).encode())])
        report("done")
        return sidecar
