"""A tiny animated scene for the sequence and cluster tests: tiny_scene.py's floor, wall and
box, and a camera that moves and turns over frames 1 to 4 (linear keys), at 48x27. Run by the
bridge into an empty factory file (the reference_scenes build-script protocol)."""
import runpy
from pathlib import Path

import bpy

runpy.run_path(str(Path(__file__).with_name("tiny_scene.py")), run_name="__main__")
scene = bpy.context.scene
cam = scene.camera
scene.frame_start, scene.frame_end = 1, 4
for frame, (x, z_rot) in {1: (2.2, 0.65), 4: (1.4, 0.45)}.items():
    cam.location.x = x
    cam.rotation_euler.z = z_rot
    cam.keyframe_insert("location", frame=frame)
    cam.keyframe_insert("rotation_euler", frame=frame)
for curve in cam.animation_data.action.fcurves:
    for key in curve.keyframe_points:
        key.interpolation = "LINEAR"
scene.frame_set(1)
scene.render.resolution_x, scene.render.resolution_y = 48, 27
