"""AO Lab reference scene `colored_room`: strongly coloured walls and objects, an emissive panel.

Run inside Blender by the bridge after `read_factory_settings(use_empty=True)`; it builds the
scene into `bpy.context.scene`. Deterministic: no randomness, no files.

A closed room 6 m x 6 m x 3 m (metres, z up; interior x in [-3, 3], y in [0, 6]) in the
manner of a Cornell box: red wall on the left, green on the right, light grey back wall,
floor and ceiling. A tall blue box stands near the red wall, a low yellow box near the green
wall, a yellow cylinder by the back wall, a faceted white sphere and a small blue cube on the
floor. An emissive panel (strength 10) hangs on the back wall and a small emissive cube sits
on the floor beside the yellow box. The camera stands near the front wall, looking in.
For colour bleeding (coloured diffuse albedo beside grey surfaces) and luminance sensitivity
(emitters that should not be darkened like ordinary surfaces).
"""
import math
import sys
from pathlib import Path

import bpy

RADIUS = 0.5  # AO distance R in metres (manifest "radius")
ROOM_X, ROOM_Y, ROOM_Z = 3.0, 6.0, 3.0  # x in [-ROOM_X, ROOM_X], y in [0, ROOM_Y]
EMISSION_STRENGTH = 10.0


# The helpers shared by every scene (reference_scenes/scene_kit.py).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from scene_kit import add_box, add_camera, finish_scene, make_material, MeshBuilder  # noqa: E402


def add_sphere(name, centre, radius, mat, segments=32, rings=16):
    """A flat-shaded UV sphere: poles on the z axis, `rings` bands of `segments` faces,
    outward normals. Built vertex by vertex (not with bmesh.ops.create_uvsphere, whose loop
    order varies from run to run and with it the bridge's scene hash)."""
    mb = MeshBuilder()
    mb.verts.append((0.0, 0.0, radius))
    for i in range(1, rings):
        polar = math.pi * i / rings
        for k in range(segments):
            azimuth = 2.0 * math.pi * k / segments
            mb.verts.append((radius * math.sin(polar) * math.cos(azimuth),
                             radius * math.sin(polar) * math.sin(azimuth),
                             radius * math.cos(polar)))
    mb.verts.append((0.0, 0.0, -radius))
    south = len(mb.verts) - 1

    def ring(i, k):  # vertex k of latitude ring i (1 ... rings - 1)
        return 1 + (i - 1) * segments + k % segments

    for k in range(segments):
        mb.faces.append((0, ring(1, k), ring(1, k + 1)))
        for i in range(1, rings - 1):
            mb.faces.append((ring(i, k), ring(i + 1, k), ring(i + 1, k + 1), ring(i, k + 1)))
        mb.faces.append((ring(rings - 1, k), south, ring(rings - 1, k + 1)))
    return mb.build(name, mat, location=centre)


def build():
    scene = bpy.context.scene
    grey = make_material("Light_Grey", (0.7, 0.7, 0.7))
    red = make_material("Red", (0.80, 0.04, 0.04))
    green = make_material("Green", (0.05, 0.65, 0.05))
    blue = make_material("Blue", (0.04, 0.10, 0.80))
    yellow = make_material("Yellow", (0.85, 0.70, 0.04))
    white = make_material("White", (0.85, 0.85, 0.85))
    light = make_material("Emitter", (1.0, 0.95, 0.85), emission_strength=EMISSION_STRENGTH)

    x, y, z = ROOM_X, ROOM_Y, ROOM_Z
    mb = MeshBuilder()  # grey shell: floor, ceiling, back and front walls (inward normals)
    mb.quad((-x, 0, 0), (x, 0, 0), (x, y, 0), (-x, y, 0))      # floor
    mb.quad((-x, 0, z), (-x, y, z), (x, y, z), (x, 0, z))      # ceiling
    mb.quad((-x, y, 0), (x, y, 0), (x, y, z), (-x, y, z))      # back wall, normal -y
    mb.quad((-x, 0, 0), (-x, 0, z), (x, 0, z), (x, 0, 0))      # front wall, normal +y
    mb.build("Room", grey)
    mb = MeshBuilder()
    mb.quad((-x, 0, 0), (-x, y, 0), (-x, y, z), (-x, 0, z))    # left wall, normal +x
    mb.build("Wall_Red", red)
    mb = MeshBuilder()
    mb.quad((x, 0, 0), (x, 0, z), (x, y, z), (x, y, 0))        # right wall, normal -x
    mb.build("Wall_Green", green)

    mb = MeshBuilder()
    mb.box((-0.4, -0.4, 0.0), (0.4, 0.4, 1.7))
    mb.build("Box_Blue_Tall", blue, (-2.2, 4.3, 0.0), 18.0)
    mb = MeshBuilder()
    mb.box((-0.5, -0.5, 0.0), (0.5, 0.5, 0.6))
    mb.build("Box_Yellow_Low", yellow, (1.9, 3.5, 0.0), -22.0)
    mb = MeshBuilder()
    mb.prism(0.6, 5.45, 0.35, 0.0, 1.1, 32)
    mb.build("Cylinder_Yellow", yellow)
    add_sphere("Sphere_White", (-0.7, 3.1, 0.45), 0.45, white)
    mb = MeshBuilder()
    mb.box((-0.2, -0.2, 0.0), (0.2, 0.2, 0.4))
    mb.build("Cube_Blue", blue, (0.25, 2.7, 0.0), 40.0)

    # Emitters: a light panel 5 cm proud of the back wall, a small glowing cube on the floor.
    add_box("Panel_Emissive", (-1.5, y - 0.05, 1.3), (-0.1, y, 2.2), light)
    mb = MeshBuilder()
    mb.box((-0.15, -0.15, 0.0), (0.15, 0.15, 0.3))
    mb.build("Cube_Emissive", light, (1.05, 2.9, 0.0), 10.0)

    cam = add_camera("Camera", (0.0, 0.3, 1.75), (0.0, 4.5, 0.7), 18.0)
    finish_scene(scene, cam, RADIUS)


if __name__ == "__main__":
    build()
