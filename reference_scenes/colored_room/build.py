"""AO Lab reference scene `colored_room`: strongly coloured walls and objects, an emissive panel.

Run inside Blender by the bridge after `read_factory_settings(use_empty=True)`; it builds the
scene into `bpy.context.scene`. Deterministic: no randomness, no files.

A closed room 6 m x 6 m x 3 m (metres, z up; interior x in [-3, 3], y in [0, 6]) in the
manner of a Cornell box: red wall on the left, green on the right, light grey back wall,
floor and ceiling. A tall blue box stands near the red wall, a low yellow box near the green
wall, a yellow cylinder by the back wall, a faceted white sphere and a small blue cube on the
floor. An emissive panel (strength 10) hangs on the back wall and a small emissive cube sits
on the floor beside the yellow box. The camera stands near the front wall, looking in.
For colour bleeding (coloured diffuse albedo beside grey surfaces) and luminance sensitivity
(emitters that should not be darkened like ordinary surfaces).
"""
import math

import bpy
from mathutils import Vector

RADIUS = 0.5  # AO distance R in metres (manifest "radius")
ROOM_X, ROOM_Y, ROOM_Z = 3.0, 6.0, 3.0  # x in [-ROOM_X, ROOM_X], y in [0, ROOM_Y]
EMISSION_STRENGTH = 10.0


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


def add_sphere(name, centre, radius, mat, segments=32, rings=16):
    """A flat-shaded UV sphere: poles on the z axis, `rings` bands of `segments` faces,
    outward normals. Built vertex by vertex (not with bmesh.ops.create_uvsphere, whose loop
    order varies from run to run and with it the bridge's scene hash)."""
    mb = MeshBuilder()
    mb.verts.append((0.0, 0.0, radius))
    for i in range(1, rings):
        polar = math.pi * i / rings
        for k in range(segments):
            azimuth = 2.0 * math.pi * k / segments
            mb.verts.append((radius * math.sin(polar) * math.cos(azimuth),
                             radius * math.sin(polar) * math.sin(azimuth),
                             radius * math.cos(polar)))
    mb.verts.append((0.0, 0.0, -radius))
    south = len(mb.verts) - 1

    def ring(i, k):  # vertex k of latitude ring i (1 ... rings - 1)
        return 1 + (i - 1) * segments + k % segments

    for k in range(segments):
        mb.faces.append((0, ring(1, k), ring(1, k + 1)))
        for i in range(1, rings - 1):
            mb.faces.append((ring(i, k), ring(i + 1, k), ring(i + 1, k + 1), ring(i, k + 1)))
        mb.faces.append((ring(rings - 1, k), south, ring(rings - 1, k + 1)))
    return mb.build(name, mat, location=centre)


def build():
    scene = bpy.context.scene
    grey = make_material("Light_Grey", (0.7, 0.7, 0.7))
    red = make_material("Red", (0.80, 0.04, 0.04))
    green = make_material("Green", (0.05, 0.65, 0.05))
    blue = make_material("Blue", (0.04, 0.10, 0.80))
    yellow = make_material("Yellow", (0.85, 0.70, 0.04))
    white = make_material("White", (0.85, 0.85, 0.85))
    light = make_material("Emitter", (1.0, 0.95, 0.85), emission_strength=EMISSION_STRENGTH)

    x, y, z = ROOM_X, ROOM_Y, ROOM_Z
    mb = MeshBuilder()  # grey shell: floor, ceiling, back and front walls (inward normals)
    mb.quad((-x, 0, 0), (x, 0, 0), (x, y, 0), (-x, y, 0))      # floor
    mb.quad((-x, 0, z), (-x, y, z), (x, y, z), (x, 0, z))      # ceiling
    mb.quad((-x, y, 0), (x, y, 0), (x, y, z), (-x, y, z))      # back wall, normal -y
    mb.quad((-x, 0, 0), (-x, 0, z), (x, 0, z), (x, 0, 0))      # front wall, normal +y
    mb.build("Room", grey)
    mb = MeshBuilder()
    mb.quad((-x, 0, 0), (-x, y, 0), (-x, y, z), (-x, 0, z))    # left wall, normal +x
    mb.build("Wall_Red", red)
    mb = MeshBuilder()
    mb.quad((x, 0, 0), (x, 0, z), (x, y, z), (x, y, 0))        # right wall, normal -x
    mb.build("Wall_Green", green)

    mb = MeshBuilder()
    mb.box((-0.4, -0.4, 0.0), (0.4, 0.4, 1.7))
    mb.build("Box_Blue_Tall", blue, (-2.2, 4.3, 0.0), 18.0)
    mb = MeshBuilder()
    mb.box((-0.5, -0.5, 0.0), (0.5, 0.5, 0.6))
    mb.build("Box_Yellow_Low", yellow, (1.9, 3.5, 0.0), -22.0)
    mb = MeshBuilder()
    mb.prism(0.6, 5.45, 0.35, 0.0, 1.1, 32)
    mb.build("Cylinder_Yellow", yellow)
    add_sphere("Sphere_White", (-0.7, 3.1, 0.45), 0.45, white)
    mb = MeshBuilder()
    mb.box((-0.2, -0.2, 0.0), (0.2, 0.2, 0.4))
    mb.build("Cube_Blue", blue, (0.25, 2.7, 0.0), 40.0)

    # Emitters: a light panel 5 cm proud of the back wall, a small glowing cube on the floor.
    add_box("Panel_Emissive", (-1.5, y - 0.05, 1.3), (-0.1, y, 2.2), light)
    mb = MeshBuilder()
    mb.box((-0.15, -0.15, 0.0), (0.15, 0.15, 0.3))
    mb.build("Cube_Emissive", light, (1.05, 2.9, 0.0), 10.0)

    cam = add_camera("Camera", (0.0, 0.3, 1.75), (0.0, 4.5, 0.7), 18.0)
    finish_scene(scene, cam, RADIUS)


if __name__ == "__main__":
    build()
