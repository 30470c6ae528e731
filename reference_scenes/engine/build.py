"""AO Lab reference scene `engine`: the Khronos 2CylinderEngine, imported from Debian.

Run inside Blender by the bridge after `read_factory_settings(use_empty=True)`; it builds the
scene into `bpy.context.scene`. The model is not in the repository: it is imported at build
time from Debian's assimp-testmodels package (apt-get install assimp-testmodels).

2CylinderEngine by Khronos Group (glTF-Sample-Models), CC-BY 4.0.

The glTF is in millimetres (it imports 743 x 268 x 273 units big); this script scales its
root by 0.001 so the scene is in metres like the others (0.743 m x 0.268 m x 0.273 m), drops
the camera the file carries, gives every mesh one grey material, and checks the bounding box,
so that R (0.04 m, 5.4 % of the length) keeps its meaning if the packaged model ever changes.
The meshes keep the file's smooth shading and custom normals.
"""
import math
import os

import bpy
from mathutils import Vector

RADIUS = 0.04  # AO distance R in metres (manifest "radius")
MODEL = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"
SCALE = 0.001  # model units (mm) to metres
EXPECTED_SIZE = (0.7434, 0.2680, 0.2730)  # bounding box after scaling, metres
EXPECTED_TRIANGLES = 110342


# ---- scene-building helpers (the same block in every reference scene's build.py) ----------


def make_material(name, rgb, emission_strength=0.0):
    """A plain Principled BSDF of base colour rgb (linear); emissive in rgb if strength > 0."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
    if emission_strength > 0.0:
        bsdf.inputs["Emission"].default_value = (*rgb, 1.0)
        bsdf.inputs["Emission Strength"].default_value = emission_strength
    mat.diffuse_color = (*rgb, 1.0)
    return mat


class MeshBuilder:
    """Accumulates flat-shaded boxes, prisms and quads into one mesh (local coordinates)."""

    def __init__(self):
        self.verts = []
        self.faces = []

    def quad(self, a, b, c, d):
        """One quad a-b-c-d, counter-clockwise seen from the side its normal points to."""
        n = len(self.verts)
        self.verts += [tuple(a), tuple(b), tuple(c), tuple(d)]
        self.faces.append((n, n + 1, n + 2, n + 3))

    def box(self, lo, hi):
        """Axis-aligned box from corner lo to corner hi, outward normals."""
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        n = len(self.verts)
        self.verts += [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
                       (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
        quads = ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))
        self.faces += [tuple(n + i for i in q) for q in quads]

    def prism(self, cx, cy, radius, z0, z1, segments, phase=0.0):
        """Vertical closed prism (a faceted cylinder) of the given circumradius."""
        n = len(self.verts)
        for z in (z0, z1):
            for k in range(segments):
                t = phase + 2.0 * math.pi * k / segments
                self.verts.append((cx + radius * math.cos(t), cy + radius * math.sin(t), z))
        self.faces.append(tuple(n + k for k in reversed(range(segments))))
        self.faces.append(tuple(n + segments + k for k in range(segments)))
        for k in range(segments):
            k1 = (k + 1) % segments
            self.faces.append((n + k, n + k1, n + segments + k1, n + segments + k))

    def build(self, name, mat, location=(0.0, 0.0, 0.0), rotation_z_deg=0.0):
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata(self.verts, [], self.faces)
        mesh.validate()
        for poly in mesh.polygons:
            poly.use_smooth = False
        mesh.materials.append(mat)
        obj = bpy.data.objects.new(name, mesh)
        obj.location = location
        obj.rotation_euler = (0.0, 0.0, math.radians(rotation_z_deg))
        bpy.context.scene.collection.objects.link(obj)
        return obj


def add_box(name, lo, hi, mat):
    mb = MeshBuilder()
    mb.box(lo, hi)
    return mb.build(name, mat)


def add_camera(name, location, target, lens_mm, clip_start=0.05, clip_end=200.0):
    """A perspective camera at location looking at target, 36 mm sensor, auto fit."""
    cam_data = bpy.data.cameras.new(name)
    cam_data.type = 'PERSP'
    cam_data.lens = lens_mm
    cam_data.sensor_fit = 'AUTO'
    cam_data.sensor_width = 36.0
    cam_data.clip_start = clip_start
    cam_data.clip_end = clip_end
    cam = bpy.data.objects.new(name, cam_data)
    bpy.context.scene.collection.objects.link(cam)
    cam.location = location
    cam.rotation_mode = 'QUATERNION'
    cam.rotation_quaternion = (Vector(target) - Vector(location)).to_track_quat('-Z', 'Y')
    return cam


def finish_scene(scene, camera, radius):
    """The protocol's common part: active camera, 1280x720 at 100 %, a world with AO distance R."""
    scene.camera = camera
    scene.render.resolution_x = 1280
    scene.render.resolution_y = 720
    scene.render.resolution_percentage = 100
    world = bpy.data.worlds.new("World")
    scene.world = world
    world.light_settings.distance = radius

# ---- end of helpers ---------------------------------------------------------------------


def import_engine():
    if not os.path.isfile(MODEL):
        raise FileNotFoundError(
            "%s not found: install Debian's assimp-testmodels package" % MODEL)
    import numpy
    if "bool" not in numpy.__dict__:  # the bundled importer uses numpy.bool (gone in 1.24)
        numpy.bool = bool
    scene = bpy.context.scene
    before = set(scene.objects)
    bpy.ops.import_scene.gltf(filepath=MODEL)
    imported = [ob for ob in scene.objects if ob not in before]
    for ob in [ob for ob in imported if ob.type == 'CAMERA']:
        bpy.data.objects.remove(ob, do_unlink=True)
    imported = [ob for ob in scene.objects if ob not in before]
    roots = [ob for ob in imported if ob.parent is None]
    if len(roots) != 1:
        raise RuntimeError("expected one root object in %s, got %s"
                           % (MODEL, [ob.name for ob in roots]))
    root = roots[0]
    root.name = "Engine"
    root.location = root.location * SCALE
    root.scale = root.scale * SCALE
    return [ob for ob in imported if ob.type == 'MESH']


def check_engine(meshes):
    """Raise if the imported model is not the one R and the camera were chosen for."""
    bpy.context.view_layer.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    lo = Vector((math.inf,) * 3)
    hi = -lo
    triangles = 0
    for ob in meshes:
        mesh = ob.evaluated_get(depsgraph).data
        mesh.calc_loop_triangles()
        triangles += len(mesh.loop_triangles)
        mw = ob.matrix_world
        for v in mesh.vertices:
            w = mw @ v.co
            lo = Vector(map(min, lo, w))
            hi = Vector(map(max, hi, w))
    size = hi - lo
    if triangles != EXPECTED_TRIANGLES or any(
            abs(s - e) > 0.01 * e for s, e in zip(size, EXPECTED_SIZE)):
        raise RuntimeError("unexpected 2CylinderEngine: %d triangles, size %s (expected %d, %s)"
                           % (triangles, tuple(size), EXPECTED_TRIANGLES, EXPECTED_SIZE))
    return lo, hi


def build():
    scene = bpy.context.scene
    meshes = import_engine()
    check_engine(meshes)
    grey = make_material("Grey", (0.6, 0.6, 0.6))
    for ob in meshes:
        ob.data.materials.clear()
        ob.data.materials.append(grey)
    for mat in [m for m in bpy.data.materials if m.users == 0]:
        bpy.data.materials.remove(mat)
    cam = add_camera("Camera", (0.62, -0.98, 0.50), (0.0, 0.0, -0.045), 51.0,
                     clip_start=0.01, clip_end=100.0)
    finish_scene(scene, cam, RADIUS)


if __name__ == "__main__":
    build()
