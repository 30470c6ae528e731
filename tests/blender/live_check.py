"""Inside Blender: the add-on's Live preview (installed by scripts/install_addon.sh, as in
addon_check.py). Prints one JSON line `RESULT {...}`.

    live_check.py -- live SCENE.py CACHE OUT_DIR
        the tiny scene: Live with no G-buffer cached (a message, nothing computed), Preview
        once, then Live off (nothing happens), Live on, a changed setting, quick changes,
        a change while a compute runs, a preset; every image saved as OUT_DIR/<name>.npy with
        the settings it was computed with; then the add-on disabled with a timer pending.
    live_check.py -- accumulate SCENE.py CACHE OUT_DIR FRAMES
        the tiny scene, Accumulate = FRAMES: Live left alone converges (every image saved
        after the last frame, and after frame 0 and a few frames of a changed setting),
        stops (no compute after), a change mid-way starts again at frame 0, a moved object
        stops it, the Accumulate setting restarts it.
    live_check.py -- converge SCENE.py CACHE OUT_DIR SCALE FRAMES METHOD,METHOD...
        the methods at `medium` converging over FRAMES frames: the mean absolute error on
        geometry pixels of the image after each power of 2 frames to the image after
        FRAMES frames, and each frame's compute and accumulate times (docs/blender_addon.md).
    live_check.py -- latency SCENE.py CACHE OUT_DIR SCALE REPEAT
        every method (but the brute-force screen_space_limit) at `medium`, each switched
        low -> medium REPEAT times; the times of each live update (compute, image, change
        to image).

Blender runs no timers in -b mode (it has no event loop), so `pump` does what the event loop
does with bpy.app.timers: calls the registered live.tick when it is due, as often as it asks,
until it returns None.
"""
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import ADDON, addon_module, panel_text, run_build_script  # noqa: E402

import addon_utils  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
mode, scene_script, cache, out_dir = args[:4]

run_build_script(scene_script)
addon_utils.enable(ADDON, default_set=True)
images, library, live, properties = (addon_module(n) for n in (
    "images", "library", "live", "properties"))

prefs = bpy.context.preferences.addons[ADDON].preferences
prefs.cache_dir = cache
prefs.threads = 2
scene = bpy.context.scene
s = scene.aolab
session = bpy.context.window_manager.aolab
methods = library.methods()


def pump(timeout: float = 120.0) -> None:
    common.pump(live, timeout)


def group(method):
    return properties.method_group(scene, method)


def stats() -> dict:
    return dict(live._state.stats)


def save(name: str, method: str) -> dict:
    """The image of `method` as OUT_DIR/name.npy, with the run (settings, blur) it shows."""
    np.save(os.path.join(out_dir, name + ".npy"), images.read_image(images.image_name(method)))
    run = next(r for r in properties.chosen_runs(scene) if r["method"] == method)
    return {"settings": run["settings"], "blur": run["blur"],
            "radius": properties.effective_radius(scene)}


def pump_until(method: str, frame: int, timeout: float = 60.0) -> dict:
    """Runs the timer until `method`'s image of `frame` (of its latest change) is shown;
    returns that update."""
    deadline = time.perf_counter() + timeout
    while True:
        last = live._state.last[-1] if live._state.last else {}
        if last.get("method") == method and last.get("frame") == frame and \
                last.get("generation") == live._state.generation.get(method):
            return last
        if time.perf_counter() > deadline or not bpy.app.timers.is_registered(live.tick):
            raise RuntimeError(f"{method} frame {frame} never shown: {last}")
        interval = live.tick()
        if interval is None:
            bpy.app.timers.unregister(live.tick)
        else:
            time.sleep(interval)


def updates(before: dict) -> list[tuple[str, int]]:
    """(method, frame) of every update shown since the stats `before`."""
    n = stats()["applied"] - before["applied"]
    return [(u["method"], u["frame"]) for u in live._state.last[-n:]] if n else []


def tick_until_computing(timeout: float = 10.0) -> None:
    deadline = time.perf_counter() + timeout
    while not live.computing():
        if time.perf_counter() > deadline:
            raise RuntimeError("no compute started")
        time.sleep(live.tick() or 0.0)


r = {"methods": methods}
if mode == "live":
    s.preview_scale = 100
    s.live_frames = 1   # one frame per change: Live as it was before accumulation
    for m in methods:
        group(m).use_method = m in ("hbao", "lsao")

    # No G-buffer cached yet: a clear message, nothing computed.
    session.live = True
    r["no_gbuffer_timer"] = bpy.app.timers.is_registered(live.tick)
    pump()
    r["no_gbuffer"] = {"message": session.live_message, "error": session.live_message_is_error,
                       "stats": stats(), "panel": panel_text(),
                       "images": sorted(i.name for i in bpy.data.images)}
    session.live = False

    # Preview exports the G-buffer once (a 1-sample render in the background).
    r["preview"] = sorted(bpy.ops.aolab.preview())
    r["gbuffer_folder"] = session.gbuffer_folder
    for m in ("hbao", "lsao"):
        bpy.data.images.remove(bpy.data.images[images.image_name(m)])

    # Live off: a change does nothing.
    before = stats()
    group("hbao").directions = 5
    r["off"] = {"timer": bpy.app.timers.is_registered(live.tick), "pending": live.pending(),
                "stats_before": before, "stats": stats(),
                "image": images.image_name("hbao") in bpy.data.images}

    # Live on: every ticked method computed.
    session.live = True
    pump()
    r["on"] = {"stats": stats(), "message": session.live_message,
               "error": session.live_message_is_error,
               "hbao": save("on_hbao", "hbao"), "lsao": save("on_lsao", "lsao"),
               "table": [(row.method, row.ms, row.image) for row in session.results],
               "kind": session.results_kind}

    # One changed setting: that method's image, no button press.
    before = stats()
    group("hbao").directions = 3
    r["changed_timer"] = bpy.app.timers.is_registered(live.tick)
    pump()
    r["changed"] = {"stats_before": before, "stats": stats(), "hbao": save("changed_hbao", "hbao"),
                    "panel": panel_text(),
                    "last": live._state.last[-1], "compute_ms": session.live_compute_ms,
                    "total_ms": session.live_total_ms, "message": session.live_message}

    # Quick changes: one compute of the latest values.
    before = stats()
    g = group("hbao")
    for d in (2, 6, 7, 4, 9):
        g.directions = d
    g.steps = 3
    g.use_blur = True
    pump()
    r["quick"] = {"stats_before": before, "stats": stats(), "hbao": save("quick_hbao", "hbao")}

    # A change while a compute runs: its result is stale, dropped; the latest one shown.
    before = stats()
    g.directions = 5
    tick_until_computing()
    g.directions = 8
    pump()
    r["stale"] = {"stats_before": before, "stats": stats(), "hbao": save("stale_hbao", "hbao")}

    # A slow method changed while it computes: cancelled, not finished; the latest shown.
    slow = group("screen_space_limit")
    slow.use_method = True
    pump()
    r["slow_full_ms"] = live._state.last[-1]["compute_ms"]
    before = stats()
    slow.use_blur = True
    tick_until_computing()
    time.sleep(0.02)
    t0 = time.perf_counter()
    slow.use_blur = False
    pump()
    r["slow"] = {"stats_before": before, "stats": stats(),
                 "ms": 1000 * (time.perf_counter() - t0), "last": live._state.last[-1]}
    slow.use_method = False
    pump()

    # A preset (it sets every setting of the method): one compute.
    before = stats()
    g.preset = "low"
    pump()
    r["preset"] = {"stats_before": before, "stats": stats(), "hbao": save("preset_hbao", "hbao")}

    # The world's AO distance (R with Scene AO Distance on): no update= callback there; the
    # depsgraph reports the world's change when it is next evaluated (the UI's redraw).
    before = stats()
    scene.world.light_settings.distance *= 0.75
    bpy.context.evaluated_depsgraph_get()
    pump()
    r["world"] = {"stats_before": before, "stats": stats(), "hbao": save("world_hbao", "hbao"),
                  "distance": scene.world.light_settings.distance}

    # R (every ticked method).
    before = stats()
    s.use_scene_radius = False
    s.radius = 0.6
    pump()
    r["radius"] = {"stats_before": before, "stats": stats(), "radius": s.radius,
                   "hbao": save("radius_hbao", "hbao"), "lsao": save("radius_lsao", "lsao")}

    # Unticked: its row leaves the table, nothing computed.
    before = stats()
    group("lsao").use_method = False
    pump()
    r["untick"] = {"stats_before": before, "stats": stats(),
                   "table": [row.method for row in session.results]}

    # The geometry changed: the cached G-buffer is not this scene's any more.
    obj = next(o for o in scene.objects if o.type == "MESH")
    obj.location.x += 0.5
    g.directions = 6
    pump()
    r["moved"] = {"message": session.live_message, "error": session.live_message_is_error}
    obj.location.x -= 0.5
    g.directions = 5
    pump()
    r["moved_back"] = {"message": session.live_message, "error": session.live_message_is_error}

    # Disabled with a change pending and a compute running: nothing left behind.
    g.directions = 7
    tick_until_computing()
    g.directions = 9
    r["pending_before_disable"] = bpy.app.timers.is_registered(live.tick)
    addon_utils.disable(ADDON, default_set=True)
    r["after_disable"] = {
        "timer": bpy.app.timers.is_registered(live.tick),
        "handlers": [f.__name__ for f in bpy.app.handlers.depsgraph_update_post +
                     bpy.app.handlers.load_pre if f.__module__.startswith(ADDON)],
        "threads": [t.name for t in threading.enumerate() if t.name == "aolab-live"],
        "wm_aolab": hasattr(bpy.types.WindowManager, "aolab")}

elif mode == "accumulate":
    frames = int(args[4])
    s.preview_scale = 100
    ticked = ("hbao", "lsao", "chebyshev")   # chebyshev has no seed: one frame
    for m in methods:
        group(m).use_method = m in ticked
    r["default_frames"] = s.live_frames
    r["preview"] = sorted(bpy.ops.aolab.preview())
    r["gbuffer_folder"] = session.gbuffer_folder
    s.live_frames = frames
    group("hbao").directions = 3   # few directions: noisy frames

    # Left alone: every seeded method converges over `frames` frames, then Live stops.
    before = stats()
    session.live = True
    pump()
    r["converged"] = {"stats_before": before, "stats": stats(), "updates": updates(before),
                      "timer": bpy.app.timers.is_registered(live.tick),
                      "frame": session.live_frame, "goal": session.live_frame_goal,
                      "message": session.live_message, "error": session.live_message_is_error,
                      "panel": panel_text(), "accum": sorted(live._state.accum)}
    for m in ticked:
        r["converged"][m] = save(f"converged_{m}", m)
    # Nothing changed: a stray timer call computes nothing, and nothing runs.
    before = stats()
    r["idle_tick"] = live.tick()
    time.sleep(0.2)
    r["idle"] = {"stats_before": before, "stats": stats(), "pending": live.pending()}

    # A setting changed mid-way: frame 0 of the new value, then its own frames.
    g = group("hbao")
    g.directions = 4
    pump_until("hbao", 2)
    r["partial"] = {"hbao": save("partial_hbao", "hbao"), "panel": panel_text()}
    before = stats()
    g.directions = 5
    r["reset_first"] = pump_until("hbao", 0)
    r["reset"] = {"hbao": save("reset_hbao", "hbao")}
    pump()
    r["reset"].update(stats_before=before, stats=stats(), updates=updates(before),
                      converged=save("reset_converged_hbao", "hbao"))

    # R changed: every ticked method from frame 0; lsao unticked mid-way: its frames stop,
    # hbao's go on.
    s.use_scene_radius = False
    s.radius = 0.6
    pump_until("lsao", 1)
    before = stats()
    group("lsao").use_method = False
    pump()
    r["untick"] = {"stats_before": before, "stats": stats(), "updates": updates(before),
                   "table": [row.method for row in session.results]}
    group("lsao").use_method = True
    pump()

    # The scene moved while converging: the G-buffer is not the scene's any more; stopped.
    g.directions = 6
    pump_until("hbao", 1)
    before = stats()
    obj = next(o for o in scene.objects if o.type == "MESH")
    obj.location.x += 0.5
    bpy.context.evaluated_depsgraph_get()   # what the UI's redraw does: the handler runs
    pump()
    r["moved"] = {"stats_before": before, "stats": stats(), "updates": updates(before),
                  "message": session.live_message, "error": session.live_message_is_error,
                  "accum": sorted(live._state.accum)}
    obj.location.x -= 0.5

    # Accumulate itself changed: every ticked method again from frame 0.
    before = stats()
    s.live_frames = 2
    pump()
    r["frames_changed"] = {"stats_before": before, "stats": stats(),
                           "updates": updates(before), "hbao": save("two_hbao", "hbao")}

    # An error (VAO++'s colour bleeding needs a colour pass, which Preview's G-buffer lacks):
    # said in the panel, no frame follows.
    before = stats()
    vao = group("vao_pp")
    vao.use_method, vao.color_bleeding = True, True
    pump()
    r["rgb_error"] = {"stats_before": before, "stats": stats(), "updates": updates(before),
                      "message": session.live_message, "error": session.live_message_is_error,
                      "accum": sorted(live._state.accum),
                      "timer": bpy.app.timers.is_registered(live.tick),
                      "image": images.image_name("vao_pp") in bpy.data.images}
    vao.use_method = False
    # An RGB result (a G-buffer with a colour pass): the worker's blend takes each channel
    # as its own image. Frames made of hbao's frames k, k+1, k+2 as R, G, B.
    aolab = library.aolab
    gb = aolab.load_gbuffer(os.path.join(r["gbuffer_folder"], "reference.exr"))
    run = {"frames": 3, "histories": []}
    hbao = [aolab.compute("hbao", gb, radius=0.75, threads=2, frame=k) for k in range(5)]
    for k in range(3):
        rgb = library.live_jobs.accumulate(np.stack(hbao[k:k + 3], axis=-1), gb, run, 2)
    np.save(os.path.join(out_dir, "rgb.npy"), rgb)

elif mode == "converge":
    scale, frames, chosen = int(args[4]), int(args[5]), args[6].split(",")
    s.preview_scale = scale
    for m in methods:
        group(m).use_method = m in chosen
        if m in chosen and "medium" in library.presets.names(m):
            group(m).preset = "medium"
    r["preview"] = sorted(bpy.ops.aolab.preview())
    r["size"] = session.results_size
    g = library.aolab.load_gbuffer(os.path.join(session.gbuffer_folder, "reference.exr"))
    geometry = g.valid_mask()
    s.live_frames = frames
    shown = {m: {} for m in chosen}   # method -> {frames averaged: image}
    times = {m: [] for m in chosen}
    session.live = True
    t0 = time.perf_counter()
    while bpy.app.timers.is_registered(live.tick):
        applied = stats()["applied"]
        interval = live.tick()
        if stats()["applied"] > applied:
            u = live._state.last[-1]
            n = u["frame"] + 1
            times[u["method"]].append((u["compute_ms"], u["accumulate_ms"]))
            if n & (n - 1) == 0 or n == frames:
                shown[u["method"]][n] = images.read_image(images.image_name(u["method"]))[..., 0]
        if interval is None:
            bpy.app.timers.unregister(live.tick)
        else:
            time.sleep(interval)
    r["seconds"] = time.perf_counter() - t0
    r["load"] = os.getloadavg()
    r["error"] = {m: {n: float(np.mean(np.abs(img - shown[m][frames])[geometry]))
                      for n, img in sorted(shown[m].items())} for m in chosen}
    r["ms"] = {m: {"compute": float(np.median([c for c, _ in times[m]])),
                   "accumulate": float(np.median([a for _, a in times[m][1:]])),
                   "frames": len(times[m])} for m in chosen}

elif mode == "latency":
    scale, repeat = int(args[4]), int(args[5])
    # screen_space_limit is the brute-force bound of the study (minutes per image), no
    # interactive method: left out.
    methods = [m for m in methods if m != "screen_space_limit"]
    s.preview_scale = scale
    s.live_frames = 1   # the latency of a change: frame 0 only
    for m in methods:
        group(m).use_method = m == methods[0]   # Preview exports the G-buffer
        if "medium" in library.presets.names(m):
            group(m).preset = "medium"
    r["preview"] = sorted(bpy.ops.aolab.preview())
    r["size"] = session.results_size
    session.live = True
    r["times"] = {}
    for m in methods:
        group(m).use_method = True
        pump()
        g = group(m)
        rows = []
        names = library.presets.names(m)
        for _ in range(repeat):
            if "medium" in names and "low" in names:
                g.preset = "low"
                pump()
                g.preset = "medium"
            else:   # a method without presets: its blur switched on and off
                g.use_blur = True
                pump()
                g.use_blur = False
            pump()
            rows.append(live._state.last[-1])
            print("LIVE", json.dumps(rows[-1]), flush=True)
        r["times"][m] = rows

print("RESULT " + json.dumps(r, default=str))
