"""AO Lab reference scene `room`: a furnished room with stairs, pillars and furniture.

Run inside Blender by the bridge after `read_factory_settings(use_empty=True)`; it builds the
scene into `bpy.context.scene`. Deterministic: no randomness, no files.

A closed room 8 m x 6 m x 3 m (metres, z up; interior x in [0, 8], y in [0, 6]) made of
inward-facing quads: a straight flight of ten steps with a landing and a thin handrail
against the far wall, a square pillar and a sixteen-sided one on a plinth (floor to ceiling),
a table with four chairs on a 12 mm rug, a bookcase full of books, crates stacked in a corner
and a turned one, a low bench and a skirting board along the long wall y = 0. The camera
stands near that wall, so it is seen at a grazing angle. Everything is flat-shaded grey.
"""
import math
import sys
from pathlib import Path

import bpy

RADIUS = 0.5  # AO distance R in metres (manifest "radius")
ROOM = (8.0, 6.0, 3.0)  # interior size x, y, z


# The helpers shared by every scene (reference_scenes/scene_kit.py).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from scene_kit import add_camera, finish_scene, make_material, MeshBuilder  # noqa: E402


def build_shell(mat):
    """Floor, ceiling and four walls as one mesh of inward-facing quads."""
    sx, sy, sz = ROOM
    mb = MeshBuilder()
    mb.quad((0, 0, 0), (sx, 0, 0), (sx, sy, 0), (0, sy, 0))          # floor, normal +z
    mb.quad((0, 0, sz), (0, sy, sz), (sx, sy, sz), (sx, 0, sz))      # ceiling, normal -z
    mb.quad((0, 0, 0), (0, sy, 0), (0, sy, sz), (0, 0, sz))          # wall x = 0, normal +x
    mb.quad((sx, 0, 0), (sx, 0, sz), (sx, sy, sz), (sx, sy, 0))      # wall x = 8, normal -x
    mb.quad((0, 0, 0), (0, 0, sz), (sx, 0, sz), (sx, 0, 0))          # wall y = 0, normal +y
    mb.quad((0, sy, 0), (sx, sy, 0), (sx, sy, sz), (0, sy, sz))      # wall y = 6, normal -y
    mb.build("Room", mat)
    # Skirting board along the walls y = 0 and x = 0 (a 1.5 cm ledge, 10 cm high).
    mb = MeshBuilder()
    mb.box((0.0, 0.0, 0.0), (sx, 0.015, 0.10))
    mb.box((0.0, 0.015, 0.0), (0.015, 0.9, 0.10))
    mb.build("Skirting", mat)


def build_stairs(mat):
    """Ten steps rising along +y against the wall x = 0, a landing, a handrail on posts."""
    rise, run, width, n = 0.18, 0.28, 1.1, 10
    y0 = 1.0
    mb = MeshBuilder()
    for i in range(n):
        mb.box((0.0, y0 + i * run, 0.0), (width, y0 + (i + 1) * run, (i + 1) * rise))
    y_top = y0 + n * run
    mb.box((0.0, y_top, 0.0), (width, ROOM[1], n * rise))  # landing against the wall y = 6
    mb.build("Stairs", mat)
    # Handrail on the open side: a 3 cm post on every other step and a rail 0.9 m above the nosing.
    mb = MeshBuilder()
    post = 0.03
    x0 = width - 0.06
    for i in range(0, n, 2):
        yc = y0 + (i + 0.5) * run
        z_step = (i + 1) * rise
        mb.box((x0, yc - post / 2, z_step), (x0 + post, yc + post / 2, z_step + 0.9))
    # The rail: a sloped square bar following the nosing line, as a closed prism of 4 quads.
    ya, za = y0 + 0.5 * run - 0.05, rise + 0.9
    yb, zb = y0 + (n - 1.5) * run + 0.05, (n - 1) * rise + 0.9
    za_top, zb_top = za + 0.04, zb + 0.04
    xa, xb = x0 - 0.005, x0 + post + 0.005
    corners = [(ya, za), (yb, zb), (yb, zb_top), (ya, za_top)]
    mb.quad(*[(xa, y, z) for y, z in reversed(corners)])   # side facing -x
    mb.quad(*[(xb, y, z) for y, z in corners])             # side facing +x
    for k in range(4):
        (ya_, za_), (yb_, zb_) = corners[k], corners[(k + 1) % 4]
        mb.quad((xa, ya_, za_), (xb, ya_, za_), (xb, yb_, zb_), (xa, yb_, zb_))
    mb.build("Handrail", mat)


def build_pillars(mat):
    sz = ROOM[2]
    mb = MeshBuilder()
    mb.box((2.8, 1.6, 0.0), (3.2, 2.0, sz))
    mb.build("Pillar_Square", mat)
    mb = MeshBuilder()
    mb.prism(5.6, 4.4, 0.22, 0.0, sz, 16)
    mb.box((5.6 - 0.3, 4.4 - 0.3, 0.0), (5.6 + 0.3, 4.4 + 0.3, 0.12))  # plinth
    mb.build("Pillar_Round", mat)


def table_builder():
    mb = MeshBuilder()
    w, d, h, top, leg = 1.6, 0.9, 0.75, 0.04, 0.06
    mb.box((-w / 2, -d / 2, h - top), (w / 2, d / 2, h))
    for sxn in (-1, 1):
        for syn in (-1, 1):
            cx, cy = sxn * (w / 2 - 0.08), syn * (d / 2 - 0.08)
            mb.box((cx - leg / 2, cy - leg / 2, 0.0), (cx + leg / 2, cy + leg / 2, h - top + 0.001))
    # Apron under the top, 8 cm deep, set back 5 cm from the edge.
    mb.box((-w / 2 + 0.05, -d / 2 + 0.05, h - top - 0.08),
           (w / 2 - 0.05, d / 2 - 0.05, h - top + 0.001))
    return mb


def chair_builder():
    """A chair facing -y in local coordinates (seat centre at the origin, on the floor)."""
    mb = MeshBuilder()
    s, h, t, leg = 0.44, 0.45, 0.04, 0.04
    mb.box((-s / 2, -s / 2, h - t), (s / 2, s / 2, h))
    for cx in (-s / 2 + leg / 2, s / 2 - leg / 2):
        for cy in (-s / 2 + leg / 2, s / 2 - leg / 2):
            top = h - t + 0.001 if cy < 0 else h + 0.45  # back legs carry the backrest
            mb.box((cx - leg / 2, cy - leg / 2, 0.0), (cx + leg / 2, cy + leg / 2, top))
    mb.box((-s / 2 + leg - 0.001, s / 2 - 0.03, h + 0.18),
           (s / 2 - leg + 0.001, s / 2 - 0.01, h + 0.42))  # backrest, 1 mm into the back legs
    return mb


def build_furniture(mat):
    table_at, table_rot = (4.1, 2.9), 8.0
    table_builder().build("Table", mat, (*table_at, 0.0), table_rot)
    # Four chairs around the table, each facing the table, some pushed back or turned.
    chairs = (("Chair_1", (0.0, -0.75), 0.0), ("Chair_2", (0.0, 0.8), 180.0),
              ("Chair_3", (-1.15, 0.05), -80.0), ("Chair_4", (1.2, -0.1), 105.0))
    rot = math.radians(table_rot)
    for name, (lx, ly), facing in chairs:
        x = table_at[0] + lx * math.cos(rot) - ly * math.sin(rot)
        y = table_at[1] + lx * math.sin(rot) + ly * math.cos(rot)
        # chair_builder's chair faces -y; rotate so its back is away from the table centre.
        chair_builder().build(name, mat, (x, y, 0.0), table_rot + facing + 180.0)
    mb = MeshBuilder()
    mb.box((-1.3, -1.0, 0.0), (1.3, 1.0, 0.012))
    mb.build("Rug", mat, (*table_at, 0.0), table_rot)

    # Bookcase against the wall y = 6, books on its shelves (sizes from a fixed pattern).
    mb = MeshBuilder()
    x0, x1, depth, height, board = 2.2, 3.8, 0.32, 2.0, 0.025
    y1 = ROOM[1]
    y0 = y1 - depth
    mb.box((x0, y0, 0.0), (x0 + board, y1, height))
    mb.box((x1 - board, y0, 0.0), (x1, y1, height))
    mb.box((x0, y1 - 0.01, 0.0), (x1, y1, height))  # back panel
    shelves = [0.08, 0.48, 0.88, 1.28, 1.68, height - board]
    for z in shelves:
        mb.box((x0 + board - 0.001, y0, z), (x1 - board + 0.001, y1 - 0.009, z + board))
    mb.box((x0 + board - 0.001, y0 + 0.02, 0.0), (x1 - board + 0.001, y0 + 0.04, 0.08))  # plinth
    mb.build("Bookcase", mat)
    mb = MeshBuilder()
    widths = (0.03, 0.045, 0.025, 0.05, 0.035, 0.04, 0.028, 0.06)
    heights = (0.26, 0.30, 0.22, 0.33, 0.28, 0.24, 0.31, 0.20)
    for s, z in enumerate(shelves[:-1]):
        x = x0 + board + 0.02 + 0.07 * (s % 3)
        k = 3 * s
        end = x1 - board - 0.25 - 0.15 * (s % 2)
        while x + widths[k % 8] < end:
            w, h = widths[k % 8], heights[(k * 5 + s) % 8]
            d = 0.2 + 0.02 * (k % 3)
            mb.box((x, y1 - 0.01 - d, z + board), (x + w, y1 - 0.011, z + board + h))
            x += w + (0.002 if k % 5 else 0.03)
            k += 1
        # One book lying flat at the end of each shelf.
        mb.box((end + 0.02, y1 - 0.23, z + board), (end + 0.22, y1 - 0.03, z + board + 0.04))
    mb.build("Books", mat)

    # Crates stacked in the corner x = 0, y = 0 (5 mm clear of the skirting), one turned crate.
    mb = MeshBuilder()
    mb.box((0.02, 0.02, 0.0), (0.70, 0.62, 0.50))
    mb.box((0.02, 0.67, 0.0), (0.55, 0.98, 0.42))
    mb.box((0.08, 0.07, 0.5), (0.58, 0.55, 0.86))
    mb.build("Crates", mat)
    mb = MeshBuilder()
    mb.box((-0.2, -0.2, 0.0), (0.2, 0.2, 0.4))
    mb.build("Crate_Turned", mat, (1.25, 0.75, 0.0), 27.0)

    # A low bench along the wall y = 0 (the wall seen at a grazing angle).
    mb = MeshBuilder()
    mb.box((4.4, 0.02, 0.40), (6.3, 0.45, 0.45))
    for x in (4.45, 6.19):
        mb.box((x, 0.07, 0.0), (x + 0.06, 0.40, 0.401))
    mb.build("Bench", mat)


def build():
    scene = bpy.context.scene
    grey = make_material("Grey", (0.6, 0.6, 0.6))
    build_shell(grey)
    build_stairs(grey)
    build_pillars(grey)
    build_furniture(grey)
    cam = add_camera("Camera", (7.6, 0.45, 1.65), (2.0, 4.0, 0.7), 20.0)
    finish_scene(scene, cam, RADIUS)


if __name__ == "__main__":
    build()
