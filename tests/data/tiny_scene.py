"""A tiny deterministic scene for the bridge tests: a floor, a box against a wall, a camera.
Run by the bridge inside an empty factory file (the reference_scenes build-script protocol)."""
import bpy

scene = bpy.context.scene


def box(name, location, scale):
    bpy.ops.mesh.primitive_cube_add(size=1, location=location)
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = scale
    return obj


box("Floor", (0, 0, -0.05), (8, 8, 0.1))
box("Wall", (0, 2, 1), (8, 0.2, 2))
box("Box", (0.3, 1.2, 0.4), (0.8, 0.8, 0.8))
cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(cam)
cam.location = (2.2, -2.5, 1.8)
cam.rotation_euler = (1.15, 0, 0.65)
scene.camera = cam
render = scene.render
render.resolution_x, render.resolution_y, render.resolution_percentage = 96, 54, 100
world = bpy.data.worlds.new("World")
scene.world = world
world.light_settings.distance = 0.75
