"""The motion tests' pan (tests/python/api/test_motion.py): a camera looking down -z at a plane
4 m away (planar depth 4), 64x48 with fx = 64 px, moving 0.125 m to the left per frame
(linear keys, frames 1-3), so the image content moves exactly 2 px to the right per frame.
The plane ends at x = 0.95 m: the right-hand columns are background. Run by the bridge into
an empty factory file (the reference_scenes build-script protocol)."""
import runpy
from pathlib import Path

import bpy

kit = runpy.run_path(str(Path(__file__).with_name("motion_kit.py")))
scene = bpy.context.scene
bpy.ops.mesh.primitive_plane_add(size=1, location=(-1.025, 0, -4))
bpy.context.active_object.scale = (3.95, 8, 1)        # x from -3 to 0.95, y from -4 to 4
kit["key_linearly"](kit["camera"](scene), {1: (0, 0, 0), 3: (-0.25, 0, 0)})
kit["finish"](scene)
