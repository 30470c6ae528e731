"""The motion tests' moving object (tests/python/api/test_motion.py): a still camera (64x48,
fx = 64 px) looking down -z at a plane 4 m away, and a 1 m cube whose front face is 2.5 m
away moving 0.15625 m to the right per frame (linear keys, frames 1-3): its pixels move
exactly 4 px to the right per frame, the plane's not at all. Run by the bridge into an empty
factory file (the reference_scenes build-script protocol)."""
import runpy
from pathlib import Path

import bpy

kit = runpy.run_path(str(Path(__file__).with_name("motion_kit.py")))
scene = bpy.context.scene
bpy.ops.mesh.primitive_plane_add(size=100, location=(0, 0, -4))
bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, -3))
kit["key_linearly"](bpy.context.active_object, {1: (-0.15625, 0, -3), 3: (0.15625, 0, -3)})
kit["camera"](scene)
kit["finish"](scene)
