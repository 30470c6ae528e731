"""Helpers of the corpus scenes (reference_scenes/families/*.py), run inside Blender: a mesh
builder for shapes at any orientation (oriented boxes, cylinders between two points, gears,
height fields, displaced rocks), seeded randomness, model import from Debian's
assimp-testmodels, and the corpus's common finish.

Every corpus scene's manifest lists this file and its family module under "uses", so that
`aolab reference` hashes them with the scene: a change here renders the corpus again.

Randomness: `random.Random(seed)` and only its `random()` / `uniform()`, whose sequences are
the same in every Python 3 (Blender 3.4 embeds 3.10, 4.3 embeds 3.11); noise from
`mathutils.noise` with a fixed basis, which takes no seed (a seed shifts its domain).
"""
import math
import os
import random

import bpy
import mathutils
from mathutils import Matrix, Vector

from scene_kit import add_camera, finish_scene, make_material

MODELS = "/usr/share/assimp/models"  # Debian's assimp-testmodels


def circle(radius, segments):
    """A regular polygon's outline (counter-clockwise) for Builder.profile."""
    return [(radius * math.cos(2.0 * math.pi * k / segments),
             radius * math.sin(2.0 * math.pi * k / segments)) for k in range(segments)]


def rng(seed):
    return random.Random(seed)


def grey(value=0.6):
    return make_material("Grey", (value, value, value))


def yaw(degrees):
    return Matrix.Rotation(math.radians(degrees), 3, 'Z')


class Builder:
    """Accumulates flat-shaded parts into one mesh: each part is built in its own frame and
    placed by a 3x3 matrix and an offset."""

    def __init__(self):
        self.verts = []
        self.faces = []

    def add(self, verts, faces, matrix=None, offset=(0.0, 0.0, 0.0)):
        m = matrix or Matrix.Identity(3)
        o = Vector(offset)
        n = len(self.verts)
        self.verts += [tuple(m @ Vector(v) + o) for v in verts]
        self.faces += [tuple(n + i for i in f) for f in faces]

    def box(self, lo, hi):
        """Axis-aligned box from corner lo to corner hi."""
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        self.add([(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
                  (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)], BOX_FACES)

    def obox(self, centre, size, matrix=None):
        """A box of full size (sx, sy, sz) centred on centre, turned by matrix."""
        sx, sy, sz = (s / 2.0 for s in size)
        verts = [(-sx, -sy, -sz), (sx, -sy, -sz), (sx, sy, -sz), (-sx, sy, -sz),
                 (-sx, -sy, sz), (sx, -sy, sz), (sx, sy, sz), (-sx, sy, sz)]
        self.add(verts, BOX_FACES, matrix, centre)

    def cylinder(self, p0, p1, radius, segments=12):
        """A closed faceted cylinder from point p0 to point p1."""
        self.profile(p0, p1, circle(radius, segments))

    def gear(self, p0, p1, radius, teeth, depth):
        """A spur gear: a prism whose outline alternates radius and radius - depth."""
        outline = []
        for k in range(teeth * 4):
            r = radius if (k % 4) in (1, 2) else radius - depth
            t = 2.0 * math.pi * k / (teeth * 4)
            outline.append((r * math.cos(t), r * math.sin(t)))
        self.profile(p0, p1, outline)

    def profile(self, p0, p1, outline):
        """A closed prism of a convex or star-shaped 2D outline (counter-clockwise), swept
        from p0 to p1."""
        axis = Vector(p1) - Vector(p0)
        m = axis.normalized().to_track_quat('Z', 'Y').to_matrix()
        h = axis.length
        n = len(outline)
        verts = [(x, y, 0.0) for x, y in outline] + [(x, y, h) for x, y in outline]
        faces = [tuple(reversed(range(n))), tuple(range(n, 2 * n))]
        faces += [(k, (k + 1) % n, n + (k + 1) % n, n + k) for k in range(n)]
        self.add(verts, faces, m, p0)

    def grid(self, heights, x0, y0, step):
        """A height field: heights[j][i] at (x0 + i step, y0 + j step), two triangles a cell."""
        rows, cols = len(heights), len(heights[0])
        verts = [(x0 + i * step, y0 + j * step, heights[j][i])
                 for j in range(rows) for i in range(cols)]
        faces = []
        for j in range(rows - 1):
            for i in range(cols - 1):
                a = j * cols + i
                faces += [(a, a + 1, a + cols + 1), (a, a + cols + 1, a + cols)]
        self.add(verts, faces)

    def rock(self, centre, size, seed, roughness=0.35, subdivisions=3):
        """A boulder: an icosphere of radii size, displaced by fractal noise shifted by seed."""
        import bmesh
        bm = bmesh.new()
        bmesh.ops.create_icosphere(bm, subdivisions=subdivisions, radius=1.0)
        shift = Vector((seed * 7.31, seed * 3.17, seed * 5.53))
        verts = []
        for v in bm.verts:
            n = v.co.normalized()
            d = mathutils.noise.fractal(n * 1.3 + shift, 0.8, 2.0, 4,
                                        noise_basis='PERLIN_ORIGINAL')
            r = 1.0 + roughness * d
            # flattened below: the rock sits in the ground rather than on a point
            verts.append((n.x * r * size[0], n.y * r * size[1],
                          max(n.z * r * size[2], -0.2 * size[2])))
        faces = [tuple(v.index for v in f.verts) for f in bm.faces]
        bm.free()
        self.add(verts, faces, offset=centre)

    def build(self, name, mat, smooth=False):
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata(self.verts, [], self.faces)
        mesh.validate()
        for poly in mesh.polygons:
            poly.use_smooth = smooth
        mesh.materials.append(mat)
        obj = bpy.data.objects.new(name, mesh)
        bpy.context.scene.collection.objects.link(obj)
        return obj


BOX_FACES = ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))


def import_model(relpath, mat, size, location=(0.0, 0.0, 0.0), turn_deg=0.0, up='Z'):
    """Imports a model of assimp-testmodels, grey, scaled so that its largest extent is size
    metres, turned about z, standing on z = 0 at location. Returns its mesh objects."""
    path = os.path.join(MODELS, relpath)
    if not os.path.isfile(path):
        raise FileNotFoundError("%s not found: install Debian's assimp-testmodels package" % path)
    scene = bpy.context.scene
    before = set(scene.objects)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".obj":
        forward = 'NEGATIVE_Z' if up == 'Y' else 'NEGATIVE_Y'
        bpy.ops.wm.obj_import(filepath=path, up_axis=up, forward_axis=forward)
    elif ext == ".dae":
        bpy.ops.wm.collada_import(filepath=path)
    elif ext == ".blend":
        with bpy.data.libraries.load(path) as (src, dst):
            dst.objects = src.objects
        for ob in [ob for ob in dst.objects if ob is not None]:
            if ob.type == 'MESH':
                scene.collection.objects.link(ob)
            else:   # the file's camera and lamps would take the names the scene uses
                bpy.data.objects.remove(ob, do_unlink=True)
    else:
        raise ValueError("no importer for %s" % path)
    meshes = [ob for ob in scene.objects if ob not in before and ob.type == 'MESH']
    if not meshes:
        raise RuntimeError("no mesh imported from %s" % path)
    place(meshes, mat, size, location, turn_deg)
    for ob in [ob for ob in scene.objects if ob not in before and ob.type != 'MESH']:
        bpy.data.objects.remove(ob, do_unlink=True)   # empties, cameras, lights: after place
    return meshes


def place(meshes, mat, size, location, turn_deg):
    """Applies each object's transform, then scales, turns and moves them as one."""
    bpy.context.view_layer.update()
    worlds = [ob.matrix_world.copy() for ob in meshes]   # before any parent is cleared
    lo, hi = Vector((math.inf,) * 3), Vector((-math.inf,) * 3)
    for ob, world in zip(meshes, worlds):
        if ob.data.users > 1:   # an instanced mesh: each object gets its own copy to move
            ob.data = ob.data.copy()
        ob.parent = None
        ob.matrix_world = Matrix.Identity(4)
        ob.data.transform(world)
        for v in ob.data.vertices:
            lo = Vector(map(min, lo, v.co))
            hi = Vector(map(max, hi, v.co))
        ob.data.materials.clear()
        ob.data.materials.append(mat)
    scale = size / max(hi - lo)
    centre = Vector(((lo.x + hi.x) / 2, (lo.y + hi.y) / 2, lo.z))
    m = (Matrix.Translation(Vector(location)) @ Matrix.Rotation(math.radians(turn_deg), 4, 'Z')
         @ Matrix.Scale(scale, 4) @ Matrix.Translation(-centre))
    for ob in meshes:
        ob.data.transform(m)
        ob.data.update()
    for extra in [m for m in bpy.data.materials if m.users == 0]:
        bpy.data.materials.remove(extra)


def finish(camera_at, target, lens, radius, clip_start=0.05, clip_end=1000.0):
    """The camera (36 mm sensor) and the protocol's common settings (scene_kit.finish_scene);
    the corpus resolution comes from the manifest."""
    cam = add_camera("Camera", camera_at, target, lens, clip_start=clip_start, clip_end=clip_end)
    finish_scene(bpy.context.scene, cam, radius)
