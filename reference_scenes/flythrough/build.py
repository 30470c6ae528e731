"""AO Lab reference scene `flythrough`: a small set seen by a moving camera, frames 1-8.

Run inside Blender by the bridge after `read_factory_settings(use_empty=True)`; it builds the
scene into `bpy.context.scene`. Deterministic: no randomness, no files.

Metres, z up. A floor (z = 0) and a back wall whose face is the plane y = 0 (facing -y); in
front of it two boxes stacked off-centre, a low table whose top overhangs the floor, a square
and an eight-sided pillar, a crate pushed against the wall and a ledge along it. The camera
trucks left to right and turns towards the set over frames 1-8 (location and rotation
keyframed at frames 1 and 8, linear interpolation), so every frame sees the same creases and
contact shadows from a slightly different place: what the study's temporal metrics need
(docs/comparison.md, "Temporal stability"). The frames render at 320x180: a sequence of eight
is then cheaper than one 1280x720 still.
"""
import math
import sys
from pathlib import Path

import bpy
from mathutils import Vector

RADIUS = 0.5  # AO distance R in metres (manifest "radius")
FRAME_START, FRAME_END = 1, 8  # manifest "frames"
WIDTH, HEIGHT = 320, 180  # manifest "resolution"
# The camera's path: (location, target) at the first and the last frame.
CAMERA_KEYS = {
    FRAME_START: ((-1.4, -4.6, 1.45), (-0.5, 0.0, 0.55)),
    FRAME_END: ((0.9, -4.0, 1.25), (0.7, 0.0, 0.55)),
}

# The helpers shared by every scene (reference_scenes/scene_kit.py).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from scene_kit import add_box, add_camera, finish_scene, make_material, MeshBuilder  # noqa: E402


def build_set(mat):
    """The floor, the wall and the objects on the floor, one mesh each."""
    mb = MeshBuilder()
    mb.quad((-8.0, -8.0, 0.0), (8.0, -8.0, 0.0), (8.0, 8.0, 0.0), (-8.0, 8.0, 0.0))
    mb.build("Floor", mat)
    add_box("Wall", (-4.0, 0.0, 0.0), (4.0, 0.25, 2.6), mat)
    # A ledge along the wall at 0.9 m: a crease above and a shadowed band below.
    add_box("Ledge", (-3.0, -0.18, 0.86), (3.0, 0.0, 0.9), mat)
    # Two boxes stacked off-centre: a floor contact, a step and a crease between them.
    stack = MeshBuilder()
    stack.box((-1.9, -1.5, 0.0), (-1.1, -0.8, 0.6))
    stack.box((-1.75, -1.35, 0.6), (-1.3, -0.95, 0.95))
    stack.build("Stack", mat)
    # A low table: a thin top overhanging the floor on four legs.
    table = MeshBuilder()
    table.box((-0.5, -1.6, 0.42), (0.5, -1.0, 0.46))
    for x in (-0.46, 0.42):
        for y in (-1.56, -1.08):
            table.box((x, y, 0.0), (x + 0.04, y + 0.04, 0.42))
    table.build("Table", mat)
    # A square pillar near the wall and an eight-sided one in the open.
    add_box("Pillar_Square", (1.0, -0.7, 0.0), (1.3, -0.4, 2.6), mat)
    octagon = MeshBuilder()
    octagon.prism(1.6, -1.9, 0.18, 0.0, 1.8, 8, phase=math.pi / 8)
    octagon.build("Pillar_Octagon", mat)
    # A crate pushed against the wall: two creases with the wall and the floor.
    add_box("Crate", (-0.9, -0.5, 0.0), (-0.4, 0.0, 0.5), mat)


def animate_camera(cam):
    """Location and rotation keyframed at the ends of the range, interpolated linearly.

    The rotation is keyframed as Euler angles (a look-at quaternion converted, each key
    compatible with the previous one so that no angle wraps between keys)."""
    cam.rotation_mode = 'XYZ'
    previous = None
    for frame in sorted(CAMERA_KEYS):
        location, target = CAMERA_KEYS[frame]
        quat = (Vector(target) - Vector(location)).to_track_quat('-Z', 'Y')
        euler = quat.to_euler('XYZ', previous) if previous is not None else quat.to_euler('XYZ')
        previous = euler
        cam.location = location
        cam.rotation_euler = euler
        cam.keyframe_insert("location", frame=frame)
        cam.keyframe_insert("rotation_euler", frame=frame)
    for curve in cam.animation_data.action.fcurves:
        for key in curve.keyframe_points:
            key.interpolation = 'LINEAR'


def build():
    scene = bpy.context.scene
    grey = make_material("Grey", (0.6, 0.6, 0.6))
    build_set(grey)
    location, target = CAMERA_KEYS[FRAME_START]
    cam = add_camera("Camera", location, target, 24.0, clip_end=50.0)
    animate_camera(cam)
    finish_scene(scene, cam, RADIUS)
    # finish_scene sets the stills' 1280x720; a sequence renders smaller (manifest resolution).
    scene.render.resolution_x = WIDTH
    scene.render.resolution_y = HEIGHT
    scene.frame_start = FRAME_START
    scene.frame_end = FRAME_END
    scene.frame_step = 1
    scene.frame_set(FRAME_START)


if __name__ == "__main__":
    build()
