"""AO Lab reference scene `street`: a kilometre-long street, from 1 m to 1 km deep.

Run inside Blender by the bridge after `read_factory_settings(use_empty=True)`; it builds the
scene into `bpy.context.scene`. Deterministic: all variation comes from fixed cycles of sizes
(no random numbers), no files.

Metres, z up; the street runs along +y. An 8 m road (x in [-4, 4], z = 0) between 15 cm
sidewalks with kerbs; terraced buildings on both sides (facades near x = -7 and x = 7, fixed
cycles of widths, heights and setbacks), each with a door in a protruding frame, a doorstep,
window sills and a cornice; an arcade of columns on the left for the first 150 m; lamp posts
every 25 m and bollards along the right kerb; a sign post, a parked van and a bin near the
camera; cross streets; and a block closing the street 1 km away. The camera stands on the
road near the right kerb: the nearest geometry is about a metre away, the far end 1000 m, so
far pixels see R (0.3 m) as much less than one pixel. The camera's clip_end is 2000 m.
"""
import sys
from pathlib import Path

import bpy

RADIUS = 0.3  # AO distance R in metres (manifest "radius")
STREET_END = 1000.0  # y of the block that closes the street
KERB = 0.15  # sidewalk height
WIDTHS = (14.0, 11.0, 18.0, 9.0, 16.0, 12.0, 20.0, 10.0, 15.0)
HEIGHTS = (12.0, 18.0, 9.5, 15.0, 21.0, 13.0, 10.0, 16.5)
SETBACKS = (0.0, 0.35, 0.0, -0.2, 0.6, 0.1, 0.0)
CROSS_STREETS = (180.0, 410.0, 640.0, 870.0)  # y of 14 m wide side streets
CROSS_WIDTH = 14.0
ARCADE_END = 150.0  # the left side is an arcade for y < ARCADE_END


# The helpers shared by every scene (reference_scenes/scene_kit.py).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from scene_kit import add_box, add_camera, finish_scene, make_material, MeshBuilder  # noqa: E402


def facade_details(mb, side, x_face, y0, y1, height, k, x_door=None):
    """Door, doorstep, window sills and cornice on a facade at x = x_face facing -side*x.

    side = -1 for the left side (facade faces +x), +1 for the right side (faces -x).
    x_door: the plane of the ground-floor facade, when it is set back from x_face.
    """
    out = -side  # direction of the street, along x
    ground = KERB

    def slab(x_from, depth, y_a, y_b, z_a, z_b):
        xa, xb = sorted((x_from, x_from + out * depth))
        mb.box((xa, y_a, z_a), (xb, y_b, z_b))

    width = y1 - y0
    # Door: a protruding frame (12 cm), a door panel inside it (4 cm), a doorstep (30 cm).
    xd = x_face if x_door is None else x_door
    yd = y0 + (0.25 + 0.5 * ((k * 3) % 4) / 4.0) * width
    dw, dh = 1.2, 2.4
    slab(xd, 0.12, yd - dw / 2 - 0.15, yd - dw / 2, ground, ground + dh + 0.15)
    slab(xd, 0.12, yd + dw / 2, yd + dw / 2 + 0.15, ground, ground + dh + 0.15)
    slab(xd, 0.12, yd - dw / 2 - 0.001, yd + dw / 2 + 0.001, ground + dh, ground + dh + 0.15)
    slab(xd, 0.04, yd - dw / 2 - 0.001, yd + dw / 2 + 0.001, ground, ground + dh + 0.001)
    slab(xd, 0.30, yd - dw / 2 - 0.3, yd + dw / 2 + 0.3, ground, ground + 0.16)
    # Window sills: one row per storey above the ground floor (above the arcade's 4.5 m
    # ground floor where there is one), a window every 3 m.
    n_win = max(1, int(width // 3.0))
    storey = 3.2
    z = ground + (4.2 if x_door is None else 5.6)
    while z + 1.5 < height - 1.0:
        for w in range(n_win):
            yc = y0 + (w + 0.5) * width / n_win
            slab(x_face, 0.10, yc - 0.6, yc + 0.6, z, z + 0.06)
        z += storey
    # Cornice: a 25 cm ledge 40 cm below the roof.
    slab(x_face, 0.25, y0, y1, ground + height - 0.6, ground + height - 0.4)


def build_side(side, mat, details_mat):
    """Buildings along one side (side = -1 left, +1 right) from y = -30 to STREET_END."""
    bodies = MeshBuilder()
    details = MeshBuilder()
    y = -30.0
    k = 0 if side < 0 else 4  # the two sides run through the cycles with different phases
    while y < STREET_END:
        width = WIDTHS[k % len(WIDTHS)]
        height = HEIGHTS[(k * 3) % len(HEIGHTS)]
        setback = SETBACKS[(k * 2) % len(SETBACKS)]
        y1 = min(y + width, STREET_END)
        cross = [c for c in CROSS_STREETS if y < c + CROSS_WIDTH and c < y1]
        if cross:  # leave the side street open
            y = cross[0] + CROSS_WIDTH
            k += 1
            continue
        x_face = side * (7.0 + setback)
        x_back = side * 30.0
        in_arcade = side < 0 and y1 <= ARCADE_END
        if in_arcade:
            # Upper storeys reach the street line; the ground floor is set back 3 m behind
            # a row of columns.
            x_face = -7.0
            bodies.box((x_back, y, KERB + 4.5), (x_face, y1, KERB + height))
            bodies.box((x_back, y, KERB), (-10.0, y1, KERB + 4.5))
        else:
            lo, hi = sorted((x_face, x_back))
            bodies.box((lo, y, KERB), (hi, y1, KERB + height))
        facade_details(details, side, x_face, y, y1, height, k,
                       x_door=-10.0 if in_arcade else None)
        y = y1 + 0.0
        k += 1
    name = "Buildings_Left" if side < 0 else "Buildings_Right"
    bodies.build(name, mat)
    details.build(name + "_Details", details_mat)


def build_street(mat):
    mb = MeshBuilder()
    mb.quad((-4.0, -30.0, 0.0), (4.0, -30.0, 0.0), (4.0, STREET_END, 0.0), (-4.0, STREET_END, 0.0))
    for y0, y1 in zip((-30.0,) + tuple(c + CROSS_WIDTH for c in CROSS_STREETS),
                      CROSS_STREETS + (STREET_END,)):
        mb.box((-30.0, y0, 0.0), (-4.0, y1, KERB))  # left sidewalk (its face is the kerb)
        mb.box((4.0, y0, 0.0), (30.0, y1, KERB))    # right sidewalk
    for c in CROSS_STREETS:  # the side streets' road surface
        c1 = c + CROSS_WIDTH
        mb.quad((-30.0, c, 0.0), (-4.0, c, 0.0), (-4.0, c1, 0.0), (-30.0, c1, 0.0))
        mb.quad((4.0, c, 0.0), (30.0, c, 0.0), (30.0, c1, 0.0), (4.0, c1, 0.0))
    mb.build("Street", mat)
    add_box("End_Block", (-80.0, STREET_END, 0.0), (80.0, STREET_END + 30.0, 45.0), mat)


def build_furniture(mat):
    """Arcade columns, lamp posts, bollards and the objects near the camera."""
    mb = MeshBuilder()
    y = 2.0
    while y < ARCADE_END - 1.0:
        mb.prism(-7.5, y, 0.25, KERB, KERB + 4.5, 16)
        mb.box((-7.85, y - 0.35, KERB), (-7.15, y + 0.35, KERB + 0.3))  # base
        y += 4.0
    mb.build("Arcade_Columns", mat)
    mb = MeshBuilder()
    y = 6.0
    while y < STREET_END - 5.0:
        for side in (-1, 1):
            x = side * 4.45
            mb.prism(x, y, 0.07, KERB, KERB + 6.0, 8)
            xa, xb = sorted((x, x - side * 1.5))
            mb.box((xa, y - 0.05, KERB + 5.9), (xb, y + 0.05, KERB + 6.0))  # arm over the road
        y += 25.0
    mb.build("Lamp_Posts", mat)
    mb = MeshBuilder()
    y = 1.0
    while y < 60.0:
        mb.prism(4.35, y, 0.09, KERB, KERB + 0.9, 12)
        y += 1.8
    mb.build("Bollards", mat)
    # Near the camera (which stands at x = 2.6, y = 0): a sign post 1 m ahead on the left
    # with its plate above eye level, a bin on the sidewalk, a van parked along the left kerb.
    mb = MeshBuilder()
    mb.prism(2.2, 1.0, 0.03, 0.0, 2.6, 8)
    mb.box((2.0, 0.97, 2.15), (2.4, 0.99, 2.55))
    mb.build("Sign_Post", mat)
    mb = MeshBuilder()
    mb.prism(5.3, 2.6, 0.3, KERB, KERB + 1.0, 12)
    mb.build("Bin", mat)
    mb = MeshBuilder()
    mb.box((-3.9, 14.0, 0.35), (-2.1, 19.0, 2.3))      # body
    mb.box((-3.85, 12.9, 0.35), (-2.15, 14.001, 1.4))  # bonnet
    for yw in (13.4, 18.2):
        for xw in (-3.95, -2.35):
            mb.box((xw, yw - 0.35, 0.0), (xw + 0.3, yw + 0.35, 0.7))  # wheels
    mb.build("Van", mat)


def build():
    scene = bpy.context.scene
    grey = make_material("Grey", (0.6, 0.6, 0.6))
    build_street(grey)
    build_side(-1, grey, grey)
    build_side(1, grey, grey)
    build_furniture(grey)
    cam = add_camera("Camera", (2.6, 0.0, 1.55), (-1.0, 300.0, 6.0), 24.0,
                     clip_start=0.05, clip_end=2000.0)
    finish_scene(scene, cam, RADIUS)


if __name__ == "__main__":
    build()
