"""Run by scripts/live_latency.sh in Blender's full UI under Xvfb, where bpy.app.timers run
in Blender's own event loop (in -b mode they never do):

    blender --factory-startup --python scripts/live_latency.py --
        BUILD.py CACHE OUT.json SCALE REPEAT

Builds the scene, enables the AO Lab add-on, exports the G-buffer with Preview (one method
ticked), ticks every method (but the brute-force screen_space_limit) at its medium preset
and switches Live on. Then a driver timer plays the user: for each method, REPEAT times,
preset low, wait for Live to settle, preset medium, wait, record the update Live measured
(compute, image, change to image). Last, Accumulate set to CONVERGE_FRAMES, the first
method converging once after a switch to medium: its frames, the seconds from the change to
the last frame and the per-frame medians (docs/blender_addon.md, "Converging at rest").
Writes OUT.json and quits; exit code 1 on a failure.
"""
import json
import runpy
import sys
import time
import traceback

import addon_utils
import bpy

BUILD, CACHE, OUT, SCALE, REPEAT = sys.argv[sys.argv.index("--") + 1:][:5]
TIMEOUT_S = 120.0   # per live update
CONVERGE_FRAMES = 16   # Accumulate of the last step (the add-on's default)
result = {"times": {}, "error": None}


def setup():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    runpy.run_path(BUILD, run_name="__main__")
    addon_utils.enable("aolab_blender", default_set=True)
    from aolab_blender import library, properties
    prefs = bpy.context.preferences
    prefs.addons["aolab_blender"].preferences.cache_dir = CACHE
    prefs.addons["aolab_blender"].preferences.threads = 2
    prefs.view.show_splash = False
    scene = bpy.context.scene
    scene.aolab.preview_scale = int(SCALE)
    scene.aolab.live_frames = 1   # the latency of a change: frame 0 only
    methods = [m for m in library.methods() if m != "screen_space_limit"]
    for m in library.methods():
        g = properties.method_group(scene, m)
        g.use_method = m == methods[0]
        if "medium" in library.presets.names(m):
            g.preset = "medium"
    assert bpy.ops.aolab.preview() == {"FINISHED"}
    result["size"] = bpy.context.window_manager.aolab.results_size
    # The user watches the image: the 3D viewport becomes an Image Editor showing it.
    for area in bpy.context.window_manager.windows[0].screen.areas:
        if area.type == "VIEW_3D":
            area.type = "IMAGE_EDITOR"
            area.spaces.active.image = bpy.data.images["AO Lab " + methods[0]]
    return methods


def driver():
    """A generator: each yield hands the event loop back for `wait` seconds."""
    methods = setup()
    from aolab_blender import library, live, properties
    scene = bpy.context.scene
    session = bpy.context.window_manager.aolab
    session.live = True

    loop = result["loop_ms"] = []   # how long the event loop took to call us back

    def settle():
        deadline = time.perf_counter() + TIMEOUT_S
        while bpy.app.timers.is_registered(live.tick) or live.pending():
            if time.perf_counter() > deadline:
                raise RuntimeError("Live did not settle")
            t = time.perf_counter()
            yield 0.01
            loop.append(1000 * (time.perf_counter() - t))

    for m in methods:
        g = properties.method_group(scene, m)
        g.use_method = True
        yield from settle()
        rows = []
        for _ in range(int(REPEAT)):
            has_presets = "low" in library.presets.names(m)
            if has_presets:
                g.preset = "low"
            else:
                g.use_blur = True
            yield from settle()
            before = live._state.stats["applied"]
            if has_presets:
                g.preset = "medium"
            else:
                g.use_blur = False
            # Blender's own work after a property change (the window's redraw), before it
            # runs any timer: how long until a 0 s timer is called.
            t = time.perf_counter()
            yield 0.0
            first_callback_ms = 1000 * (time.perf_counter() - t)
            yield from settle()
            assert live._state.stats["applied"] == before + 1, live._state.stats
            rows.append({**live._state.last[-1], "first_callback_ms": first_callback_ms})
            print("LIVE", json.dumps(rows[-1]), flush=True)
            area = next(a for a in bpy.context.window_manager.windows[0].screen.areas
                        if a.type == "IMAGE_EDITOR")
            area.spaces.active.image = bpy.data.images["AO Lab " + m]
        result["times"][m] = rows
    yield from converge(methods[0], settle)
    result["stats"] = dict(live._state.stats)


def converge(method, settle):
    """Accumulate on, `method` switched low -> medium and left to converge."""
    from aolab_blender import live, properties
    scene = bpy.context.scene
    g = properties.method_group(scene, method)
    scene.aolab.live_frames = CONVERGE_FRAMES   # every ticked method converges once
    yield from settle()
    g.preset = "low"
    yield from settle()
    before = live._state.stats["applied"]
    t = time.perf_counter()
    g.preset = "medium"
    yield from settle()
    rows = live._state.last[-(live._state.stats["applied"] - before):]
    result["converge"] = {"method": method, "seconds": time.perf_counter() - t,
                          "frames": [r["frame"] for r in rows], "rows": rows}


steps = None


def step():
    global steps
    try:
        if steps is None:
            steps = driver()
        return next(steps)
    except StopIteration:
        pass
    except Exception:
        result["error"] = traceback.format_exc()
    with open(OUT, "w") as f:
        json.dump(result, f, indent=1)
    bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(step, first_interval=0.5)
