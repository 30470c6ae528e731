"""The scene's triangles as Cycles renders them, in world space: the `mesh` pass (bpy).

export_mesh() writes `<stem>.mesh` + `<stem>.mesh.json` (aolab.bridge.mesh; the format is in
docs/file_formats.md) without rendering; reference.export_reference() calls write_scene_mesh()
when its passes include "mesh".

Geometry as rendered, not as the viewport shows it: Python's evaluated depsgraph is the
viewport's (Blender 3.4 offers no render-mode depsgraph to Python outside a render engine),
so for the evaluation the viewport settings are made equal to the render ones — modifiers'
show_viewport, Subdivision/Multires levels, objects' and collections' hide_viewport, the
eye icons, instancer display, particle display amounts, curve and metaball resolutions —
and restored exactly afterwards (SettingsRestorer). Measured in Blender 3.4:
docs/blender_bridge.md, "Scene geometry".
"""

from __future__ import annotations

import os
import time

import bpy
import numpy as np

from aolab.bridge import mesh as mesh_file
from aolab.bridge.constants import BRIDGE_VERSION

from . import compat
from .scene_record import camera_record, content_hash, evaluation_settings, scene_camera
from .state import SettingsRestorer

#: Object types that can have faces. In Blender 3.4 the faces of curves, text, surfaces and
#: metaballs reach the depsgraph as a mesh instance of the object itself (instance true,
#: instancer its own name), beside the object entry, whose data is not a mesh: only MESH
#: entries are exported, as Cycles exports only mesh data, so nothing is counted twice.
SURFACE_TYPES = ("MESH", "CURVE", "SURFACE", "FONT", "META")
#: Geometry Cycles renders as something other than triangles (curves, points, volumes).
NON_TRIANGLE_TYPES = {"CURVES": "hair curves, rendered by Cycles as curves, not triangles",
                      "POINTCLOUD": "a point cloud, rendered by Cycles as points",
                      "VOLUME": "a volume, which Cycles' AO rays do not stop at"}


def export_mesh(scene, out_mesh: str, camera_name: str | None = None, report=print,
                extra: dict | None = None) -> dict:
    """Writes the evaluated world-space triangles of `scene` to `out_mesh` (+ .mesh.json)
    with the camera record and scene_hash a reference of this camera would have; returns the
    JSON. Every setting is restored, whatever happens."""
    cam = scene_camera(scene, camera_name)
    view_layer = bpy.context.view_layer
    os.makedirs(os.path.dirname(os.path.abspath(out_mesh)), exist_ok=True)
    with SettingsRestorer() as rs:
        # Registered first, so it runs last: re-evaluate with the restored settings.
        rs.on_restore(view_layer.update)
        report("prepare")
        evaluation_settings(rs, scene, cam)
        view_layer.update()
        record = camera_record(scene, cam)
        scene_hash = content_hash(scene, cam)
        report("mesh")
        info = write_scene_mesh(rs, scene, view_layer, out_mesh, record, scene_hash, extra)
    report("done")
    return info


def write_scene_mesh(rs: SettingsRestorer, scene, view_layer, out_mesh: str, record: dict,
                     scene_hash: str, extra: dict | None = None) -> dict:
    """Evaluates the scene as for render (settings changed through `rs`, restored by its
    owner) and writes its triangles; `record` and `scene_hash` are the reference's, taken
    before anything here changes the evaluation."""
    t0 = time.perf_counter()
    _viewport_as_render(rs, view_layer)
    view_layer.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    vertices, triangles, objects, skipped = _triangles(depsgraph)
    skipped += _not_rendered(scene, depsgraph)
    info = {"space": "world", "scene_hash": scene_hash,
            "camera_to_world": record["camera_to_world"],
            "width": record["width"], "height": record["height"],
            "camera": record["camera"]["name"], "scene": scene.name,
            "view_layer": view_layer.name, "objects": objects, "skipped": skipped,
            "blender_version": bpy.app.version_string, "bridge_version": BRIDGE_VERSION,
            "export_seconds": time.perf_counter() - t0, **(extra or {})}
    return mesh_file.write_mesh(out_mesh, vertices, triangles, info)


def _layer_collections(layer_collection):
    yield layer_collection
    for child in layer_collection.children:
        yield from _layer_collections(child)


def _viewport_as_render(rs: SettingsRestorer, view_layer) -> None:
    """Makes every viewport setting that changes evaluated geometry or visibility equal to
    its render counterpart. Linked (library) data cannot be changed and is left as it is."""
    def local(idb):
        return idb.library is None
    for obj in filter(local, bpy.data.objects):
        rs.set(obj, "hide_viewport", obj.hide_render)
        rs.set(obj, "show_instancer_for_viewport", obj.show_instancer_for_render)
        for mod in obj.modifiers:
            rs.set(mod, "show_viewport", mod.show_render)
            if mod.type in ("SUBSURF", "MULTIRES"):
                rs.set(mod, "levels", mod.render_levels)
    for coll in filter(local, bpy.data.collections):
        rs.set(coll, "hide_viewport", coll.hide_render)
    for lc in _layer_collections(view_layer.layer_collection):
        rs.set(lc, "hide_viewport", False)   # the layer's eye icon: renders ignore it
    for obj in view_layer.objects:           # the object's eye icon, also ignored by renders
        if obj.hide_get(view_layer=view_layer):
            obj.hide_set(False, view_layer=view_layer)
            rs.on_restore(lambda obj=obj: obj.hide_set(True, view_layer=view_layer))
    for part in filter(local, bpy.data.particles):
        rs.set(part, "display_percentage", 100)
        rs.set(part, compat.PARTICLE_VIEWPORT_CHILDREN, part.rendered_child_count)
    for curve in filter(local, bpy.data.curves):
        if curve.render_resolution_u > 0:    # 0: the render uses resolution_u
            rs.set(curve, "resolution_u", curve.render_resolution_u)
        if curve.render_resolution_v > 0:
            rs.set(curve, "resolution_v", curve.render_resolution_v)
    for ball in filter(local, bpy.data.metaballs):
        rs.set(ball, "resolution", ball.render_resolution)


def _triangles(depsgraph):
    """(vertices float32 (V, 3), triangles uint32 (T, 3), objects, skipped) of every
    object instance Cycles would trace AO rays against, one after another."""
    vertices, triangles, objects, skipped = [], [], [], {}
    empty = set()                # names with an entry without faces
    n_vertices = n_triangles = 0
    for inst in depsgraph.object_instances:
        obj = inst.object
        if not inst.show_self:   # an instancer that is not shown itself (Cycles skips it)
            if obj.type == "MESH" and not inst.is_instance:
                skipped.setdefault(obj.name, "an instancer whose own faces are not rendered "
                                   "(show_instancer_for_render off)")
            continue
        if obj.type in NON_TRIANGLE_TYPES:
            skipped.setdefault(obj.name, NON_TRIANGLE_TYPES[obj.type])
            continue
        if obj.type != "MESH":
            continue             # lights, cameras, empties; curves... come as mesh instances
        # Cycles keeps the shadow-ray visibility of both the instance and its instancer.
        for owner in (obj, inst.parent) if inst.is_instance else (obj,):
            if not owner.visible_shadow:
                skipped.setdefault(obj.name, f"{owner.name} has Ray Visibility > Shadow off "
                                   "(visible_shadow): Cycles' AO rays ignore it")
                break
        else:
            co, tri = _object_triangles(obj, inst.matrix_world)
            if not len(tri):
                empty.add(obj.name)
                continue
            objects.append({"name": obj.name, "data": _data_name(obj),
                            "first_triangle": n_triangles, "triangles": len(tri),
                            "instance": bool(inst.is_instance),
                            **({"instancer": inst.parent.name} if inst.is_instance else {})})
            vertices.append(co)
            triangles.append(tri + n_vertices)
            n_vertices += len(co)
            n_triangles += len(tri)
    for name in sorted(empty - {o["name"] for o in objects}):
        skipped.setdefault(name, "no faces (only vertices or edges)")
    v = np.concatenate(vertices) if vertices else np.zeros((0, 3), np.float32)
    t = np.concatenate(triangles) if triangles else np.zeros((0, 3), np.uint32)
    return v, t, objects, [{"name": k, "why": w} for k, w in skipped.items()]


def _data_name(obj) -> str:
    data = obj.original.data if obj.original is not None else obj.data
    return data.name if data is not None else ""


def _object_triangles(obj, matrix_world) -> tuple[np.ndarray, np.ndarray]:
    """World-space vertices (float32, transformed in float64) and loop triangles (uint32) of
    an evaluated object; triangles keep their front side under a mirroring transform."""
    me = obj.to_mesh()
    try:
        if me is None:
            return np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32)
        me.calc_loop_triangles()
        co = np.empty(len(me.vertices) * 3, np.float32)
        me.vertices.foreach_get("co", co)
        tri = np.empty(len(me.loop_triangles) * 3, np.uint32)
        me.loop_triangles.foreach_get("vertices", tri)
    finally:
        obj.to_mesh_clear()
    m = np.array(matrix_world, dtype=np.float64)
    world = co.reshape(-1, 3).astype(np.float64) @ m[:3, :3].T + m[:3, 3]
    tri = tri.reshape(-1, 3)
    if np.linalg.det(m[:3, :3]) < 0:   # a mirror reverses the winding seen from the front
        tri = tri[:, ::-1]
    return world.astype(np.float32), np.ascontiguousarray(tri)


def _not_rendered(scene, depsgraph) -> list[dict]:
    """The scene's surface objects that the render does not evaluate at all, and why (an
    object of an excluded collection that is rendered through collection instances is not
    listed: it is exported as those instances)."""
    evaluated = {inst.object.name for inst in depsgraph.object_instances}
    out = []
    for obj in sorted(scene.objects, key=lambda o: o.name):
        if obj.type not in SURFACE_TYPES or obj.name in evaluated:
            continue
        why = ("hidden from render (Disable in Renders, hide_render)" if obj.hide_render else
               "not rendered: a collection holding it is disabled in renders or excluded "
               "from the view layer")
        out.append({"name": obj.name, "why": why})
    return out
