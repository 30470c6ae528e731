"""Corpus family `interior`: furnished rooms, built from a seed.

A closed box room (walls, floor, ceiling, skirting, a door recess and a window recess),
furnished by seeded placement: tables with four legs and chairs around them, a sofa, a bed,
shelves full of books, cabinets and rugs. Metres, z up, the room spans x in [0, W] and
y in [0, D]. Variants differ in seed, room size, furniture and camera.
"""
from families import kit

# variant: (seed, (W, D, H), furniture, camera at, target, lens mm, R)
VARIANTS = {
    0: (11, (6.0, 5.0, 2.8), ("dining", "sofa", "shelves", "cabinet"),
        (5.6, 0.4, 1.6), (1.5, 3.6, 0.7), 18.0, 0.5),
    1: (12, (4.5, 4.0, 2.6), ("bed", "shelves", "desk", "cabinet"),
        (4.3, 0.2, 2.5), (1.6, 2.6, 0.0), 16.0, 0.3),
    2: (13, (5.0, 4.5, 2.7), ("dining", "shelves", "cabinet"),
        (3.8, 0.9, 1.2), (2.2, 2.4, 0.6), 35.0, 0.25),
    3: (14, (10.0, 8.0, 3.6), ("dining", "dining", "dining", "sofa", "shelves", "shelves"),
        (9.6, 0.4, 2.2), (3.0, 5.5, 0.5), 24.0, 1.0),
}


def shell(b, w, d, h):
    """Walls 15 cm thick outside the room, floor and ceiling slabs, skirting, recesses."""
    t = 0.15
    b.box((-t, -t, -t), (w + t, d + t, 0.0))          # floor
    b.box((-t, -t, h), (w + t, d + t, h + t))          # ceiling
    b.box((-t, -t, 0.0), (0.0, d + t, h))              # wall x = 0
    b.box((w, -t, 0.0), (w + t, d + t, h))             # wall x = W
    b.box((0.0, d, 0.0), (w, d + t, h))                # wall y = D
    b.box((0.0, -t, 0.0), (w, 0.0, h))                 # wall y = 0
    for x0, x1 in ((0.0, w),):                          # skirting boards
        b.box((x0, d - 0.02, 0.0), (x1, d, 0.1))
    b.box((0.0, 0.0, 0.0), (0.02, d, 0.1))
    b.box((0.3 * w, d - 0.02, 0.9), (0.3 * w + 1.2, d, 0.95))   # a window sill
    b.box((0.02, 0.4 * d, 2.05), (0.1, 0.4 * d + 0.9, 2.15))     # a door lintel


def table(b, x, y, length, width, height=0.75):
    b.box((x - length / 2, y - width / 2, height - 0.04), (x + length / 2, y + width / 2, height))
    for sx in (-1, 1):
        for sy in (-1, 1):
            lx, ly = x + sx * (length / 2 - 0.06), y + sy * (width / 2 - 0.06)
            b.box((lx - 0.025, ly - 0.025, 0.0), (lx + 0.025, ly + 0.025, height - 0.04))


def chair(b, x, y, facing):
    """A chair at (x, y) whose back is on the side -facing (a unit axis vector)."""
    fx, fy = facing
    b.box((x - 0.22, y - 0.22, 0.43), (x + 0.22, y + 0.22, 0.46))
    for sx in (-1, 1):
        for sy in (-1, 1):
            lx, ly = x + sx * 0.19, y + sy * 0.19
            b.box((lx - 0.015, ly - 0.015, 0.0), (lx + 0.015, ly + 0.015, 0.43))
    bx, by = x - fx * 0.2, y - fy * 0.2
    hx, hy = (0.02, 0.22) if fx else (0.22, 0.02)
    b.box((bx - hx, by - hy, 0.46), (bx + hx, by + hy, 0.9))


def dining(b, r, x, y):
    length, width = r.uniform(1.2, 1.8), r.uniform(0.7, 0.9)
    table(b, x, y, length, width)
    for k in (-1, 1):
        for s in (-0.25, 0.25):
            chair(b, x + s * length, y + k * (width / 2 + 0.15), (0, -k))
    chair(b, x + length / 2 + 0.2, y, (-1, 0))


def sofa(b, r, x, y):
    length = r.uniform(1.6, 2.2)
    b.box((x - length / 2, y - 0.45, 0.1), (x + length / 2, y + 0.45, 0.42))   # seat
    b.box((x - length / 2, y + 0.25, 0.42), (x + length / 2, y + 0.45, 0.85))  # back
    for s in (-1, 1):
        b.box((x + s * length / 2 - (0.18 if s > 0 else 0.0), y - 0.45, 0.42),
              (x + s * length / 2 + (0.0 if s > 0 else 0.18), y + 0.45, 0.62))
    for s in (-1, 1):
        for t in (-1, 1):
            b.box((x + s * (length / 2 - 0.05) - 0.02, y + t * 0.4 - 0.02, 0.0),
                  (x + s * (length / 2 - 0.05) + 0.02, y + t * 0.4 + 0.02, 0.1))
    b.box((x - 0.5, y - 1.2, 0.0), (x + 0.5, y - 0.7, 0.4))   # low coffee table


def shelves(b, r, x, y):
    """A bookcase against a wall at y (its back at y), books of seeded widths on 5 boards."""
    width, depth = r.uniform(1.0, 1.6), 0.32
    b.box((x - width / 2, y - depth, 0.0), (x - width / 2 + 0.02, y, 2.0))
    b.box((x + width / 2 - 0.02, y - depth, 0.0), (x + width / 2, y, 2.0))
    for k in range(6):
        z = 0.05 + k * 0.38
        b.box((x - width / 2, y - depth, z), (x + width / 2, y, z + 0.02))
        if k == 5:
            break
        bx = x - width / 2 + 0.03
        while bx < x + width / 2 - 0.06:
            bw, bh = r.uniform(0.02, 0.05), r.uniform(0.2, 0.33)
            inset = r.uniform(0.0, 0.06)
            b.box((bx, y - depth + inset, z + 0.02), (bx + bw, y - 0.02, z + 0.02 + bh))
            bx += bw + (0.002 if r.random() < 0.8 else r.uniform(0.02, 0.1))


def bed(b, r, x, y):
    b.box((x - 0.8, y - 2.0, 0.0), (x + 0.8, y, 0.45))
    b.box((x - 0.8, y - 0.06, 0.0), (x + 0.8, y, 1.0))           # headboard
    b.box((x - 0.6, y - 0.5, 0.45), (x + 0.6, y - 0.12, 0.58))   # pillow
    b.box((x + 0.9, y - 0.45, 0.0), (x + 1.35, y, 0.5))          # bedside table


def desk(b, r, x, y):
    table(b, x, y - 0.35, 1.3, 0.65)
    chair(b, x, y - 0.9, (0, 1))
    b.box((x - 0.3, y - 0.2, 0.75), (x + 0.3, y - 0.17, 1.1))    # a screen
    b.box((x - 0.05, y - 0.25, 0.75), (x + 0.05, y - 0.15, 0.8))


def cabinet(b, r, x, y):
    w = r.uniform(0.8, 1.4)
    b.box((x - w / 2, y - 0.5, 0.08), (x + w / 2, y, 0.9))
    b.box((x - w / 2 + 0.05, y - 0.45, 0.0), (x + w / 2 - 0.05, y - 0.05, 0.08))
    for k in range(3):   # things standing on it
        x0 = x - w / 2 + 0.1 + k * 0.15
        b.box((x0, y - 0.3, 0.9), (x0 + 0.1, y - 0.2, 0.9 + r.uniform(0.1, 0.35)))


PIECES = {"dining": dining, "sofa": sofa, "shelves": shelves, "bed": bed, "desk": desk,
          "cabinet": cabinet}
AGAINST_WALL = {"shelves", "bed", "desk", "cabinet"}


def furnish(b, r, w, d, furniture):
    """Free pieces on a grid of the floor's middle, wall pieces along the far wall y = D."""
    free = [p for p in furniture if p not in AGAINST_WALL]
    wall = [p for p in furniture if p in AGAINST_WALL]
    for k, name in enumerate(free):
        x = w * (k + 1) / (len(free) + 1) + r.uniform(-0.2, 0.2)
        y = d * (0.45 if k % 2 == 0 else 0.6) + r.uniform(-0.2, 0.2)
        PIECES[name](b, r, x, y)
    for k, name in enumerate(wall):
        x = w * (k + 0.5) / len(wall)
        PIECES[name](b, r, x, d)
    b.box((0.2 * w, 0.25 * d, 0.0), (0.55 * w, 0.55 * d, 0.012))   # a rug


def build(variant):
    seed, (w, d, h), furniture, at, target, lens, radius = VARIANTS[variant]
    r = kit.rng(seed)
    b = kit.Builder()
    shell(b, w, d, h)
    furnish(b, r, w, d, furniture)
    b.build("Room", kit.grey())
    kit.finish(at, target, lens, radius)
