"""AO Lab reference scene `analytic`: planes whose Cycles AO has a closed form.

Run inside Blender by the bridge after `read_factory_settings(use_empty=True)`; it builds the
scene into `bpy.context.scene`. Deterministic: no randomness, no files.

Metres, z up, R = 1. An open floor (z = 0); three floating ceiling slabs, 2.6 m square and
0.1 m thick, with their undersides at h = 0.55, 0.75 and 0.90 above the floor; to their right
a thick wall whose face is the plane x = 6 (facing -x), from y = -2.5 to 6.5 and 2.5 m high.
The check points of manifest.json lie under the slab centres (no slab edge within 1.3 m > R),
on the floor at distances 0.1 to 1.2 from the wall, on the wall face and on the floor/wall
crease (the wall reaching at least 1.5 m > R beyond each of them along y, and nothing else
within R). The camera is low enough to see the floor beneath the slabs.
"""
import sys
from pathlib import Path

import bpy

RADIUS = 1.0  # AO distance R in metres (manifest "radius")
SLAB_HALF = 1.3  # half-size of a ceiling slab in x and y (> R: no edge within R of its centre)
SLAB_THICKNESS = 0.1
SLABS = (  # (name, centre x, underside height h); centres at y = 0
    ("Ceiling_h055", -4.2, 0.55),
    ("Ceiling_h075", -1.4, 0.75),
    ("Ceiling_h090", 1.4, 0.90),
)
WALL_FACE_X = 6.0


# The helpers shared by every scene (reference_scenes/scene_kit.py).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from scene_kit import add_box, add_camera, finish_scene, make_material, MeshBuilder  # noqa: E402


def build():
    scene = bpy.context.scene
    grey = make_material("Grey", (0.6, 0.6, 0.6))
    mb = MeshBuilder()  # the floor: one single-sided quad at z = 0
    mb.quad((-12.0, -12.0, 0.0), (14.0, -12.0, 0.0), (14.0, 16.0, 0.0), (-12.0, 16.0, 0.0))
    mb.build("Floor", grey)
    for name, cx, h in SLABS:
        add_box(name, (cx - SLAB_HALF, -SLAB_HALF, h),
                (cx + SLAB_HALF, SLAB_HALF, h + SLAB_THICKNESS), grey)
    add_box("Wall", (WALL_FACE_X, -2.5, 0.0), (WALL_FACE_X + 0.3, 6.5, 2.5), grey)
    cam = add_camera("Camera", (0.3, -5.8, 1.9), (0.3, 1.0, -0.6), 18.0)
    finish_scene(scene, cam, RADIUS)


if __name__ == "__main__":
    build()
