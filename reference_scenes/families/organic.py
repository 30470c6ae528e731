"""Corpus family `organic`: curved, sculpted and scanned shapes: figures from Debian's
assimp-testmodels (Wuson, the HUMAN body, the COLLADA duck) and seeded noise-displaced
boulders. Metres, z up, ground z = 0. The models keep their own (smooth or flat) shading.
"""
from families import kit


def ground(b, size=30.0):
    b.box((-size, -size, -0.2), (size, size, 0.0))


def boulders(b, r, count, spread, scale):
    """count rocks of seeded size and shape in a disc of radius spread, sunk into the
    ground by a fifth of their height; some rest on others."""
    placed = []
    for k in range(count):
        sx, sy, sz = (scale * r.uniform(0.5, 1.2) for _ in range(3))
        sz *= 0.7
        x, y = r.uniform(-spread, spread), r.uniform(-spread, spread)
        z = 0.0
        for (px, py, ps) in placed:   # resting on a neighbour: sit on its shoulder
            if (x - px) ** 2 + (y - py) ** 2 < (0.6 * ps) ** 2:
                z = max(z, 0.5 * ps)
        b.rock((x, y, z), (sx, sy, sz), seed=r.uniform(0.0, 100.0))
        placed.append((x, y, max(sx, sy)))


def wuson(b, r, mat):
    ground(b)
    b.box((-4.0, 0.8, 0.0), (4.0, 1.2, 3.0))   # a wall behind
    kit.import_model("OBJ/WusonOBJ.obj", mat, 1.1, location=(0.0, 0.0, 0.0), turn_deg=200.0,
                     up='Y')
    boulders(b, r, 5, 1.2, 0.25)


def human(b, r, mat):
    ground(b)
    kit.import_model("BLEND/HUMAN.blend", mat, 1.8, location=(0.0, 0.0, 0.0), turn_deg=160.0)
    boulders(b, r, 9, 3.0, 0.7)


def rock_field(b, r, mat):
    ground(b)
    boulders(b, r, 40, 6.0, 1.0)


def duck(b, r, mat):
    ground(b)
    b.box((-2.0, 0.6, 0.0), (2.0, 0.8, 1.0))
    kit.import_model("Collada/duck.dae", mat, 0.35, location=(0.05, 0.1, 0.0), turn_deg=230.0)
    boulders(b, r, 12, 0.6, 0.12)


# variant: (seed, builder, camera at, target, lens mm, R)
VARIANTS = {
    0: (31, wuson, (0.6, -1.5, 0.9), (0.0, 0.2, 0.55), 35.0, 0.15),
    1: (32, human, (1.0, -2.4, 1.3), (0.0, 0.0, 0.9), 35.0, 0.3),
    2: (33, rock_field, (4.0, -11.0, 9.0), (0.0, 0.0, 0.0), 24.0, 0.8),
    3: (34, duck, (0.55, -0.9, 0.45), (0.0, 0.1, 0.1), 40.0, 0.05),
}


def build(variant):
    seed, builder, at, target, lens, radius = VARIANTS[variant]
    mat = kit.grey()
    b = kit.Builder()
    builder(b, kit.rng(seed), mat)
    b.build("Ground", mat)
    kit.finish(at, target, lens, radius, clip_start=0.02)
