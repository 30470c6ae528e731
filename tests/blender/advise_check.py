"""Inside Blender: the add-on's Quick Compare and Advise, installed by scripts/install_addon.sh
(as addon_check.py). Prints one JSON line `RESULT {...}`.

    advise_check.py -- flow TINY_SCENE.py CACHE OUT_DIR
        the tiny scene: Quick Compare refused without a camera, then run (its G-buffer and
        triangles exported at 1 sample, the quick reference traced) and run again (cached);
        Advise against the quick reference, its front drawn, the panel's advice, Apply (and an
        Apply of a preset the menu lacks); Render Reference (8 spp), then Advise against it
        and Compare, each stating what it scored against.
    advise_check.py -- timing BUILD.py CACHE SCALE
        a reference scene at SCALE % (the panel's default: 25) with every method ticked at its
        medium preset: Quick Compare and Advise from an empty cache, then each again with the
        G-buffer cached; the seconds of each and the load average (docs/blender_addon.md,
        "Quick Compare and Advise: measured").
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (ADDON, addon_module, addon_on_scene, call, diff,  # noqa: E402
                    panel_text, scene_state)

import addon_utils  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
mode = args[0]
images, library, properties = (addon_module(n) for n in ("images", "library", "properties"))


def table() -> list[dict]:
    return [{"method": r.method, "ms": r.ms, "has_metrics": r.has_metrics,
             "metrics": json.loads(r.metrics_json) if r.metrics_json else None,
             "image": r.image} for r in bpy.context.window_manager.aolab.results]


def session_state() -> dict:
    s = bpy.context.window_manager.aolab
    return {"kind": s.results_kind, "reference": s.results_reference,
            "noise": s.results_noise, "gbuffer_folder": s.gbuffer_folder,
            "size": s.results_size}


def advice() -> dict | None:
    text = bpy.context.window_manager.aolab.advice_json
    return json.loads(text) if text else None


if mode == "timing":
    build, cache, scale = args[1], args[2], int(args[3])
    scene = addon_on_scene(build, cache, ticked=())
    scene.aolab.preview_scale = scale
    from aolab.named_presets import preset_names
    for m in scene.aolab.methods:
        g = getattr(scene.aolab, "m_" + m)
        if not library.aolab.method_info(m)["bound"]:
            g.use_method = True
            if "medium" in preset_names(m):
                g.preset = "medium"
    out = {"methods": properties.chosen_runs(scene), "cpus": os.cpu_count(),
           "threads": bpy.context.preferences.addons[ADDON].preferences.threads}
    for step, op in (("quick_compare_empty_cache", bpy.ops.aolab.quick_compare),
                     ("quick_compare_cached", bpy.ops.aolab.quick_compare),
                     ("advise_cached", bpy.ops.aolab.advise)):
        load = os.getloadavg()
        out[step] = {**call(op), "load_before": load, "load_after": os.getloadavg()}
    out["size"] = session_state()["size"]
    out["advice"] = {k: advice()[k] for k in ("seconds", "reference", "width", "height")}
    out["advice"]["trials"] = len(advice()["trials"])
    # Advise from nothing: a new cache, so that its G-buffer and triangles are exported too.
    prefs = bpy.context.preferences.addons[ADDON].preferences
    prefs.cache_dir = cache + "_advise"
    load = os.getloadavg()
    out["advise_empty_cache"] = {**call(bpy.ops.aolab.advise), "load_before": load,
                                 "load_after": os.getloadavg()}
    print("RESULT " + json.dumps(out, default=str))
    sys.exit(0)

tiny, cache, out_dir = args[1:4]
scene = addon_on_scene(tiny, cache)
s = scene.aolab
r = {}
session = bpy.context.window_manager.aolab

cam = scene.camera
scene.camera = None
r["quick_no_camera"] = call(bpy.ops.aolab.quick_compare)
r["advise_no_camera"] = call(bpy.ops.aolab.advise)
scene.camera = cam
r["cache_after_errors"] = sorted(os.listdir(cache)) if os.path.isdir(cache) else []

before = scene_state(scene)
r["quick"] = call(bpy.ops.aolab.quick_compare)
r["quick_diff"] = [d for d in diff(before, scene_state(scene)) if not d.startswith(".ids.images")]
r["quick_table"] = table()
r["quick_session"] = session_state()
r["quick_radius"] = properties.effective_radius(scene)
r["quick_settings"] = properties.chosen_runs(scene)
for row in table():
    np.save(os.path.join(out_dir, f"quick_{row['method']}.npy"), images.read_image(row["image"]))
np.save(os.path.join(out_dir, "quick_reference.npy"),
        images.read_image(images.image_name("reference")))
r["quick_again"] = call(bpy.ops.aolab.quick_compare)
r["quick_again_table"] = table()
r["cache_after_quick"] = sorted(os.listdir(cache))

r["advise"] = call(bpy.ops.aolab.advise)
got = advice()
r["advice"] = {k: got[k] for k in ("scene", "width", "height", "reference", "methods",
                                   "pixels", "refused")}
r["advice"]["trials"] = len(got["trials"])
advise = library.advise
picks = {b: advise.choose(got, b) for b in library.BUDGETS_MS + (1e6,)}
r["picks"] = {str(b): (p["best"]["label"] if p["best"] else None) for b, p in picks.items()}
front = bpy.data.images.get(images.image_name(images.ADVICE))
r["front_image"] = list(front.size) if front is not None else None
found = images.preview(images.image_name(images.ADVICE))
r["front_preview"] = list(found.image_size) if found is not None else None
r["front_preview_pixels"] = float(np.mean(found.image_pixels_float[:])) if found else None
r["panel"] = panel_text()
best = next((p["best"] for p in picks.values() if p["best"] is not None), None)
if best is not None:
    getattr(s, "m_" + best["method"]).use_method = False
    r["apply"] = call(bpy.ops.aolab.apply_advice, method=best["method"], preset=best["preset"])
    g = getattr(s, "m_" + best["method"])
    r["applied"] = {"method": best["method"], "preset": best["preset"], "use_method": g.use_method,
                    "menu": g.preset, "use_blur": g.use_blur,
                    "settings": {n: getattr(g, n) for n in g.setting_names}}
r["apply_unknown"] = call(bpy.ops.aolab.apply_advice, method="hbao", preset="tuned-1ms")

s.reference_samples = 8
r["reference"] = call(bpy.ops.aolab.render_reference)
r["advise_cycles"] = call(bpy.ops.aolab.advise)
r["advice_cycles_reference"] = advice()["reference"]
r["compare"] = call(bpy.ops.aolab.compare)
r["compare_session"] = session_state()

addon_utils.disable(ADDON, default_set=True)
r["preview_after_disable"] = images.preview(images.image_name(images.ADVICE)) is not None
print("RESULT " + json.dumps(r, default=str))
