"""Corpus family `mechanical`: machines and CAD parts: the Khronos 2CylinderEngine of
assimp-testmodels seen close, a seeded gearbox, a bracket assembly with bolt patterns and a
pipe manifold. Metres, z up; parts of millimetre to decimetre size.
"""

from families import kit

ENGINE = "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"


def engine(b, r, mat):
    import os
    import numpy
    if "bool" not in numpy.__dict__:   # the bundled glTF importer uses numpy.bool (gone in 1.24)
        numpy.bool = bool
    path = os.path.join(kit.MODELS, ENGINE)
    if not os.path.isfile(path):
        raise FileNotFoundError("%s not found: install Debian's assimp-testmodels package" % path)
    scene = kit.bpy.context.scene
    before = set(scene.objects)
    kit.bpy.ops.import_scene.gltf(filepath=path)
    meshes = [ob for ob in scene.objects if ob not in before and ob.type == 'MESH']
    kit.place(meshes, mat, 0.74, (0.0, 0.0, 0.0), 0.0)
    for ob in [ob for ob in scene.objects if ob not in before and ob.type != 'MESH']:
        kit.bpy.data.objects.remove(ob, do_unlink=True)
    b.box((-1.0, -1.0, -0.02), (1.0, 1.0, 0.0))   # the bench it stands on


def gearbox(b, r, mat):
    """An open gearbox: a base plate, two side walls with bearings, three shafts carrying
    seeded spur gears that mesh, ribs and bolts."""
    b.box((-0.3, -0.2, -0.02), (0.3, 0.2, 0.0))
    for y in (-0.15, 0.15):
        b.box((-0.28, y - 0.01, 0.0), (0.28, y + 0.01, 0.22))
        for x in (-0.2, 0.0, 0.2):
            b.box((x - 0.004, y - 0.05, 0.0), (x + 0.004, y - 0.01 if y > 0 else y + 0.05, 0.1))
    shafts = [(-0.16, 0.12), (0.0, 0.12), (0.14, 0.1)]
    for k, (x, z) in enumerate(shafts):
        b.cylinder((x, -0.18, z), (x, 0.18, z), 0.008, 12)
        for y in (-0.15, 0.15):
            b.cylinder((x, y - 0.02, z), (x, y + 0.02, z), 0.02, 16)
    radii = [0.07, 0.05, 0.06]
    for k, (x, z) in enumerate(shafts):
        y = -0.1 + 0.06 * k
        rad = radii[k] + r.uniform(-0.005, 0.005)
        b.gear((x, y, z), (x, y + 0.02, z), rad, int(rad * 400), 0.006)
        b.gear((x, y + 0.05, z), (x, y + 0.065, z), rad * 0.6, int(rad * 240), 0.005)
    for x in (-0.27, 0.27):
        for y in (-0.18, 0.18):
            b.cylinder((x, y, 0.0), (x, y, 0.012), 0.01, 6)


def plate_with_holes(b, x0, y0, x1, y1, z0, z1, hole, pitch):
    """A plate as a lattice of bars, leaving square holes of side `hole` at `pitch`."""
    nx, ny = int((x1 - x0) / pitch), int((y1 - y0) / pitch)
    web = (pitch - hole) / 2
    for i in range(nx + 1):
        x = x0 + i * pitch
        b.box((x - web, y0, z0), (x + web, y1, z1))
    for j in range(ny + 1):
        y = y0 + j * pitch
        b.box((x0, y - web, z0), (x1, y + web, z1))


def bracket(b, r, mat):
    """A bracket assembly: a perforated base plate, an upright with ribs, standoffs and a row
    of hex bolts, all within 0.2 m."""
    b.box((-0.3, -0.3, -0.01), (0.3, 0.3, 0.0))
    plate_with_holes(b, -0.1, -0.08, 0.1, 0.08, 0.0, 0.006, 0.012, 0.025)
    b.box((-0.1, 0.04, 0.006), (0.1, 0.05, 0.12))
    for x in (-0.08, -0.02, 0.04, 0.09):
        b.obox((x, 0.02, 0.04), (0.004, 0.05, 0.05), kit.Matrix.Rotation(0.785, 3, 'X'))
    for k in range(6):
        x = -0.075 + 0.03 * k
        b.profile((x, -0.04, 0.006), (x, -0.04, 0.014), kit.circle(0.007, 6))   # hex head
        b.cylinder((x, -0.04, 0.014), (x, -0.04, 0.014 + r.uniform(0.004, 0.012)), 0.004, 8)
    for x in (-0.06, 0.06):
        b.cylinder((x, 0.02, 0.006), (x, 0.02, 0.06), 0.006, 10)
        b.box((x - 0.02, 0.005, 0.06), (x + 0.02, 0.045, 0.066))


def manifold(b, r, mat):
    """A pipe manifold on a floor: a header pipe on saddles, branch pipes with flanges and
    valves, a vertical riser against a wall."""
    b.box((-3.0, -3.0, -0.1), (3.0, 1.0, 0.0))
    b.box((-3.0, 1.0, 0.0), (3.0, 1.2, 3.0))
    b.cylinder((-2.0, 0.3, 0.6), (2.0, 0.3, 0.6), 0.15, 20)
    for x in (-1.6, 0.0, 1.6):
        b.box((x - 0.1, 0.1, 0.0), (x + 0.1, 0.5, 0.45))
    for k in range(5):
        x = -1.5 + 0.75 * k
        b.cylinder((x, 0.3, 0.6), (x, -1.2, 0.6), 0.06, 14)
        y = -0.4 - r.uniform(0.0, 0.3)
        b.cylinder((x, y - 0.02, 0.6), (x, y + 0.02, 0.6), 0.11, 16)   # flanges
        b.obox((x, y - 0.15, 0.6), (0.16, 0.2, 0.16))                  # the valve body
        b.cylinder((x, y - 0.15, 0.68), (x, y - 0.15, 0.85), 0.012, 8)
        b.cylinder((x, y - 0.15, 0.85), (x, y - 0.15, 0.87), 0.09, 16)  # hand wheel
    b.cylinder((2.0, 0.3, 0.6), (2.0, 0.3, 2.8), 0.15, 20)
    b.cylinder((2.0, 0.3, 1.5), (2.0, 1.0, 1.5), 0.03, 8)


# variant: (seed, builder, camera at, target, lens mm, R)
VARIANTS = {
    0: (71, engine, (-0.45, 0.55, 0.42), (0.0, 0.0, 0.12), 50.0, 0.02),
    1: (72, gearbox, (0.5, -0.12, 0.38), (0.0, 0.0, 0.09), 35.0, 0.02),
    2: (73, bracket, (0.18, -0.25, 0.22), (0.0, 0.0, 0.02), 35.0, 0.01),
    3: (74, manifold, (1.3, -2.0, 1.3), (0.0, -0.3, 0.5), 24.0, 0.15),
}


def build(variant):
    seed, builder, at, target, lens, radius = VARIANTS[variant]
    mat = kit.grey()
    b = kit.Builder()
    builder(b, kit.rng(seed), mat)
    b.build("Machine", mat)
    kit.finish(at, target, lens, radius, clip_start=0.005)
