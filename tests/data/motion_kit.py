"""What the motion tests' scenes (motion_pan.py, motion_object.py) share: a 64x48 camera
looking down -z with fx = 64 px, objects keyed at frames 1 and 3 with linear interpolation,
frames 1-3, and a world with AO distance 0.5. Run with runpy by those build scripts."""
import bpy


def camera(scene):
    """The scene camera "Camera" at the origin, looking down -z, fx = 64 px at 64x48."""
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.lens, cam.data.sensor_width, cam.data.sensor_fit = 36, 36, "HORIZONTAL"
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam


def key_linearly(obj, positions: dict) -> None:
    """obj.location keyed at each frame of ``positions`` (frame -> (x, y, z)), linear."""
    for frame, position in positions.items():
        obj.location = position
        obj.keyframe_insert("location", frame=frame)
    for curve in obj.animation_data.action.fcurves:
        for key in curve.keyframe_points:
            key.interpolation = "LINEAR"


def finish(scene) -> None:
    """Frames 1-3 (left at 1), 64x48, a world with AO distance 0.5."""
    scene.frame_start, scene.frame_end = 1, 3
    scene.frame_set(1)
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("World")
    scene.world.light_settings.distance = 0.5
