"""Inside Blender: the AO Lab add-on, installed by scripts/install_addon.sh into the folders
of BLENDER_USER_SCRIPTS / BLENDER_USER_CONFIG. Prints one JSON line `RESULT {...}`.

    addon_check.py -- installed OUT_DIR
        run without --factory-startup: the saved preferences enable the add-on; checks where
        it was imported from, then disables it and lists what is left registered.
    addon_check.py -- flow TINY_SCENE.py CACHE OUT_DIR
        the tiny scene; Preview, Render Reference (8 spp), a cancelled Render Reference,
        Compare, Write Report and the user errors, all through bpy.ops. In -b mode there is
        no event loop, so the operators run their execute() path: the same job, waited for
        (their modal invoke() path is exercised by scripts/addon_screenshot.sh). The cancel
        goes through the job's cancel(), which Esc and the panel's Cancel button call.
"""
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (ADDON, addon_module, addon_on_scene, call, diff,  # noqa: E402
                    scene_state)

import addon_utils  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
mode = args[0]


def registered() -> list[str]:
    """What of the add-on is registered: its classes (bpy.types lists all but the
    preferences), the property groups, and the properties on Scene and WindowManager."""
    names = [n for n in dir(bpy.types) if n.startswith("AOLAB")]
    mod = sys.modules.get(ADDON)
    if mod is not None:
        names += [f"{c.__name__} (is_registered)" for c in getattr(mod, "classes", ())
                  if c.is_registered and c.__name__ not in names]
    if hasattr(bpy.types.Scene, "aolab"):
        names.append("Scene.aolab")
    if hasattr(bpy.types.WindowManager, "aolab"):
        names.append("WindowManager.aolab")
    return names


def results_table() -> list[dict]:
    return [{"method": r.method, "ms": r.ms, "has_metrics": r.has_metrics, "mae": r.mae,
             "ssim": r.ssim, "image": r.image, "error_image": r.error_image,
             "metrics": json.loads(r.metrics_json) if r.metrics_json else None}
            for r in bpy.context.window_manager.aolab.results]


if mode == "installed":
    out = {}
    mod = sys.modules.get(ADDON)
    out["enabled"] = addon_utils.check(ADDON)[1]
    out["file"] = getattr(mod, "__file__", None)
    out["user_scripts"] = bpy.utils.user_resource("SCRIPTS")
    out["registered_enabled"] = registered()
    out["panel"] = hasattr(bpy.types, "AOLAB_PT_sidebar")
    addon_utils.disable(ADDON, default_set=True)
    out["registered_disabled"] = registered()
    addon_utils.enable(ADDON, default_set=True)
    out["registered_reenabled"] = len(registered())
    addon_utils.disable(ADDON, default_set=True)
    out["registered_disabled_again"] = registered()
    print("RESULT " + json.dumps(out))
    sys.exit(0)

tiny, cache, out_dir = args[1:4]
scene = addon_on_scene(tiny, cache)
mod = sys.modules[ADDON]
images, library, operators, properties = (addon_module(n) for n in (
    "images", "library", "operators", "properties"))
prefs = bpy.context.preferences.addons[ADDON].preferences
s = scene.aolab
methods = library.methods()
getattr(s, "m_hbao").directions = 4  # a changed setting: passed to compute like --set
r = {"methods": methods, "file": mod.__file__}

# User errors first (each leaves nothing behind).
r["compare_without_reference"] = call(bpy.ops.aolab.compare)
for m in methods:
    getattr(s, "m_" + m).use_method = False
r["nothing_selected"] = call(bpy.ops.aolab.preview)
for m in ("hbao", "lsao"):
    getattr(s, "m_" + m).use_method = True
saved_aolab = library.aolab
library.aolab = None  # as if `import aolab` had failed
r["not_built"] = call(bpy.ops.aolab.preview)
library.aolab = saved_aolab
cam = scene.camera
cam.data.type = "ORTHO"
r["orthographic"] = call(bpy.ops.aolab.render_reference)
cam.data.type = "PERSP"
scene.camera = None
r["no_camera"] = call(bpy.ops.aolab.preview)
scene.camera = cam
# Hostile values a user can set in Blender: each is named before any work starts.
distance = scene.world.light_settings.distance
scene.world.light_settings.distance = 0.0   # the world's AO distance may be 0 in Blender
r["zero_distance"] = call(bpy.ops.aolab.preview)
scene.world.light_settings.distance = float("inf")   # Blender stores 3.4e38
r["huge_distance"] = call(bpy.ops.aolab.preview)
scene.world.light_settings.distance = distance
s.preview_scale = 1   # 1 % of the tiny scene: below Blender's 4x4 minimum
r["too_small"] = call(bpy.ops.aolab.preview)
s.preview_scale = 100
cache_file = os.path.join(out_dir, "cache_is_a_file")
with open(cache_file, "w") as f:
    f.write("not a folder")
prefs.cache_dir = os.path.join(cache_file, "sub")
r["cache_under_file"] = call(bpy.ops.aolab.preview)
prefs.cache_dir = cache
saved_copy = operators.save_copy


def no_space(context):   # a full temporary folder, as saving the copy of the file meets it
    raise OSError(28, "No space left on device")


operators.save_copy = no_space
r["save_copy_fails"] = call(bpy.ops.aolab.preview)
operators.save_copy = saved_copy
r["cache_after_errors"] = sorted(os.listdir(cache)) if os.path.isdir(cache) else None

before = scene_state(scene)
r["preview"] = call(bpy.ops.aolab.preview)
r["preview_table"] = results_table()
r["preview_images"] = {}
for row in results_table():
    px = images.read_image(row["image"])
    np.save(os.path.join(out_dir, f"preview_{row['method']}.npy"), px)
    r["preview_images"][row["method"]] = {
        "size": list(bpy.data.images[row["image"]].size),
        "colorspace": bpy.data.images[row["image"]].colorspace_settings.name,
        "grey": bool(np.array_equal(px[..., 0], px[..., 1]))}
r["preview_folder"] = bpy.context.window_manager.aolab.gbuffer_folder
after_preview = scene_state(scene)
r["preview_diff"] = [d for d in diff(before, after_preview) if not d.startswith(".ids.images")]

before = scene_state(scene)
r["reference"] = call(bpy.ops.aolab.render_reference)
r["reference_diff"] = diff(before, scene_state(scene))
r["reference_folder"] = bpy.context.window_manager.aolab.reference_folder
r["reference_again"] = call(bpy.ops.aolab.render_reference)  # from the cache

# Cancel a longer render once it is under way, as Esc does (job.cancel()).
s.reference_samples = 4096
before = scene_state(scene)
seen = {}


def canceller():
    deadline = time.time() + 60
    while time.time() < deadline:
        job = operators.ACTIVE.get("AOLAB_OT_render_reference")
        if job is not None and "/4096 samples" in job.stage:
            seen["stage"], seen["progress"] = job.stage, job.progress
            job.cancel()
            return
        time.sleep(0.02)


thread = threading.Thread(target=canceller)
thread.start()
r["cancel"] = call(bpy.ops.aolab.render_reference)
thread.join()
r["cancel_seen"] = seen
r["cancel_diff"] = diff(before, scene_state(scene))
r["cache_after_cancel"] = sorted(os.listdir(cache))
s.reference_samples = 8

r["compare"] = call(bpy.ops.aolab.compare)
r["compare_table"] = results_table()
r["compare_folder"] = bpy.context.window_manager.aolab.gbuffer_folder
np.save(os.path.join(out_dir, "error_hbao.npy"),
        images.read_image(images.image_name("hbao", "error")))
for row in results_table():
    np.save(os.path.join(out_dir, f"compare_{row['method']}.npy"), images.read_image(row["image"]))
r["compare_images"] = sorted(im.name for im in bpy.data.images if im.name.startswith("AO Lab"))
r["settings_passed"] = properties.chosen_runs(scene)
s.report_dir = os.path.join(cache_file, "report")
r["report_under_file"] = call(bpy.ops.aolab.write_report)
s.report_dir = os.path.join(out_dir, "report")
r["report"] = call(bpy.ops.aolab.write_report)
r["report_path"] = bpy.context.window_manager.aolab.report_path
r["presets"] = {m: [item[0] for item in
                    properties._preset_items(getattr(s, "m_" + m), bpy.context)]
                for m in methods}
g = getattr(s, "m_hbao")
if "low" in r["presets"]["hbao"]:
    g.preset = "low"
    r["hbao_low"] = {name: getattr(g, name) for name in g.setting_names} | {"blur": g.use_blur}
    for name in [n for n in r["presets"]["hbao"] if n.startswith("tuned-")][:1]:
        g.preset = name
        r["hbao_tuned"] = {name: getattr(g, name) for name in g.setting_names} | \
            {"blur": g.use_blur}
    g.preset = "default"
    r["hbao_default_again"] = library.method_settings.changed_settings(
        "hbao", {n: getattr(g, n) for n in g.setting_names})
r["show_image_background"] = call(bpy.ops.aolab.show_image, image="AO Lab hbao")

addon_utils.disable(ADDON, default_set=True)
r["registered_after_disable"] = registered()
print("RESULT " + json.dumps(r, default=str))
