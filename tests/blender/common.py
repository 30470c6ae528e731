"""Shared by the Blender-side check scripts: puts the bridge on sys.path (use_checkout),
builds scenes, snapshots every RNA property the bridge might touch, and drives the add-on as
a user would (call an operator, pump Live's timer, draw the panel)."""
import importlib
import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


#: The module name of the add-on that scripts/install_addon.sh installed: an extension in the
#: user repository on Blender 4.2+, a legacy add-on before.
ADDON = ("bl_ext.user_default.aolab_blender" if bpy.app.version >= (4, 2, 0)
         else "aolab_blender")


def addon_module(name: str):
    """A module of the installed add-on (images, live, ...), under whichever name it has."""
    return importlib.import_module(f"{ADDON}.{name}")


def use_checkout():
    """The checkout's bridge (blender_addon/aolab_blender) first on sys.path, and before it
    the aolab package the test imports ($AOLAB_PACKAGE_PATH, as aolab.cycles.blender sets it for
    batch.py). Not for the add-on's own check, which tests the installed add-on."""
    sys.path.insert(0, os.path.join(ROOT, "blender_addon"))
    if os.environ.get("AOLAB_PACKAGE_PATH"):
        sys.path.insert(0, os.environ["AOLAB_PACKAGE_PATH"])


def addon_on_scene(scene_script: str, cache: str, ticked=("hbao", "lsao")):
    """Builds the scene of `scene_script` and enables the installed add-on on it: its cache
    in `cache`, 2 threads, the AO Lab size at 100 %, 8 reference samples, the methods of
    `ticked` ticked. Returns the scene."""
    import addon_utils
    run_build_script(scene_script)
    addon_utils.enable(ADDON, default_set=True)
    prefs = bpy.context.preferences.addons[ADDON].preferences
    prefs.cache_dir = cache
    prefs.threads = 2
    scene = bpy.context.scene
    s = scene.aolab
    s.preview_scale = 100
    s.reference_samples = 8
    for m in s.methods:
        getattr(s, "m_" + m).use_method = m in ticked
    return scene


def call(op, **kw) -> dict:
    """Runs an operator; returns its result set and the message it reported."""
    t0 = time.perf_counter()
    try:
        result = sorted(op(**kw))
        error = None
    except RuntimeError as e:  # an ERROR report makes bpy.ops raise in the background
        result, error = ["CANCELLED"], str(e)
    session = bpy.context.window_manager.aolab
    return {"result": result, "error": error, "message": session.message,
            "seconds": time.perf_counter() - t0}


def pump(live, timeout: float = 120.0) -> None:
    """Blender's event loop, for bpy.app.timers and live.tick only."""
    deadline = time.perf_counter() + timeout
    while bpy.app.timers.is_registered(live.tick):
        if time.perf_counter() > deadline:
            raise RuntimeError("live.tick still registered after %g s" % timeout)
        interval = live.tick()
        if interval is None:
            bpy.app.timers.unregister(live.tick)   # what Blender does when it returns None
            return
        time.sleep(interval)


class Layout:
    """Stands in for bpy.types.UILayout (which -b cannot make): records the labels, checks
    that every drawn property exists."""

    def __init__(self, texts):
        self.texts = texts

    def __getattr__(self, name):   # box, row, column, split, operator, separator, ...
        return lambda *a, **k: Layout(self.texts)

    def label(self, text="", **k):
        self.texts.append(text)

    def prop(self, owner, name, **k):
        if not hasattr(owner, name):
            raise AttributeError(f"the panel draws {owner!r}.{name}, which does not exist")


def panel_text() -> list[str]:
    """The AO Lab panel's labels, drawn by ui.draw_panel as Blender would."""
    from types import SimpleNamespace
    ui = addon_module("ui")
    texts = []
    c = bpy.context
    ui.draw_panel(Layout(texts), SimpleNamespace(
        scene=c.scene, window_manager=c.window_manager, region=None,
        preferences=c.preferences))
    return texts


def run_build_script(path):
    import runpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    runpy.run_path(path, run_name="__main__")


def scene_from_argv(dressed: bool = False):
    """Builds the scene of the build script that follows `--` on Blender's command line and
    returns it; `dressed`: with a user's non-default settings (dress_as_user_scene)."""
    run_build_script(sys.argv[sys.argv.index("--") + 1])
    scene = bpy.context.scene
    if dressed:
        dress_as_user_scene(scene)
    return scene


def rna_values(owner, depth=1, seen=None):
    """Every readable property value of `owner` (pointers followed `depth` levels), as a dict
    of plain Python values, for before/after comparisons."""
    seen = set() if seen is None else seen
    out = {}
    if owner is None or owner.as_pointer() in seen:
        return out
    seen.add(owner.as_pointer())
    for prop in owner.bl_rna.properties:
        name = prop.identifier
        if name in ("rna_type",) or prop.type == "COLLECTION":
            continue
        try:
            value = getattr(owner, name)
        except Exception:
            continue
        if prop.type == "POINTER":
            if value is None or not hasattr(value, "bl_rna"):
                out[name] = None
            elif isinstance(value, bpy.types.ID):
                out[name] = f"ID:{value.name}"  # identity only; IDs are checked by name
            elif depth > 0:
                out[name] = rna_values(value, depth - 1, seen)
            continue
        try:
            is_sequence = hasattr(value, "__len__") and not isinstance(value, str)
            out[name] = list(value) if is_sequence else value
        except TypeError:
            out[name] = str(value)
    return out


def scene_state(scene):
    """What the bridge touches, and more: render, cycles, image settings, world, view layers,
    every object with its cycles settings and data, and the set of datablocks."""
    state = {
        "scene": rna_values(scene, depth=0),
        "render": rna_values(scene.render, depth=2),
        "cycles": rna_values(scene.cycles, depth=1),
        "eevee": rna_values(scene.eevee, depth=1),
        "world": rna_values(scene.world, depth=2) if scene.world else None,
        "view_layers": {vl.name: rna_values(vl, depth=2) for vl in scene.view_layers},
        "objects": {o.name: {"object": rna_values(o, depth=0), "cycles": rna_values(o.cycles),
                             "data": rna_values(o.data, depth=2) if o.data else None}
                    for o in scene.objects},
        "ids": {kind: sorted(x.name for x in getattr(bpy.data, kind))
                for kind in ("worlds", "objects", "cameras", "meshes", "images", "materials",
                             "scenes", "lights")},
        # What the mesh export changes to evaluate as for render: every object (those of
        # collections outside the scene too), its modifiers and eye icon, collections, the
        # view layers' collection flags, particle, curve and metaball settings.
        "all_objects": {o.name: {"object": rna_values(o, depth=0),
                                 "modifiers": [rna_values(m, depth=0) for m in o.modifiers]}
                        for o in bpy.data.objects},
        "hidden": {vl.name: sorted(o.name for o in vl.objects if o.hide_get(view_layer=vl))
                   for vl in scene.view_layers},
        "collections": {c.name: rna_values(c, depth=0) for c in bpy.data.collections},
        "layer_collections": {vl.name: layer_collection_flags(vl.layer_collection)
                              for vl in scene.view_layers},
        "particles": {p.name: rna_values(p, depth=0) for p in bpy.data.particles},
        "curves": {c.name: rna_values(c, depth=0) for c in bpy.data.curves},
        "metaballs": {m.name: rna_values(m, depth=0) for m in bpy.data.metaballs},
    }
    return state


def layer_collection_flags(lc, out=None):
    """exclude, hide_viewport, holdout, indirect_only of a layer collection and its children."""
    out = {} if out is None else out
    out[lc.name] = [lc.exclude, lc.hide_viewport, lc.holdout, lc.indirect_only]
    for child in lc.children:
        layer_collection_flags(child, out)
    return out


def diff(a, b, path=""):
    """Paths where two nested states differ."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for k in sorted(set(a) | set(b)):
            out += diff(a.get(k, "<missing>"), b.get(k, "<missing>"), f"{path}.{k}")
        return out
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return []
    return [] if a == b else [f"{path}: {a!r} -> {b!r}"]


def dress_as_user_scene(scene):
    """Gives `scene` deliberately non-default settings everywhere the bridge reaches (render,
    Cycles, EEVEE, world, passes, objects, camera, a light), like a user's own scene."""
    engines = bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items.keys()
    next_ = "BLENDER_EEVEE_NEXT" in engines       # Blender 4.2 to 4.4
    scene.render.engine = "BLENDER_EEVEE_NEXT" if next_ else "BLENDER_EEVEE"
    scene.render.use_compositing = True
    scene.render.use_motion_blur = True
    scene.render.filepath = "//user_output_"
    scene.render.image_settings.file_format = "JPEG"
    scene.cycles.samples = 77
    scene.cycles.use_adaptive_sampling = True
    scene.cycles.adaptive_threshold = 0.05
    scene.cycles.use_denoising = True
    scene.cycles.max_bounces = 9
    scene.cycles.filter_width = 2.5
    scene.cycles.seed = 42
    scene.cycles.use_animated_seed = True
    scene.world.light_settings.distance = 3.3
    vl = bpy.context.view_layer
    vl.use_pass_mist = True
    vl.use_pass_diffuse_color = True
    vl.use_pass_z = False
    vl.cycles.denoising_store_passes = True
    for obj in scene.objects:
        obj.cycles.shadow_terminator_geometry_offset = 0.37
    scene.camera.data.dof.use_dof = True
    scene.camera.data.dof.focus_distance = 2.0
    light = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    scene.collection.objects.link(light)
    bpy.context.view_layer.update()
    scene.eevee.gtao_distance = 0.123
    scene.eevee.use_gtao = False
    scene.eevee.taa_render_samples = 3
    if hasattr(scene.eevee, "use_gtao_bounce"):   # 3.4's EEVEE
        scene.eevee.use_gtao_bounce = True
        scene.eevee.use_bloom = True
    else:                                         # EEVEE Next's horizon scan settings
        scene.eevee.fast_gi_thickness_near = 0.77
        scene.eevee.fast_gi_bias = 0.11
    scene.render.filter_size = 1.7
