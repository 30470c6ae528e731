"""Scene-building helpers shared by every reference scene's build.py (run inside Blender):
plain materials, a mesh builder for flat-shaded boxes, prisms and quads, boxes, a look-at
camera, and the protocol's common scene settings (docs/reference_scenes.md).

`aolab reference` hashes this file with each scene's build.py and manifest, so a change here
renders every scene again.
"""
import math

import bpy
from mathutils import Vector


def make_material(name, rgb, emission_strength=0.0):
    """A plain Principled BSDF of base colour rgb (linear); emissive in rgb if strength > 0."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
    if emission_strength > 0.0:
        # Blender 4.0 renamed the Principled BSDF's "Emission" input "Emission Color"
        emission = bsdf.inputs.get("Emission Color") or bsdf.inputs["Emission"]
        emission.default_value = (*rgb, 1.0)
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
