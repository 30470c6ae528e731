"""AO Lab reference scene `grille`: thin bars close to a wall, on a floor.

Run inside Blender by the bridge after `read_factory_settings(use_empty=True)`; it builds the
scene into `bpy.context.scene`. Deterministic: no randomness, no files.

Metres, z up. A floor (z = 0) and a wall whose face is the plane y = 0 (facing -y). In front
of the wall: a grille of 2 cm vertical bars 5 cm from the wall, a lattice of 1.5 cm bars
15 cm from the wall, and a free-standing picket fence 0.8 m from the wall; a thin pole and a
bar leaning against the wall. A screen-space method that treats every pixel as infinitely thick
darkens the wall and floor behind the bars; the ray-traced reference sees the light between
them.
"""
import math
import sys
from pathlib import Path

import bpy

RADIUS = 0.5  # AO distance R in metres (manifest "radius")


# The helpers shared by every scene (reference_scenes/scene_kit.py).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from scene_kit import add_box, add_camera, finish_scene, make_material, MeshBuilder  # noqa: E402


def build_grille(mat):
    """Vertical 2 cm bars, 10 cm apart, 5 cm from the wall, x in [-3.0, -0.4], on two rails."""
    mb = MeshBuilder()
    bar, y_back = 0.02, -0.05  # bars 2 cm square, their back faces 5 cm in front of the wall
    x = -3.0
    while x < -0.4:
        mb.box((x, y_back - bar, 0.0), (x + bar, y_back, 2.0))
        x += 0.10
    x_end = x - 0.10 + bar
    for z in (0.12, 1.85):  # flat rails in front of the bars
        mb.box((-3.05, y_back - bar - 0.012, z), (x_end + 0.05, y_back - bar + 0.0005, z + 0.04))
    # Wall brackets holding the rails: short bars from the rail to the wall.
    for xb in (-3.03, x_end + 0.02):
        for z in (0.13, 1.86):
            mb.box((xb - 0.01, y_back - bar - 0.011, z + 0.005), (xb + 0.01, 0.0005, z + 0.025))
    mb.build("Grille", mat)


def build_lattice(mat):
    """A 1.5 cm square lattice, 12 cm pitch, 15 cm from the wall, on four 3 cm feet."""
    mb = MeshBuilder()
    bar, y_back = 0.015, -0.15
    x0, x1, z0, z1 = 0.0, 1.92, 0.3, 2.1
    n_x = int(round((x1 - x0) / 0.12))
    n_z = int(round((z1 - z0) / 0.12))
    for i in range(n_x + 1):
        x = x0 + i * (x1 - x0) / n_x
        mb.box((x - bar / 2, y_back - bar, z0 - bar / 2), (x + bar / 2, y_back, z1 + bar / 2))
    for k in range(n_z + 1):  # horizontal bars 1.5 cm in front of the vertical ones
        z = z0 + k * (z1 - z0) / n_z
        mb.box((x0 - bar / 2, y_back - 2 * bar + 0.0005, z - bar / 2),
               (x1 + bar / 2, y_back - bar + 0.0005, z + bar / 2))
    for x in (x0, x1):  # feet: posts from the floor to the lattice
        mb.box((x - 0.015, y_back - 0.03, 0.0), (x + 0.015, y_back, z0 + 0.02))
    mb.build("Lattice", mat)


def build_fence(mat):
    """A free-standing picket fence 0.8 m in front of the wall: 3 cm pickets, 12 cm pitch."""
    mb = MeshBuilder()
    y_back = -0.8
    x0, x1 = -1.3, 2.3
    x = x0
    while x <= x1:
        mb.box((x, y_back - 0.02, 0.0), (x + 0.03, y_back, 1.0))
        x += 0.12
    for z in (0.2, 0.8):  # rails behind the pickets
        mb.box((x0 - 0.05, y_back - 0.0005, z), (x + 0.05, y_back + 0.02, z + 0.05))
    for xp in (x0 - 0.05, x + 0.0):  # end posts
        mb.box((xp - 0.03, y_back - 0.03, 0.0), (xp + 0.03, y_back + 0.05, 1.1))
    mb.build("Fence", mat)


def build():
    scene = bpy.context.scene
    grey = make_material("Grey", (0.6, 0.6, 0.6))
    mb = MeshBuilder()
    mb.quad((-20.0, -20.0, 0.0), (20.0, -20.0, 0.0), (20.0, 20.0, 0.0), (-20.0, 20.0, 0.0))
    mb.build("Floor", grey)
    add_box("Wall", (-5.0, 0.0, 0.0), (5.0, 0.3, 3.0), grey)
    build_grille(grey)
    build_lattice(grey)
    build_fence(grey)
    # A 2 cm pole standing 4 cm from the wall, and a 3 cm bar leaning against it.
    mb = MeshBuilder()
    mb.prism(-0.2, -0.05, 0.01, 0.0, 2.6, 8)
    mb.build("Pole", grey)
    lean = MeshBuilder()
    lean.box((-0.015, -0.015, 0.0), (0.015, 0.015, 2.2))
    lean_obj = lean.build("Leaning_Bar", grey, (-3.6, -0.6, 0.004))
    lean_obj.rotation_euler = (math.radians(-15.5), 0.0, 0.0)  # top rests against the wall
    cam = add_camera("Camera", (1.6, -4.4, 1.55), (-0.3, 0.0, 0.8), 24.0)
    finish_scene(scene, cam, RADIUS)


if __name__ == "__main__":
    build()
