"""Inside Blender: the add-on (installed by scripts/install_addon.sh, as in addon_check.py) on
scenes a user can make that the methods cannot score or see. Prints one JSON line
`RESULT {...}`.

    hostile_check.py -- hostile SCENE.py CACHE OUT_DIR
        the tiny scene, changed step by step: its camera scaled to zero, then moved to a
        location beyond float range (every operator and Live refuse, naming the camera, and
        nothing enters the cache); an object scaled 1e7 (everything works); a tuned-presets
        file gone bad (the menus keep the built-in presets, the panel names the file); the
        camera turned to the sky (an all-background frame), then every object deleted: Preview
        and Render Reference work, Compare and Write Report say there is nothing to score,
        Live computes.
"""
import json
import math
import os
import sys
from types import SimpleNamespace

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import ADDON, addon_module, addon_on_scene, call, panel_text  # noqa: E402

import addon_utils  # noqa: E402
import bpy  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
mode, scene_script, cache, out_dir = args[:4]

scene = addon_on_scene(scene_script, cache)
live, properties = (addon_module(n) for n in ("live", "properties"))
s = scene.aolab
session = bpy.context.window_manager.aolab
cam = scene.camera
OPERATORS = ("preview", "render_reference", "compare", "write_report")


def cached() -> list[str]:
    return sorted(os.listdir(cache)) if os.path.isdir(cache) else []


def live_once() -> dict:
    """Live switched on for every ticked method, its timer run to the end, switched off."""
    before = dict(live._state.stats)
    session.live = True
    common.pump(live)
    out = {"message": session.live_message, "error": session.live_message_is_error,
           "applied": live._state.stats["applied"] - before["applied"],
           "frames": s.live_frames}
    session.live = False
    return out


def every_operator(name: str) -> dict:
    """Each operator, then Live; with the metrics of Compare's table."""
    s.report_dir = os.path.join(out_dir, f"report_{name}")
    out = {}
    for op in OPERATORS:
        out[op] = call(getattr(bpy.ops.aolab, op))
        if op == "compare":
            out["metrics"] = [json.loads(row.metrics_json) for row in session.results
                              if row.metrics_json and session.results_kind == "Compare"]
    out["live"] = live_once()
    return out


r = {}
# A camera scaled to zero has no view direction: its sidecar would hold NaN.
before = cached()
cam.scale = (0.0, 0.0, 0.0)
r["zero_scale"] = every_operator("zero_scale")
cam.scale = (1.0, 1.0, 1.0)
cam.location.x = 1e39   # Blender keeps the largest float32, 3.4e38
r["infinite_location"] = every_operator("infinite_location")
cam.location.x = 2.2
r["cache_after_camera"] = cached() == before

# An object scaled 1e7: far larger than the frame, depths still finite.
box = bpy.data.objects["Box"]
box.scale = (1e7, 1e7, 1e7)
r["huge"] = every_operator("huge")
box.scale = (0.8, 0.8, 0.8)

# A tuned-presets file gone bad: the menus keep the built-in presets, the panel says why,
# and a tuned preset picked from a menu drawn before the file went bad is refused.
good = os.environ.get("AOLAB_TUNED_PRESETS")
g = properties.method_group(scene, "hbao")
tuned = [n for n, _, _ in properties._preset_items(g, bpy.context) if n.startswith("tuned-")]
bad = os.path.join(out_dir, "tuned_bad.json")
with open(bad, "w") as f:
    json.dump({"methods": {"hbao": {"presets": {"tuned-xms": {"directions": 4}}}}}, f)
os.environ["AOLAB_TUNED_PRESETS"] = bad
session.message = ""
picked = SimpleNamespace(method_name="hbao", preset=tuned[0] if tuned else "tuned-100ms")
properties.apply_preset(picked, bpy.context)   # what Blender calls when a menu item is picked
r["bad_tuned"] = {"tuned_before": tuned, "apply_message": session.message,
                  "menu": [n for n, _, _ in properties._preset_items(g, bpy.context)],
                  "panel": panel_text()}
g.preset = "low"
r["bad_tuned"]["low"] = {"directions": g.directions, "steps": g.steps, "blur": g.use_blur}
if good is None:
    del os.environ["AOLAB_TUNED_PRESETS"]
else:
    os.environ["AOLAB_TUNED_PRESETS"] = good
g.preset = "default"

# The camera turned to the sky: geometry in the scene, none in the frame.
cam.rotation_euler = (math.pi, 0.0, 0.0)
r["sky"] = every_operator("sky")
cam.rotation_euler = (1.15, 0.0, 0.65)

# No geometry at all.
for obj in [o for o in bpy.data.objects if o.type == "MESH"]:
    bpy.data.objects.remove(obj)
r["empty"] = every_operator("empty")

addon_utils.disable(ADDON, default_set=True)
print("RESULT " + json.dumps(r, default=str))
