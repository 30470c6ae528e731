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
import sys
from pathlib import Path
import os

import bpy
from mathutils import Vector

RADIUS = 0.04  # AO distance R in metres (manifest "radius")
MODEL = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"
SCALE = 0.001  # model units (mm) to metres
EXPECTED_SIZE = (0.7434, 0.2680, 0.2730)  # bounding box after scaling, metres
EXPECTED_TRIANGLES = 110342


# The helpers shared by every scene (reference_scenes/scene_kit.py).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from scene_kit import add_camera, finish_scene, make_material  # noqa: E402


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
