"""The scene record (bpy): what a reference, its mesh and its peers all record of the scene
and check before they render, so that reference.py, mesh.py and peers.py share it from
below instead of importing each other.

- scene_camera(): the camera to render from, or BridgeError saying what the user can fix;
- camera_record(): the camera, its world matrix and its intrinsics at the output size;
- content_hash(): the `scene_hash` of sidecars, mesh files and the cache: SHA-256 of the
  evaluated geometry, transforms, visibility, materials and the camera record;
- evaluation_settings(): the settings the scene is evaluated (and hashed) with, applied by
  the reference and the mesh export alike so that their scene_hash agree;
- BridgeError and Cancelled, the bridge's errors.
"""

from __future__ import annotations

import hashlib
import json

import bpy
import numpy as np

from aolab.bridge.intrinsics import (SUPPORTED_CAMERA_TYPES, check_camera_to_world,
                                     image_size, intrinsics, max_ray_coordinate)

from .state import SettingsRestorer

CAMERA_TYPE_NAMES = {"ORTHO": "orthographic", "PANO": "panoramic"}


class BridgeError(Exception):
    """A problem the user can act on (no camera, unsupported camera, failed render...)."""


class Cancelled(BridgeError):
    def __init__(self):
        super().__init__("cancelled")


def scene_camera(scene, camera_name: str | None = None):
    """The camera object to render from, or BridgeError saying what is wrong."""
    if camera_name:
        cam = bpy.data.objects.get(camera_name)
        if cam is None or cam.type != "CAMERA":
            cams = sorted(o.name for o in bpy.data.objects if o.type == "CAMERA")
            raise BridgeError(f"camera {camera_name!r} not found; cameras in the file: "
                              f"{', '.join(cams) or 'none'}")
    else:
        cam = scene.camera
        if cam is None:
            raise BridgeError(f"scene {scene.name!r} has no camera: set the scene camera "
                              "(Scene Properties > Camera); AO Lab renders from it")
    if cam.data.type not in SUPPORTED_CAMERA_TYPES:
        kind = CAMERA_TYPE_NAMES.get(cam.data.type, cam.data.type)
        raise BridgeError(f"camera {cam.name!r} is {kind}; AO Lab supports perspective cameras "
                          "only (its methods reconstruct positions with a pinhole model)")
    camera_to_world(cam)   # refuses a sheared, zero-scaled or far camera before any render
    return cam


def camera_to_world(cam) -> list[list[float]]:
    """The camera's world matrix, row-major, scale removed (renders ignore camera scale);
    BridgeError when what is left is no rotation: a camera sheared by a parent's uneven scale
    under a rotation, which neither the pinhole intrinsics nor rtao can follow; a camera
    scaled to zero (its sidecar would hold NaN, which no JSON reader takes, and break the
    cache's entry); or one beyond the ray tracers' coordinate range (max_ray_coordinate:
    Cycles, which traces with Embree, dies on a ray from beyond it)."""
    m = np.array(cam.matrix_world, dtype=np.float64)
    # Two cases the rotation check would misname (as a shear, or NaN): a camera out of the
    # ray tracer's range, and one scaled to zero, which has no view direction at all.
    loc = m[:3, 3]
    limit = max_ray_coordinate()
    if not (np.abs(loc) <= limit).all():   # NaN included
        shown = ", ".join(f"{v:g}" for v in loc)
        raise BridgeError(f"camera {cam.name!r} is at the world location ({shown}), beyond "
                          f"+-{limit:g} along an axis, where Cycles cannot "
                          "trace rays: move it (or its parents) nearer the origin")
    scale = np.linalg.norm(m[:3, :3], axis=0)
    if not (scale > 0).all():   # NaN included
        shown = ", ".join(f"{v:g}" for v in scale)
        raise BridgeError(f"camera {cam.name!r} is scaled to zero (world scale {shown}): it "
                          "has no view direction; give it (and its parents) a non-zero scale")
    m[:3, :3] /= scale
    try:
        check_camera_to_world(m)
    except ValueError as e:
        raise BridgeError(f"camera {cam.name!r} cannot be rendered from: {e} (a parent "
                          "scaled unevenly and rotated shears a camera: scale the parent "
                          "evenly, or apply its scale)") from None
    return m.tolist()


def camera_record(scene, cam, size: tuple[int, int] | None = None) -> dict:
    """The camera and its intrinsics at the scene's output size, or at `size` (W, H) as a
    render with that resolution at 100 % would have them."""
    r = scene.render
    w, h = size or image_size(r.resolution_x, r.resolution_y, r.resolution_percentage)
    d = cam.data
    k = intrinsics(w, h, lens=d.lens, sensor_width=d.sensor_width,
                   sensor_height=d.sensor_height, sensor_fit=d.sensor_fit, shift_x=d.shift_x,
                   shift_y=d.shift_y, pixel_aspect_x=r.pixel_aspect_x,
                   pixel_aspect_y=r.pixel_aspect_y)
    return {"width": w, "height": h, **k, "camera_to_world": camera_to_world(cam),
            "clip_start": d.clip_start, "clip_end": d.clip_end,
            "camera": {"name": cam.name, "lens": d.lens, "sensor_width": d.sensor_width,
                       "sensor_height": d.sensor_height, "sensor_fit": d.sensor_fit,
                       "shift_x": d.shift_x, "shift_y": d.shift_y,
                       "pixel_aspect_x": r.pixel_aspect_x, "pixel_aspect_y": r.pixel_aspect_y}}


def content_hash(scene, cam, size: tuple[int, int] | None = None) -> str:
    """SHA-256 of what the renders depend on: evaluated geometry and transforms of every
    object, its render visibility and materials, the camera and the resolution (`size`
    overrides the scene's, as camera_record does)."""
    h = hashlib.sha256()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for obj in sorted(depsgraph.objects, key=lambda o: o.name):
        h.update(f"{obj.name}|{obj.type}|{obj.hide_render}|{obj.visible_shadow}".encode())
        h.update(np.array(obj.matrix_world, dtype=np.float64).tobytes())
        if obj.type == "MESH":
            me = obj.data
            co = np.empty(len(me.vertices) * 3, np.float32)
            me.vertices.foreach_get("co", co)
            loops = np.empty(len(me.loops), np.int32)
            me.loops.foreach_get("vertex_index", loops)
            h.update(co.tobytes())
            h.update(loops.tobytes())
            h.update("|".join(m.name if m else "" for m in me.materials).encode())
    h.update(json.dumps(camera_record(scene, cam, size), sort_keys=True).encode())
    return h.hexdigest()


def evaluation_settings(rs: SettingsRestorer, scene, cam) -> None:
    """The settings the references are evaluated (and content_hash taken) with: the mesh
    export applies the same, so that its scene_hash equals the reference's."""
    rs.set(scene.render, "engine", "CYCLES")
    rs.set(scene.cycles, "device", "CPU")
    rs.set(scene, "camera", cam)
    rs.set(scene.render, "use_simplify", False)
