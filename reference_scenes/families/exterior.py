"""Corpus family `exterior`: architecture outdoors: façades, stairs, a colonnade, a street seen
from above. Metres, z up, ground z = 0. Seeded sizes; variants differ in layout and camera.
"""
from families import kit


def facade(b, r, x0, x1, y, floors, storey=3.2, bays=None):
    """A building front in the plane y (facing -y): recessed windows with sills and lintels,
    balconies with railings on upper floors, a cornice and a recessed door."""
    height = floors * storey
    b.box((x0, y, 0.0), (x1, y + 8.0, height))
    b.box((x0 - 0.1, y - 0.35, height), (x1 + 0.1, y + 0.1, height + 0.3))   # cornice
    bays = bays or max(2, int((x1 - x0) / 2.6))
    pitch = (x1 - x0) / bays
    for f in range(floors):
        z = f * storey
        b.box((x0, y - 0.08, z + storey - 0.2), (x1, y, z + storey - 0.05))   # string course
        for k in range(bays):
            cx = x0 + (k + 0.5) * pitch
            if f == 0 and k == bays // 2:   # the door: a deep recess and two steps
                b.box((cx - 0.7, y - 0.25, 0.0), (cx - 0.55, y, 2.4))
                b.box((cx + 0.55, y - 0.25, 0.0), (cx + 0.7, y, 2.4))
                b.box((cx - 0.7, y - 0.25, 2.4), (cx + 0.7, y, 2.6))
                b.box((cx - 0.8, y - 0.7, 0.0), (cx + 0.8, y, 0.15))
                b.box((cx - 0.8, y - 0.4, 0.15), (cx + 0.8, y, 0.3))
                continue
            ww = r.uniform(0.8, 1.3)
            # window reveals: jambs and head standing 0.2 m proud of the wall
            b.box((cx - ww / 2 - 0.12, y - 0.2, z + 0.9), (cx - ww / 2, y, z + 2.4))
            b.box((cx + ww / 2, y - 0.2, z + 0.9), (cx + ww / 2 + 0.12, y, z + 2.4))
            b.box((cx - ww / 2 - 0.12, y - 0.2, z + 2.4), (cx + ww / 2 + 0.12, y, z + 2.55))
            b.box((cx - ww / 2 - 0.15, y - 0.28, z + 0.82), (cx + ww / 2 + 0.15, y, z + 0.9))
            if f > 0 and r.random() < 0.5:
                balcony(b, cx, y, z, ww + 0.8)


def balcony(b, cx, y, z, width):
    b.box((cx - width / 2, y - 1.0, z - 0.15), (cx + width / 2, y, z))
    for k in range(int(width / 0.12) + 1):
        x = cx - width / 2 + k * width / int(width / 0.12)
        b.box((x - 0.01, y - 0.98, z), (x + 0.01, y - 0.96, z + 1.0))
    b.box((cx - width / 2, y - 1.0, z + 1.0), (cx + width / 2, y - 0.94, z + 1.05))


def sidewalk(b, x0, x1, y0, y1):
    b.box((x0, y0, -0.3), (x1, y1, 0.0))                 # road
    b.box((x0, y1 - 3.0, 0.0), (x1, y1, 0.15))            # sidewalk with its kerb at y1 - 3


def street_front(b, r):
    sidewalk(b, -30.0, 30.0, -20.0, 0.0)
    x = -30.0
    while x < 30.0:
        w = r.uniform(8.0, 14.0)
        facade(b, r, x, x + w - 0.3, r.uniform(0.0, 0.6), int(r.uniform(2, 5.99)))
        x += w
    for k in range(8):   # bollards along the kerb
        b.cylinder((-10.0 + 2.5 * k, -2.8, 0.15), (-10.0 + 2.5 * k, -2.8, 1.0), 0.08, 10)


def stairs(b, r):
    """An outdoor stair between two retaining walls rising along +y, with two landings,
    planters on the walls and a handrail."""
    b.box((-20.0, -20.0, -0.3), (20.0, 0.0, 0.0))
    z, y = 0.0, 0.0
    for flight in range(3):
        for _ in range(10):
            b.box((-2.0, y, 0.0), (2.0, y + 0.3, z + 0.16))
            y, z = y + 0.3, z + 0.16
        b.box((-2.0, y, 0.0), (2.0, y + 1.5, z))   # a landing
        y += 1.5
    for s in (-1, 1):
        wall_x = s * 2.0 + (0.0 if s > 0 else -0.4)
        b.box((wall_x, -0.5, 0.0), (wall_x + 0.4, y, z + 1.1))
        for k in range(6):   # planters on the walls
            py = 1.0 + k * y / 6.0
            b.box((s * 2.6 - 0.3, py, 0.0), (s * 2.6 + 0.3, py + 0.8, min(z, py * 0.4) + 1.5))
        b.cylinder((s * 1.9, 0.0, 0.9), (s * 1.9, y, z + 0.9), 0.025, 8)
    b.box((-8.0, y, 0.0), (8.0, y + 6.0, z + 6.0))   # the building at the top


def colonnade(b, r):
    """A plaza with a portico: two rows of columns on plinths under an entablature, benches."""
    b.box((-40.0, -40.0, -0.3), (40.0, 40.0, 0.0))
    b.box((-15.0, 4.0, 0.0), (15.0, 10.0, 0.6))   # stylobate
    for row in (5.0, 8.5):
        for k in range(11):
            x = -13.5 + 2.7 * k
            b.box((x - 0.45, row - 0.45, 0.6), (x + 0.45, row + 0.45, 0.9))
            b.cylinder((x, row, 0.9), (x, row, 6.9), 0.32, 16)
            b.box((x - 0.42, row - 0.42, 6.9), (x + 0.42, row + 0.42, 7.15))
    b.box((-14.5, 4.3, 7.15), (14.5, 9.2, 8.3))      # entablature
    b.box((-15.0, 9.2, 0.6), (15.0, 10.0, 8.3))      # back wall
    for k in range(6):
        x, y = r.uniform(-12.0, 12.0), r.uniform(-10.0, 1.0)
        b.box((x - 1.0, y - 0.25, 0.4), (x + 1.0, y + 0.25, 0.48))
        for s in (-0.8, 0.8):
            b.box((x + s - 0.05, y - 0.22, 0.0), (x + s + 0.05, y + 0.22, 0.4))
    b.cylinder((0.0, -6.0, 0.0), (0.0, -6.0, 0.5), 3.0, 32)     # a fountain basin
    b.cylinder((0.0, -6.0, 0.5), (0.0, -6.0, 2.0), 0.3, 12)


def blocks(b, r):
    """A street grid seen from above: blocks of buildings of seeded heights, courtyards,
    parked cars."""
    b.box((-80.0, -80.0, -0.3), (80.0, 80.0, 0.0))
    for bx in range(-2, 2):
        for by in range(-2, 2):
            x0, y0 = bx * 36.0 + 6.0, by * 36.0 + 6.0
            for k in range(4):   # four buildings around a courtyard, side by side
                hgt = r.uniform(8.0, 30.0)
                lo = [(x0, y0), (x0 + 16.0, y0 + 8.0), (x0, y0 + 16.0), (x0, y0 + 8.0)][k]
                sz = [(24.0, 8.0), (8.0, 16.0), (16.0, 8.0), (8.0, 8.0)][k]
                b.box((lo[0], lo[1], 0.0), (lo[0] + sz[0], lo[1] + sz[1], hgt))
                b.box((lo[0] + 1.0, lo[1] + 1.0, hgt), (lo[0] + 3.0, lo[1] + 3.0, hgt + 2.5))
            for c in range(5):
                cx = x0 - 3.0
                cy = y0 + 2.0 + c * 5.0 + r.uniform(0.0, 1.0)
                b.box((cx - 0.9, cy - 2.1, 0.15), (cx + 0.9, cy + 2.1, 1.0))
                b.box((cx - 0.8, cy - 1.0, 1.0), (cx + 0.8, cy + 1.2, 1.5))


# variant: (seed, builder, camera at, target, lens mm, R)
VARIANTS = {
    0: (21, street_front, (-6.0, -14.0, 1.7), (4.0, 0.0, 4.0), 24.0, 0.5),
    1: (22, stairs, (0.6, -3.5, 1.6), (0.0, 6.0, 3.5), 20.0, 0.3),
    2: (23, colonnade, (-14.0, -16.0, 2.0), (0.0, 6.0, 3.5), 28.0, 1.0),
    3: (24, blocks, (50.0, -70.0, 70.0), (0.0, 0.0, 0.0), 35.0, 2.0),
}


def build(variant):
    seed, builder, at, target, lens, radius = VARIANTS[variant]
    b = kit.Builder()
    builder(b, kit.rng(seed))
    b.build("Architecture", kit.grey())
    kit.finish(at, target, lens, radius, clip_end=2000.0)
