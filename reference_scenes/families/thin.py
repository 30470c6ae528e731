"""Corpus family `thin`: geometry thinner than R in front of other surfaces: the
assimp-testmodels spider's legs, potted plants (stems and leaves), a balustrade, café chairs
and hanging cables. Metres, z up, floor z = 0; a wall in the plane y = WALL behind.
"""
import math

from families import kit


def room_corner(b, wall_y, size=6.0, height=3.0):
    b.box((-size, -size, -0.1), (size, wall_y + 0.1, 0.0))
    b.box((-size, wall_y, 0.0), (size, wall_y + 0.1, height))


def spider(b, r, mat):
    room_corner(b, 0.5)
    kit.import_model("OBJ/spider.obj", mat, 0.5, location=(0.0, 0.0, 0.0), turn_deg=20.0)
    for k in range(6):   # pebbles around it
        b.rock((r.uniform(-0.5, 0.5), r.uniform(-0.4, 0.3), 0.0), (0.03, 0.03, 0.02),
               seed=r.uniform(0.0, 100.0), subdivisions=2)


def plant(b, r, x, y, height):
    """A pot, a stem and seeded leaves: thin tilted slabs (5 mm) on short petioles."""
    b.profile((x, y, 0.0), (x, y, 0.3), kit.circle(0.15, 16))
    b.cylinder((x, y, 0.3), (x, y, height), 0.008, 6)
    for k in range(int(r.uniform(10, 18))):
        z = 0.4 + (height - 0.4) * r.random()
        a = r.uniform(0.0, 2 * math.pi)
        ln = r.uniform(0.12, 0.25)
        tip = (x + ln * math.cos(a), y + ln * math.sin(a), z + r.uniform(-0.05, 0.1))
        b.cylinder((x, y, z), tip, 0.004, 5)
        m = kit.yaw(math.degrees(a)) @ kit.Matrix.Rotation(r.uniform(-0.6, 0.6), 3, 'X')
        b.obox(tip, (ln * 0.9, ln * 0.4, 0.005), m)


def plants(b, r, mat):
    room_corner(b, 0.8)
    for k in range(5):
        plant(b, r, -1.2 + 0.6 * k + r.uniform(-0.1, 0.1), 0.2 + r.uniform(-0.2, 0.3),
              r.uniform(0.8, 1.5))


def balustrade(b, r, mat):
    """A stair along +x against the wall, 2 cm balusters every 12 cm and a handrail."""
    room_corner(b, 1.2)
    for k in range(14):
        x = -2.0 + 0.28 * k
        b.box((x, 0.0, 0.0), (x + 0.28, 1.2, 0.18 * (k + 1)))
        for j in range(2):
            bx = x + 0.07 + 0.14 * j
            b.box((bx - 0.01, 0.04, 0.18 * (k + 1)), (bx + 0.01, 0.06, 0.18 * (k + 1) + 0.9))
    b.profile((-2.0, 0.05, 0.18 + 0.9), (1.92, 0.05, 0.18 * 14 + 0.9), kit.circle(0.03, 8))


def cafe(b, r, mat):
    """Bistro tables on one stem, chairs of 1.5 cm legs and hoops, cables hanging from above
    with lamps."""
    room_corner(b, 2.0, height=3.0)
    b.box((-6.0, -6.0, 3.0), (6.0, 2.0, 3.1))   # ceiling
    for k in range(3):
        x, y = -1.6 + 1.6 * k, r.uniform(-0.3, 0.6)
        b.cylinder((x, y, 0.0), (x, y, 0.02), 0.25, 16)
        b.cylinder((x, y, 0.02), (x, y, 0.72), 0.02, 8)
        b.cylinder((x, y, 0.72), (x, y, 0.74), 0.35, 20)
        for s in (-1, 1):
            cx = x + s * 0.45
            for lx in (-0.17, 0.17):
                for ly in (-0.17, 0.17):
                    b.cylinder((cx + lx * 1.1, y + ly * 1.1, 0.0), (cx + lx, y + ly, 0.45),
                               0.0075, 6)   # splayed legs
            b.cylinder((cx, y, 0.45), (cx, y, 0.47), 0.2, 14)
            b.cylinder((cx - s * 0.18, y - 0.15, 0.47), (cx - s * 0.18, y - 0.15, 0.85), 0.0075, 6)
            b.cylinder((cx - s * 0.18, y + 0.15, 0.47), (cx - s * 0.18, y + 0.15, 0.85), 0.0075, 6)
            b.cylinder((cx - s * 0.18, y - 0.15, 0.85), (cx - s * 0.18, y + 0.15, 0.85), 0.0075, 6)
        cable_z = 1.4 + r.uniform(0.0, 0.3)
        b.cylinder((x, y, 3.0), (x, y, cable_z), 0.004, 6)
        b.cylinder((x, y, cable_z - 0.2), (x, y, cable_z), 0.15, 16)


# variant: (seed, builder, camera at, target, lens mm, R)
VARIANTS = {
    0: (41, spider, (0.45, -0.85, 0.45), (0.0, 0.0, 0.08), 35.0, 0.05),
    1: (42, plants, (0.6, -2.4, 1.3), (0.0, 0.3, 0.7), 28.0, 0.2),
    2: (43, balustrade, (0.8, -2.8, 1.6), (0.0, 0.6, 1.6), 24.0, 0.3),
    3: (44, cafe, (2.2, -3.0, 1.6), (-0.4, 0.4, 0.7), 24.0, 0.25),
}


def build(variant):
    seed, builder, at, target, lens, radius = VARIANTS[variant]
    mat = kit.grey()
    b = kit.Builder()
    builder(b, kit.rng(seed), mat)
    b.build("Scene", mat)
    kit.finish(at, target, lens, radius, clip_start=0.02)
