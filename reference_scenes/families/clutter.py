"""Corpus family `clutter`: many small objects in contact on surfaces: a desk, a workshop
floor, packed shelves, a heap of toy blocks. Every object rests on the surface or object
below it (its z is that surface's top). Metres, z up.
"""

from families import kit


def mug(b, x, y, z, radius, height):
    b.profile((x, y, z), (x, y, z + height), kit.circle(radius, 16))
    b.box((x + radius, y - 0.006, z + 0.25 * height),
          (x + radius + 0.025, y + 0.006, z + 0.8 * height))


def desk(b, r, mat):
    b.box((-3.0, -3.0, -0.1), (3.0, 1.0, 0.0))
    b.box((-3.0, 0.6, 0.0), (3.0, 0.7, 2.5))
    top = 0.75
    b.box((-0.9, -0.2, top - 0.04), (0.9, 0.6, top))
    for x in (-0.85, 0.85):
        b.box((x - 0.03, -0.15, 0.0), (x + 0.03, 0.55, top - 0.04))
    b.box((-0.3, 0.05, top), (0.1, 0.33, top + 0.015))            # a laptop
    b.obox((-0.1, 0.36, top + 0.13), (0.4, 0.01, 0.26), kit.Matrix.Rotation(-0.25, 3, 'X'))
    z = top
    for k in range(int(r.uniform(4, 7))):                         # a stack of books
        w, d, h = r.uniform(0.15, 0.25), r.uniform(0.2, 0.3), r.uniform(0.015, 0.04)
        b.obox((-0.6, 0.2, z + h / 2), (w, d, h), kit.yaw(r.uniform(-15, 15)))
        z += h
    for k in range(5):                                            # mugs, pens, boxes
        x, y = r.uniform(0.2, 0.8), r.uniform(-0.15, 0.5)
        kind = r.random()
        if kind < 0.4:
            mug(b, x, y, top, 0.04, 0.1)
        elif kind < 0.7:
            b.obox((x, y, top + 0.005), (0.15, 0.008, 0.008), kit.yaw(r.uniform(0, 180)))
        else:
            s = r.uniform(0.05, 0.12)
            b.obox((x, y, top + s / 2), (s, s * 1.3, s), kit.yaw(r.uniform(0, 90)))
    for k in range(8):                                            # loose paper sheets
        b.obox((r.uniform(-0.4, 0.4), r.uniform(-0.15, 0.0), top + 0.001 * (k + 1)),
               (0.21, 0.297, 0.001), kit.yaw(r.uniform(-30, 30)))


def workshop(b, r, mat):
    b.box((-8.0, -8.0, -0.1), (8.0, 3.0, 0.0))
    b.box((-8.0, 3.0, 0.0), (8.0, 3.2, 4.0))
    for k in range(14):                                           # crates, stacked
        x, y = r.uniform(-3.0, 3.0), r.uniform(-1.0, 2.4)
        s = r.uniform(0.35, 0.7)
        z = 0.0 if r.random() < 0.6 else s
        b.obox((x, y, z + s / 2), (s, s, s), kit.yaw(r.uniform(-20, 20)))
        if z > 0:
            b.obox((x, y, s / 2), (s * 1.05, s * 1.05, s), kit.yaw(r.uniform(-10, 10)))
    for k in range(6):                                            # barrels
        x, y = r.uniform(-3.5, 3.5), r.uniform(-1.5, 2.5)
        b.cylinder((x, y, 0.0), (x, y, 0.9), 0.3, 20)
        b.cylinder((x, y, 0.18), (x, y, 0.22), 0.31, 20)
    for k in range(5):                                            # pipes lying on the floor
        y = -1.8 + 0.09 * k
        b.cylinder((-2.0, y, 0.04), (1.5, y, 0.04), 0.04, 10)
    b.box((-3.8, -0.8, 0.0), (-2.6, 0.4, 0.14))                   # a pallet
    for k in range(5):
        b.box((-3.8, -0.8 + 0.27 * k, 0.14), (-2.6, -0.7 + 0.27 * k, 0.16))


def shelf(b, r, mat):
    b.box((-3.0, -3.0, -0.1), (3.0, 0.5, 0.0))
    b.box((-3.0, 0.4, 0.0), (3.0, 0.5, 2.5))
    for k in range(5):
        z = 0.3 + 0.4 * k
        b.box((-1.2, 0.0, z - 0.02), (1.2, 0.4, z))
        x = -1.15
        while x < 1.1:
            kind = r.random()
            w = r.uniform(0.05, 0.14)
            if kind < 0.45:
                mug(b, x + w / 2, 0.15 + r.uniform(0.0, 0.15), z, w / 2, r.uniform(0.08, 0.3))
            else:
                b.box((x, r.uniform(0.02, 0.12), z), (x + w, 0.38, z + r.uniform(0.06, 0.34)))
            x += w + r.uniform(0.0, 0.03)
    for x in (-1.22, 1.2):
        b.box((x, 0.0, 0.0), (x + 0.02, 0.4, 2.1))


def blocks(b, r, mat):
    b.box((-2.0, -2.0, -0.1), (2.0, 2.0, 0.0))
    b.box((-0.6, -0.4, 0.0), (0.6, 0.4, 0.03))   # a board under the heap
    heights = {}
    cell = 0.04
    for k in range(160):
        i, j = int(r.uniform(-10, 10)), int(r.uniform(-7, 7))
        long_ = r.random() < 0.4
        cells = [(i, j), (i + 1, j)] if long_ else [(i, j)]
        z = max(heights.get(c, 0.03) for c in cells)
        size = (cell * (2 if long_ else 1) - 0.001, cell - 0.001, cell)
        b.box((i * cell, j * cell, z), (i * cell + size[0], j * cell + size[1], z + size[2]))
        for c in cells:
            heights[c] = z + cell


# variant: (seed, builder, camera at, target, lens mm, R)
VARIANTS = {
    0: (51, desk, (0.3, -0.9, 1.25), (0.0, 0.2, 0.75), 28.0, 0.06),
    1: (52, workshop, (3.5, -4.5, 1.7), (0.0, 0.8, 0.3), 24.0, 0.3),
    2: (53, shelf, (0.4, -1.6, 1.3), (0.0, 0.3, 1.0), 28.0, 0.1),
    3: (54, blocks, (0.35, -0.7, 0.75), (0.0, 0.0, 0.05), 35.0, 0.05),
}


def build(variant):
    seed, builder, at, target, lens, radius = VARIANTS[variant]
    mat = kit.grey()
    b = kit.Builder()
    builder(b, kit.rng(seed), mat)
    b.build("Clutter", mat)
    kit.finish(at, target, lens, radius, clip_start=0.02)
