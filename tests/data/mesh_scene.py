"""A small scene for the `mesh` pass: geometry whose render differs from the viewport.
Run by the bridge inside an empty factory file (the reference_scenes build-script protocol).

In view of the camera (each 1 m cube = 12 triangles as rendered):
- Floor: a flat box, 12;
- Smooth: a cube with a Subdivision modifier at level 1 in the viewport, 2 in renders:
  6 faces x 4^2 quads x 2 = 192 triangles (the viewport would give 48);
- Row: a cube with an Array modifier of 3 that is off in the viewport, on in renders: 36;
- Prop (in the collection Props, excluded from the view layer) seen through two collection
  instances, one of them mirrored (scale x -1): 12 each;
- ViewportHidden (hide_viewport) and EyeHidden (hide_set) are rendered: 12 each.
Out of view: RenderHidden (hide_render) and NoShadow (visible_shadow off) are not exported;
Tube (a curve), Blob (a metaball) and the 10 particle instances of Prop on Emitter (whose own
faces are not rendered: show_instancer_for_render off) are, at their render settings.
"""
import bpy

scene = bpy.context.scene


def box(name, location, scale, collection=None):
    mesh = bpy.data.meshes.new(name)
    s = 0.5
    verts = [(x, y, z) for x in (-s, s) for y in (-s, s) for z in (-s, s)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4),
             (1, 5, 7, 3)]
    mesh.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new(name, mesh)
    (collection or scene.collection).objects.link(obj)
    obj.location, obj.scale = location, scale
    return obj


box("Floor", (0, 0, -0.05), (8, 8, 0.1))
smooth = box("Smooth", (-0.9, 1.0, 0.6), (1, 1, 1))
sub = smooth.modifiers.new("Subdivision", "SUBSURF")
sub.levels, sub.render_levels = 1, 2
row = box("Row", (0.6, 1.8, 0.25), (0.4, 0.4, 0.4))
arr = row.modifiers.new("Array", "ARRAY")
arr.count = 3
arr.relative_offset_displace = (1.5, 0, 0)
arr.show_viewport = False

props = bpy.data.collections.new("Props")
scene.collection.children.link(props)
box("Prop", (0, 0, 0.2), (0.4, 0.4, 0.4), props)
bpy.context.view_layer.layer_collection.children["Props"].exclude = True
for name, location, scale in (("PropsA", (0.9, 0.2, 0.0), (1, 1, 1)),
                              ("PropsB", (-0.2, -0.2, 0.0), (-1, 1, 1))):
    empty = bpy.data.objects.new(name, None)
    empty.instance_type = "COLLECTION"
    empty.instance_collection = props
    empty.location, empty.scale = location, scale
    scene.collection.objects.link(empty)

box("ViewportHidden", (1.6, 0.6, 0.15), (0.3, 0.3, 0.3)).hide_viewport = True
eye = box("EyeHidden", (-0.3, 0.6, 0.1), (0.2, 0.2, 0.2))
box("RenderHidden", (0, -6, 0.5), (1, 1, 1)).hide_render = True
box("NoShadow", (2, -6, 0.5), (1, 1, 1)).visible_shadow = False

# Out of view, with viewport and render settings that differ: a bevelled curve (resolution
# 2 in the viewport, 6 in renders), a metaball (0.5 and 0.2) and a particle system showing
# 50 % of its 10 instances of Prop in the viewport.
curve = bpy.data.curves.new("Tube", "CURVE")
curve.dimensions, curve.bevel_depth, curve.bevel_resolution = "3D", 0.05, 1
curve.resolution_u, curve.render_resolution_u = 2, 6
spline = curve.splines.new("BEZIER")
spline.bezier_points.add(1)
for point, co in zip(spline.bezier_points, ((0, 0, 0), (1, 0, 0.5))):
    point.co, point.handle_left_type, point.handle_right_type = co, "AUTO", "AUTO"
tube = bpy.data.objects.new("Tube", curve)
scene.collection.objects.link(tube)
tube.location = (-3, -6, 0.5)
ball = bpy.data.metaballs.new("Blob")
ball.resolution, ball.render_resolution = 0.5, 0.2
ball.elements.new().radius = 0.6
blob = bpy.data.objects.new("Blob", ball)
scene.collection.objects.link(blob)
blob.location = (-5, -6, 0.5)
emitter = box("Emitter", (4, -6, 0), (1, 1, 0.1))
emitter.show_instancer_for_render = False
system = emitter.modifiers.new("Particles", "PARTICLE_SYSTEM").particle_system
settings = system.settings
settings.count, settings.frame_start, settings.frame_end = 10, 1, 1
settings.physics_type, settings.render_type = "NO", "OBJECT"
settings.instance_object = bpy.data.objects["Prop"]
settings.display_percentage = 50

cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(cam)
cam.location = (2.2, -2.5, 1.8)
cam.rotation_euler = (1.15, 0, 0.65)
scene.camera = cam
bpy.context.view_layer.update()
eye.hide_set(True)
render = scene.render
render.resolution_x, render.resolution_y, render.resolution_percentage = 64, 48, 100
world = bpy.data.worlds.new("World")
scene.world = world
world.light_settings.distance = 0.5
