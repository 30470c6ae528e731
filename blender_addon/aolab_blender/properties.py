"""The add-on's properties (bpy).

- `scene.aolab` (saved with the file): R, preview scale, reference samples, report folder,
  and one group per method (`scene.aolab.m_<method>`) with its checkbox, preset, shared
  blur and every setting of aolab.method_info as a Blender property (default, range and
  description from the C++ field table; a choice setting as an enum of its names). The
  method groups are built when the add-on is registered, from aolab.methods() at that time.
- `window_manager.aolab` (this session only): the running job's progress, the last message,
  the results table (AOLAB_PG_result rows) of the last Preview, Compare or live update, and
  the Live switch with its last update's times. Every setting's update= callback calls a
  hook (hooks.py) that live.py registers; Live does nothing unless it is on.

What they take from `aolab` (the settings tables, the presets) comes through library.py;
without it (library.available() False) the method groups are empty.
"""

import bpy

from . import hooks, library

# `# noqa: F722` / `F821` below: pyflakes reads the strings in bpy property annotations
# (`mae: bpy.props.FloatProperty(name="MAE")`) as forward references to types.

BUDGET_ITEMS = [(str(b), f"{b} ms", f"{b} ms per 1280x720 frame") for b in library.BUDGETS_MS]

METHOD_PREFIX = "m_"
UI_FIELDS = ("use_method", "show_expanded", "preset", "use_blur")
INT_LIMIT = 2**31 - 1
FLOAT_LIMIT = 3.0e38


# Every setting's update= callback tells Live what changed, through the hook live.py
# registers (hooks.py): this module does not import live, which imports it.
def _live_toggled(self, context):
    hooks.call("live_toggled", self, context)


def _setting_changed(self, context):
    hooks.call("setting_changed", self, context)


def _scene_setting_changed(self, context):
    hooks.call("scene_setting_changed", self, context)


class AOLAB_PG_result(bpy.types.PropertyGroup):
    method: bpy.props.StringProperty(name="Method")  # noqa: F821
    label: bpy.props.StringProperty(
        name="Settings",  # noqa: F821
        description="Preset or changed settings")  # noqa: F722
    ms: bpy.props.FloatProperty(name="ms", description="Compute time in milliseconds")  # noqa: F722
    has_metrics: bpy.props.BoolProperty()
    mae: bpy.props.FloatProperty(name="MAE", precision=4)  # noqa: F821
    ssim: bpy.props.FloatProperty(name="SSIM", precision=4)  # noqa: F821
    rmse: bpy.props.FloatProperty(name="RMSE", precision=4)  # noqa: F821
    bias: bpy.props.FloatProperty(name="Bias", precision=4)  # noqa: F821
    metrics_json: bpy.props.StringProperty(
        description="aolab.metrics' dict in full (double) precision; the float "  # noqa: F722
                    "properties above are single precision, for display")
    image: bpy.props.StringProperty(name="Image")  # noqa: F821
    error_image: bpy.props.StringProperty(name="Error Image")  # noqa: F722


class AOLAB_PG_session(bpy.types.PropertyGroup):
    busy: bpy.props.BoolProperty()
    cancel_requested: bpy.props.BoolProperty()
    job_name: bpy.props.StringProperty()
    progress: bpy.props.FloatProperty(
        name="Progress", subtype="PERCENTAGE", min=0, max=100,  # noqa: F821
        precision=0)
    stage: bpy.props.StringProperty()
    message: bpy.props.StringProperty()
    message_is_error: bpy.props.BoolProperty()
    results: bpy.props.CollectionProperty(type=AOLAB_PG_result)
    results_kind: bpy.props.StringProperty()   # "Preview", "Compare", "Quick Compare", "Live"
    results_scene: bpy.props.StringProperty()
    results_size: bpy.props.StringProperty()
    results_reference: bpy.props.StringProperty()   # what Compare scored against, its label
    results_noise: bpy.props.FloatProperty(default=-1.0)   # its noise (-1: unknown)
    advice_json: bpy.props.StringProperty()   # the last Advise (aolab.study.advise.run)
    advice_scene: bpy.props.StringProperty()
    advice_size: bpy.props.StringProperty()
    reference_folder: bpy.props.StringProperty()   # the last reference rendered or compared
    gbuffer_folder: bpy.props.StringProperty()     # the G-buffer of the last Preview / Compare
    report_path: bpy.props.StringProperty()
    live: bpy.props.BoolProperty(
        name="Live", default=False, update=_live_toggled,  # noqa: F821
        description="Redraw a method's image whenever its settings, R or the "  # noqa: F722
                    "Resolution change, from the G-buffer Preview cached (no button press), "
                    "then converge it over Accumulate frames while nothing changes")
    live_message: bpy.props.StringProperty()
    live_message_is_error: bpy.props.BoolProperty()
    live_method: bpy.props.StringProperty()
    live_compute_ms: bpy.props.FloatProperty(
        name="Compute",  # noqa: F821
        description="aolab.compute of the last live update (ms)")  # noqa: F722
    live_image_ms: bpy.props.FloatProperty(
        name="Image",  # noqa: F821
        description="Writing the last live result into its image (ms)")  # noqa: F722
    live_total_ms: bpy.props.FloatProperty(
        name="Total",  # noqa: F821
        description="From the change to the updated image (ms)")  # noqa: F722
    live_frame: bpy.props.IntProperty(
        name="Frame",  # noqa: F821
        description="Frames averaged in the last live image")  # noqa: F722
    live_frame_goal: bpy.props.IntProperty(
        name="Frames",  # noqa: F821
        description="Frames the last live image converges to (its Accumulate)")  # noqa: F722


def _setting_property(s: dict):
    desc = s["description"] + (f" ({s['unit']})" if s["unit"] else "")
    name = s["name"].replace("_", " ").title()
    if library.method_settings.is_choice(s):
        items = [(c, c.replace("_", " ").title(), f"{s['name']} = {c}") for c in s["choices"]]
        return bpy.props.EnumProperty(name=name, description=desc, items=items,
                                      default=s["default"], update=_setting_changed)
    if s["type"] == "bool":
        return bpy.props.BoolProperty(name=name, description=desc, default=bool(s["default"]),
                                      update=_setting_changed)
    if s["type"] == "int":
        return bpy.props.IntProperty(name=name, description=desc, default=int(s["default"]),
                                     min=int(max(s["min"], -INT_LIMIT)),
                                     max=int(min(s["max"], INT_LIMIT)), update=_setting_changed)
    return bpy.props.FloatProperty(name=name, description=desc, default=float(s["default"]),
                                   min=max(s["min"], -FLOAT_LIMIT),
                                   max=min(s["max"], FLOAT_LIMIT), precision=4,
                                   update=_setting_changed)


def _preset_label(name: str) -> str:
    """"low" -> "Low", "tuned-100ms" -> "Tuned 100 ms"."""
    presets = library.presets
    if name.startswith(presets.TUNED_PREFIX):
        return f"Tuned {presets.budget_of(name):g} ms"
    return name.title()


def preset_problem(method: str) -> str | None:
    """Why the method's preset menu lacks the tuned presets (a bad tuned-presets file: its
    error, naming the file), or None. The built-in presets serve all the same."""
    try:
        library.presets.tuned_presets(method)
    except ValueError as e:
        return str(e)
    return None


def _preset_items(self, context):
    """aolab.presets(method)'s names: default, the study's presets, the tuned ones. A bad
    tuned-presets file leaves the tuned ones out (the panel says why: ui._problems) instead
    of a Python error in every redraw and an empty menu."""
    presets = library.presets
    try:
        names = presets.names(self.method_name)
    except ValueError:
        names = [presets.DEFAULT_PRESET] + presets.preset_names(self.method_name)
    items = [(n, _preset_label(n), f"{self.method_name} at its {n} preset") for n in names]
    # The enum keeps the returned strings alive only while they are referenced.
    _preset_items.cache[self.method_name] = items
    return items


_preset_items.cache = {}


def apply_preset(self, context):
    """Puts the preset's values into the settings (default: every setting's default). The
    name is checked as aolab.compute(preset=...) checks it; a preset that cannot be applied
    (its tuned-presets file changed and went bad) leaves the settings as they were and says
    why in the panel: an update callback cannot report, and a raise would be a traceback."""
    try:
        values, blur = library.presets.preset_values(self.method_name, self.preset)
    except ValueError as e:
        session = context.window_manager.aolab
        session.message, session.message_is_error = f"Preset: {e}", True
        return
    for s in library.method_settings.described(self.method_name):
        setattr(self, s["name"], values.get(s["name"], s["default"]))
    self.use_blur = blur
    _setting_changed(self, context)   # also when the preset changed no value


def _method_group(method: str, index: int):
    settings = library.method_settings.described(method)
    clash = [s["name"] for s in settings if s["name"] in UI_FIELDS]
    if clash:
        raise RuntimeError(f"{method}: settings {clash} clash with the panel's own fields")
    annotations = {
        "use_method": bpy.props.BoolProperty(name=method, default=index == 0,
                                             description=f"Compare {method}",
                                             update=_setting_changed),
        "show_expanded": bpy.props.BoolProperty(name="Show settings", default=False),
        "preset": bpy.props.EnumProperty(
            name="Preset", items=_preset_items, update=apply_preset,
            description="Quality preset of the comparison study"),
        "use_blur": bpy.props.BoolProperty(
            name="Blur", default=False, update=_setting_changed,
            description="The shared separable Gaussian after the method (sigma 1.5 px, 5 taps)"),
    }
    annotations.update({s["name"]: _setting_property(s) for s in settings})
    return type(f"AOLAB_PG_method_{method}", (bpy.types.PropertyGroup,),
                {"__annotations__": annotations, "method_name": method,
                 "setting_names": tuple(s["name"] for s in settings)})


def _scene_group(method_groups: dict):
    annotations = {
        "use_scene_radius": bpy.props.BoolProperty(
            name="Scene AO Distance", default=True, update=_scene_setting_changed,
            description="Use the world's AO distance (World > Ambient Occlusion) as R"),
        "radius": bpy.props.FloatProperty(
            name="Radius", default=1.0, min=1e-6, max=1e6, subtype="DISTANCE", precision=3,
            update=_scene_setting_changed,
            description="R, the AO distance of the reference and every method (scene units)"),
        "preview_scale": bpy.props.IntProperty(
            name="Resolution", default=25, min=1, max=100, subtype="PERCENTAGE",
            update=_scene_setting_changed,
            description="Preview, reference and comparison resolution, as a percentage of the "
                        "scene's output resolution"),
        "live_frames": bpy.props.IntProperty(
            name="Accumulate", default=16, min=1, max=1024, soft_max=256,
            update=_scene_setting_changed,
            description="Live keeps computing a resting image at a new per-frame seed and "
                        "shows the mean of up to this many frames, then stops (one compute "
                        "per frame): noise falls as 1/sqrt(frames), so 16 frames have a "
                        "quarter of one frame's. 1: off, one frame per change"),
        "reference_samples": bpy.props.IntProperty(
            name="Reference Samples", default=1024, min=1, max=65536,
            description="Cycles AO samples of the reference (adaptive sampling off)"),
        "quick_rays": bpy.props.IntProperty(
            name="Quick Rays", default=library.QUICK_RAYS, min=2, max=65536,
            description="Rays per pixel of the quick reference (rtao against the scene's "
                        "triangles) that Quick Compare and Advise score against: its noise, "
                        "stated beside the scores, falls as 1/sqrt(rays)"),
        "advise_budget": bpy.props.EnumProperty(
            name="Budget", items=BUDGET_ITEMS, default=BUDGET_ITEMS[0][0],
            description="Advise names the most accurate configuration within this time per "
                        "1280x720 frame (measured at the Resolution, scaled by pixels)"),
        "report_dir": bpy.props.StringProperty(
            name="Report Folder", subtype="DIR_PATH", default="//aolab_report",
            description="Where Write Report puts report.html (// = beside the .blend file)"),
    }
    for method, cls in method_groups.items():
        annotations[METHOD_PREFIX + method] = bpy.props.PointerProperty(type=cls)
    return type("AOLAB_PG_scene", (bpy.types.PropertyGroup,),
                {"__annotations__": annotations, "methods": tuple(method_groups)})


STATIC = (AOLAB_PG_result, AOLAB_PG_session)
_dynamic = []


def register():
    """Registers the result and session groups, one group per method (when aolab imports)
    and the scene group, then hooks them onto Scene and WindowManager."""
    groups = {m: _method_group(m, i) for i, m in enumerate(library.methods())}
    _dynamic[:] = list(STATIC) + list(groups.values()) + [_scene_group(groups)]
    for cls in _dynamic:
        bpy.utils.register_class(cls)
    bpy.types.Scene.aolab = bpy.props.PointerProperty(type=_dynamic[-1])
    bpy.types.WindowManager.aolab = bpy.props.PointerProperty(type=AOLAB_PG_session)


def unregister():
    del bpy.types.WindowManager.aolab
    del bpy.types.Scene.aolab
    for cls in reversed(_dynamic):
        bpy.utils.unregister_class(cls)
    _dynamic.clear()


def method_group(scene, method: str):
    return getattr(scene.aolab, METHOD_PREFIX + method)


def effective_radius(scene) -> float | None:
    """R: the world's AO distance, or the panel's value (None: no world to take it from)."""
    s = scene.aolab
    if s.use_scene_radius:
        return scene.world.light_settings.distance if scene.world is not None else None
    return s.radius


def chosen_runs(scene) -> list[dict]:
    """The checked methods with their settings (only those changed from the defaults) and
    blur, in aolab.methods() order."""
    runs = []
    for method in scene.aolab.methods:
        g = method_group(scene, method)
        if not g.use_method:
            continue
        values = {name: getattr(g, name) for name in g.setting_names}
        changed = library.method_settings.changed_settings(method, values)
        label = g.preset if g.preset != library.presets.DEFAULT_PRESET else \
            (",".join(f"{k}={v}" for k, v in changed.items()) or "defaults")
        runs.append({"method": method, "settings": changed, "blur": bool(g.use_blur),
                     "label": label + (" +blur" if g.use_blur else "")})
    return runs
