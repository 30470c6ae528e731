"""Inside Blender: the intrinsics the bridge stores reconstruct Cycles' Position pass to
1e-4 relative, for AUTO/HORIZONTAL/VERTICAL sensor fits, shifts and non-square pixels.
Prints `RESULT {config: max relative error}`."""
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import scene_from_argv, use_checkout  # noqa: E402

use_checkout()
import bpy  # noqa: E402
import numpy as np  # noqa: E402
from aolab.bridge import exr  # noqa: E402

from aolab_blender.export.scene_record import camera_record  # noqa: E402

scene = scene_from_argv()
cam = scene.camera
r, c = scene.render, scene.cycles
r.engine = "CYCLES"
c.device = "CPU"
c.samples = 1
c.use_denoising = False
c.use_adaptive_sampling = False
c.filter_width = 0.01
r.image_settings.file_format = "OPEN_EXR_MULTILAYER"
r.image_settings.color_depth = "32"
vl = bpy.context.view_layer
vl.use_pass_position = True
vl.use_pass_z = True

configs = {
    "auto_wide": dict(res=(64, 36), fit="AUTO", shift=(0, 0), aspect=(1, 1)),
    "auto_tall_shift": dict(res=(36, 64), fit="AUTO", shift=(0.1, -0.05), aspect=(1, 1)),
    "horizontal_shift_aspect": dict(res=(60, 40), fit="HORIZONTAL", shift=(-0.07, 0.12),
                                    aspect=(2, 1)),
    "vertical_shift": dict(res=(64, 36), fit="VERTICAL", shift=(0.05, 0.08), aspect=(1, 1)),
    "vertical_aspect": dict(res=(48, 48), fit="VERTICAL", shift=(0.0, -0.1), aspect=(1, 1.5)),
    "auto_aspect_tall": dict(res=(40, 60), fit="AUTO", shift=(0.02, 0.03), aspect=(1, 2)),
}
results = {}
tmp = tempfile.mkdtemp()
for name, cfg in configs.items():
    r.resolution_x, r.resolution_y = cfg["res"]
    r.resolution_percentage = 100
    cam.data.sensor_fit = cfg["fit"]
    cam.data.sensor_height = 20.0
    cam.data.shift_x, cam.data.shift_y = cfg["shift"]
    r.pixel_aspect_x, r.pixel_aspect_y = cfg["aspect"]
    bpy.context.view_layer.update()
    path = os.path.join(tmp, f"{name}.exr")
    r.filepath = path
    bpy.ops.render.render(write_still=True)
    ch = exr.read_channels(path)
    depth = exr.find_pass(ch, "Depth", ("Z",))[..., 0]
    position = exr.find_pass(ch, "Position", ("X", "Y", "Z"))
    rec = camera_record(scene, cam)
    h, w = depth.shape
    j, i = np.mgrid[0:h, 0:w]
    valid = depth < 1e9
    d = depth.astype(np.float64)
    view = np.stack([(i + 0.5 - rec["cx"]) / rec["fx"] * d, -(j + 0.5 - rec["cy"]) / rec["fy"] * d,
                     -d, np.ones_like(d)], -1)
    world = view @ np.array(rec["camera_to_world"]).T
    err = np.linalg.norm(world[..., :3] - position, axis=-1) / np.maximum(d, 1e-9)
    results[name] = {"max_rel": float(err[valid].max()), "valid": int(valid.sum()),
                     "size": [w, h]}
print("RESULT " + json.dumps(results))
