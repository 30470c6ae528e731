"""Two coincident faces, for the check of the reference's definition on them
(docs/conventions.md, "Coincident faces"): a floor quad, and a second object whose top face
lies exactly in the floor's plane over the right half of the view (a 1 cm slab flush with the
floor, as a panel flush with a cabinet's side). Nothing else within R of the floor, so away
from the slab every pixel is unoccluded. Run by the bridge into an empty factory file."""
import bpy

scene = bpy.context.scene


def quad_mesh(name, verts, faces):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.update()
    obj = bpy.data.objects.new(name, me)
    scene.collection.objects.link(obj)
    return obj


quad_mesh("Floor", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)], [(0, 1, 2, 3)])
# A box from z = -0.01 to z = 0 over x in [0, 3], y in [-3, 3]: its top face coincides with
# the floor.
x0, x1, y0, y1, z0, z1 = 0.0, 3.0, -3.0, 3.0, -0.01, 0.0
v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
     (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
quad_mesh("Slab", v, f)
cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(cam)
cam.location = (0, 0, 3)            # straight down at the floor
cam.rotation_euler = (0, 0, 0)
cam.data.lens = 35
scene.camera = cam
render = scene.render
render.resolution_x, render.resolution_y, render.resolution_percentage = 48, 32, 100
world = bpy.data.worlds.new("World")
scene.world = world
world.light_settings.distance = 0.5
