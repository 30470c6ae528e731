"""Run by scripts/addon_screenshot.sh in Blender's full UI under Xvfb:

    blender --factory-startup --python scripts/addon_screenshot.py -- BUILD.py CACHE READY [MODE]

Builds a reference scene, enables the AO Lab add-on, opens the 3D viewport's sidebar on the
AO Lab tab, with an Image Editor beside it, then clicks through its real modal operators
(INVOKE_DEFAULT, driven by the event loop) and writes the file READY. MODE "compare" (the
default): Preview, Render Reference (64 samples, cached) and Compare, the lowest-MAE method's
error map in the Image Editor. MODE "advise": Quick Compare (three methods ticked) and Advise
at the 33 ms budget, its front in the Image Editor. The shell script then captures the X
screen (xwd) and writes READY + ".done", and this script quits. Exits with code 1 (and no
READY) if a step fails.

The X screen rather than bpy.ops.screen.screenshot: that operator reads back Blender's own
frame buffer, which Blender 4.3 on Mesa's llvmpipe returns black (measured), while the X
server holds what a user would see on both releases.
"""
import os
import runpy
import sys
import time
import traceback

import addon_utils
import bpy

ARGS = sys.argv[sys.argv.index("--") + 1:]
BUILD, CACHE, READY = ARGS[:3]
MODE = ARGS[3] if len(ARGS) > 3 else "compare"
#: Advise's screenshot: the methods ticked for Quick Compare (a short table leaves room for
#: the advice below it) and the budget shown.
ADVISE_TICKED = ("gtao", "hbao", "sao")
ADVISE_BUDGET = "33"
ADVISE_SCROLL = 1    # pages down the sidebar, to the advice
CAPTURE_TIMEOUT = 120  # s to wait for the shell script's capture
SCALE = 25           # % of the scene's 1280x720: 320x180
SAMPLES = 64         # a quick reference; the panel's default is 1024
PRESET = "medium"    # each method's preset, where it has one
UI_SCALE = 1.0       # Blender's default text size
SIDEBAR_EXTRA = 200  # px added to the sidebar's width
EDGE = 1             # px inside the sidebar's left edge: where dragging resizes it
SPLIT = 0.62         # share of the 3D viewport's width kept by it (the rest: Image Editor)
state = {"step": 0, "t": 0}
#: The installed add-on's module: an extension on Blender 4.2+ (scripts/install_addon.sh).
ADDON = ("bl_ext.user_default.aolab_blender" if bpy.app.version >= (4, 2, 0)
         else "aolab_blender")


def build_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    runpy.run_path(BUILD, run_name="__main__")
    addon_utils.enable(ADDON, default_set=True)
    from aolab.named_presets import preset_names
    prefs = bpy.context.preferences
    prefs.addons[ADDON].preferences.cache_dir = CACHE
    prefs.view.show_splash = False
    scene = bpy.context.scene
    scene.aolab.preview_scale = SCALE
    scene.aolab.reference_samples = SAMPLES
    scene.aolab.advise_budget = ADVISE_BUDGET
    for method in scene.aolab.methods:
        group = getattr(scene.aolab, "m_" + method)
        group.use_method = MODE != "advise" or method in ADVISE_TICKED
        if PRESET in preset_names(method):
            group.preset = PRESET


def areas():
    """(window, the 3D viewport, the Image Editor), after split_screen()."""
    window = bpy.context.window_manager.windows[0]
    view = next(a for a in window.screen.areas if a.type == "VIEW_3D")
    editor = next((a for a in window.screen.areas if a.type == "IMAGE_EDITOR"), None)
    return window, view, editor


def region(area, kind="WINDOW"):
    return next(r for r in area.regions if r.type == kind)


def invoke(op):
    window, view, _ = areas()
    with bpy.context.temp_override(window=window, area=view, region=region(view)):
        return op("INVOKE_DEFAULT")


def split_screen():
    """The 3D viewport split: itself on the left with its sidebar open, an Image Editor on
    the right. An active object, so that the sidebar has its usual four tabs."""
    bpy.context.view_layer.objects.active = bpy.context.scene.camera
    window, view, _ = areas()
    with bpy.context.temp_override(window=window, area=view, region=region(view)):
        bpy.ops.screen.area_split(direction="VERTICAL", factor=SPLIT)
    views = sorted((a for a in window.screen.areas if a.type == "VIEW_3D"), key=lambda a: a.x)
    views[-1].type = "IMAGE_EDITOR"
    space = views[0].spaces.active
    space.show_region_ui = True
    space.region_3d.view_perspective = "CAMERA"
    space.overlay.show_overlays = False


def click_tab_and_widen():
    """Blender 3.4 has no Python API to choose the sidebar's tab or its width: this clicks
    the AO Lab tab (the fourth, 165 px below the region's top at UI scale 1) and drags the
    sidebar's edge, with simulated events (--enable-event-simulate)."""
    window, view, _ = areas()
    ui = region(view, "UI")
    x, y = ui.x + ui.width - 8, ui.y + ui.height - 165
    for kind, value in (("MOUSEMOVE", "NOTHING"), ("LEFTMOUSE", "PRESS"), ("LEFTMOUSE", "RELEASE")):
        window.event_simulate(type=kind, value=value, x=x, y=y)
    x, y = ui.x + EDGE, ui.y + ui.height // 2
    window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x, y=y)
    window.event_simulate(type="LEFTMOUSE", value="PRESS", x=x, y=y)
    for dx in range(20, SIDEBAR_EXTRA + 1, 20):
        window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x - dx, y=y)
    window.event_simulate(type="LEFTMOUSE", value="RELEASE", x=x - SIDEBAR_EXTRA, y=y)


def scroll_sidebar(pages: int) -> None:
    """Scrolls the sidebar down by `pages` pages (View2D's scroll operator in the region), so
    that what lies below its height shows: the advice is below the methods and results."""
    window, view, _ = areas()
    with bpy.context.temp_override(window=window, area=view, region=region(view, "UI")):
        for _ in range(pages):
            bpy.ops.view2d.scroll_down(page=True)


def show_results():
    """The lowest-MAE method's error map (or, after Advise, the front) in the Image Editor,
    the camera view framed, and the larger UI scale."""
    window, view, editor = areas()
    if MODE == "advise":
        editor.spaces.active.image = bpy.data.images["AO Lab advise"]
    else:
        rows = [r for r in bpy.context.window_manager.aolab.results if r.has_metrics]
        best = min(rows, key=lambda r: r.mae)
        editor.spaces.active.image = bpy.data.images[best.error_image]
    bpy.context.preferences.view.ui_scale = UI_SCALE
    with bpy.context.temp_override(window=window, area=editor, region=region(editor)):
        bpy.ops.image.view_all(fit_view=True)
    with bpy.context.temp_override(window=window, area=view, region=region(view)):
        bpy.ops.view3d.view_center_camera()
    if MODE == "advise":
        scroll_sidebar(ADVISE_SCROLL)


def tick():
    """One step per call; returns the delay before the next (None: done)."""
    try:
        session = bpy.context.window_manager.aolab
        if session.busy:
            return 0.5
        if session.message_is_error:
            raise RuntimeError(session.message)
        step = state["step"]
        state["step"] += 1
        if step == 0:
            split_screen()
            return 1.0
        elif step == 1:
            click_tab_and_widen()
            return 1.0
        elif step == 2:
            invoke(bpy.ops.aolab.quick_compare if MODE == "advise" else bpy.ops.aolab.preview)
        elif step == 3:
            invoke(bpy.ops.aolab.advise if MODE == "advise" else
                   bpy.ops.aolab.render_reference)
        elif step == 4:
            if MODE != "advise":
                invoke(bpy.ops.aolab.compare)
        elif step == 5:
            show_results()
            return 2.0
        elif step == 6:
            with open(READY, "w") as f:
                f.write(session.message)
            state["t"] = time.monotonic()
            return 0.5
        elif step >= 7:
            if not os.path.exists(READY + ".done"):
                if time.monotonic() - state["t"] > CAPTURE_TIMEOUT:
                    raise RuntimeError("the screen was not captured")
                state["step"] = 7
                return 0.5
            print(f"addon_screenshot: captured; {session.message}", flush=True)
            bpy.ops.wm.quit_blender()
            return None
        return 0.5
    except Exception:
        traceback.print_exc()
        print("addon_screenshot: FAILED", flush=True)
        sys.exit(1)


build_scene()
bpy.app.timers.register(tick, first_interval=3.0)
