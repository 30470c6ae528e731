"""The AO Lab panel (bpy): the 3D viewport sidebar tab "AO Lab" and Properties > View Layer
show the same content (draw_panel)."""

import json

import bpy

from . import images, inputs, library, properties

RESULT_COLUMNS = (0.34, 0.19, 0.19, 0.16)   # method | MAE | SSIM | ms, then image buttons
WIDE_TABLE_CHARS = 44                       # narrower regions get two lines per method
FRONT_ICON_UNITS = (5, 30)                  # the front's preview: its least and most UI units
AS_GOOD_SHOWN = 3                           # picks not told apart at the noise, listed at most


def _problems(context) -> list[str]:
    scene = context.scene
    if not library.available():
        return [library.problem()]
    out = []
    problem = inputs.camera_problem(scene)
    if problem:
        out.append(problem)
    if properties.effective_radius(scene) is None:
        out.append("no world: set the radius by hand")
    if not properties.chosen_runs(scene):
        out.append("nothing selected: tick a method")
    tuned = next(filter(None, map(properties.preset_problem, scene.aolab.methods)), None)
    if tuned:
        out.append(f"tuned presets left out of the menus: {tuned}")
    return out


def _chars(context) -> int:
    """About how many characters fit across the region."""
    region = context.region
    scale = context.preferences.view.ui_scale
    return max(20, int((region.width if region else 300) / (8 * scale)) - 5)


def _wrapped(layout, text: str, icon: str = "NONE", width: int = 40) -> None:
    col = layout.column(align=True)
    words, line, first = text.split(), "", True
    for w in words:
        if line and len(line) + len(w) + 1 > width:
            col.label(text=line, icon=icon if first else "BLANK1")
            line, first = "", False
        line = f"{line} {w}".strip()
    if line:
        col.label(text=line, icon=icon if first else "BLANK1")


def _draw_methods(layout, scene, width: int) -> None:
    box = layout.box()
    box.label(text="Methods", icon="MOD_SMOOTH")
    for method in scene.aolab.methods:
        g = properties.method_group(scene, method)
        row = box.row(align=True)
        row.prop(g, "show_expanded", text="", emboss=False,
                 icon="TRIA_DOWN" if g.show_expanded else "TRIA_RIGHT")
        row.prop(g, "use_method", text=method)
        sub = row.row(align=True)
        sub.active = g.use_method
        sub.prop(g, "preset", text="")
        if g.show_expanded:
            col = box.column(align=True)
            col.active = g.use_method
            for name in g.setting_names:
                col.prop(g, name)
            col.prop(g, "use_blur")


def _image_buttons(layout, r) -> None:
    op = layout.operator("aolab.show_image", text="", icon="IMAGE_RGB_ALPHA")
    op.image = r.image
    if r.error_image:
        op = layout.operator("aolab.show_image", text="", icon="MOD_MASK")
        op.image = r.error_image


def _columns(row, factors):
    """Splits `row` into len(factors) + 1 sub-rows of the given width shares."""
    cols, rest, used = [], row, 0.0
    for f in factors:
        split = rest.split(factor=f / (1 - used), align=True)
        cols.append(split.row(align=True))
        rest, used = split, used + f
    cols.append(rest.row(align=True))
    return cols


def _draw_results(layout, session, scene, width: int) -> None:
    """The results table: one line per method where the region is wide enough (Method, MAE,
    SSIM, ms, image buttons), else two (method and ms, buttons / MAE and SSIM)."""
    if not len(session.results) or session.results_scene != scene.name:
        return
    box = layout.box()
    box.label(text=f"{session.results_kind} {session.results_size}", icon="IMAGE_DATA")
    if session.results_reference:
        noise = (f", noise {session.results_noise:.4f}: each MAE may read up to that much "
                 "high" if session.results_noise >= 0 else ", noise unknown")
        _wrapped(box, f"Against {session.results_reference}{noise}", icon="INFO", width=width)
    if width >= WIDE_TABLE_CHARS:
        for col, text in zip(_columns(box.row(), RESULT_COLUMNS), ("Method", "MAE", "SSIM", "ms")):
            col.label(text=text)
        for r in session.results:
            cols = _columns(box.row(), RESULT_COLUMNS)
            cols[0].label(text=r.method)
            cols[1].label(text=f"{r.mae:.4f}" if r.has_metrics else "-")
            cols[2].label(text=f"{r.ssim:.3f}" if r.has_metrics else "-")
            cols[3].label(text=f"{r.ms:.1f}")
            _image_buttons(cols[4], r)
    else:
        col = box.column(align=True)
        for r in session.results:
            row = col.row(align=True)
            left, right = _columns(row, (0.8,))
            left.label(text=f"{r.method}  {r.ms:.0f} ms")
            right.alignment = "RIGHT"
            _image_buttons(right, r)
            if r.has_metrics:
                col.label(text=f"MAE {r.mae:.4f}  SSIM {r.ssim:.3f}", icon="BLANK1")
            col.separator()
    if session.results_kind in ("Compare", "Quick Compare"):
        op = box.operator("aolab.show_image", text="Reference", icon="RENDER_RESULT")
        op.image = "AO Lab reference"
        _wrapped(box, "Error maps: blue = lighter, red = darker than the reference",
                 width=width)


_advice_cache = {"text": None, "result": None}


def _advice(session, scene) -> dict | None:
    """The last Advise's data for this scene (parsed once per run), or None."""
    if not session.advice_json or session.advice_scene != scene.name:
        return None
    if _advice_cache["text"] != session.advice_json:
        _advice_cache.update(text=session.advice_json, result=json.loads(session.advice_json))
    return _advice_cache["result"]


def _icon_units(context) -> float:
    """The front's preview as wide as the region (its square fits the width), in UI units."""
    region = context.region
    scale = context.preferences.view.ui_scale
    units = ((region.width if region else 300) - 40) / (20 * scale)
    return max(FRONT_ICON_UNITS[0], min(FRONT_ICON_UNITS[1], units))


def _draw_advice(layout, context, session, width: int) -> None:
    """"Which method for this scene?": the Budget, the Advise button and, after it ran on
    this scene, the front, the best configuration within the budget with its Apply button,
    those not told apart from it at the reference's noise, and what it was scored against."""
    scene = context.scene
    box = layout.box()
    box.label(text="Which method for this scene?", icon="QUESTION")
    box.row(align=True).prop(scene.aolab, "advise_budget", expand=True)
    row = box.row(align=True)
    row.enabled = not session.busy
    row.operator("aolab.advise", icon="VIEWZOOM")
    result = _advice(session, scene)
    if result is None:
        return
    advise = library.advise
    icon = images.preview_icon(images.image_name(images.ADVICE))
    if icon:
        box.template_icon(icon_value=icon, scale=_icon_units(context))
    op = box.operator("aolab.show_image", text="Front in the Image Editor", icon="IMAGE_DATA")
    op.image = images.image_name(images.ADVICE)
    budget = float(scene.aolab.advise_budget)
    got = advise.choose(result, budget)
    best = got["best"]
    if best is None:
        _wrapped(box, f"No advice within {budget:g} ms: {got['why']}", icon="ERROR", width=width)
        if got["fastest"] is not None:
            _wrapped(box, "The fastest: " + advise.describe(result, got["fastest"]),
                     width=width)
    else:
        scores = best["scenes"][result["scene"]]
        _wrapped(box, f"Within {budget:g} ms: {best['label']}", icon="CHECKMARK", width=width)
        _wrapped(box, f"occluded MAE {scores['mae']:.4f}, whole frame {scores['all_mae']:.4f}, "
                      f"{scores['ms']:.1f} ms per 1280x720 frame", icon="BLANK1", width=width)
        op = box.operator("aolab.apply_advice", text=f"Apply {best['short']}",
                          icon="CHECKBOX_HLT")
        op.method, op.preset = best["method"], best["preset"]
        for t in got["as_good"][:AS_GOOD_SHOWN]:
            s = t["scenes"][result["scene"]]
            _wrapped(box, f"Not told apart at this noise: {t['short']} ({s['mae']:.4f}, "
                          f"{s['ms']:.0f} ms)", icon="BLANK1", width=width)
    ref = result["reference"]
    noise = "" if ref["noise_occluded"] is None else \
        f", noise {ref['noise_occluded']:.4f} on the occluded region"
    _wrapped(box, f"Against {ref['label']}{noise}; {len(result['trials'])} configurations at "
                  f"{session.advice_size} in {result['seconds']:.1f} s", icon="INFO", width=width)


def _draw_live(layout, session, s, width: int) -> None:
    """Live's state: its Accumulate setting, why nothing is computed (no G-buffer cached:
    which button exports it), or the last update's frame, compute and change-to-image
    times."""
    box = layout.box()
    box.prop(s, "live_frames")
    if session.live_message_is_error:
        _wrapped(box, "Live: " + session.live_message, icon="ERROR", width=width)
    elif session.live_method:
        col = box.column(align=True)
        frames = f", frame {session.live_frame}/{session.live_frame_goal}" \
            if session.live_frame_goal > 1 else ""
        col.label(text=f"Live: {session.live_method}{frames}", icon="PLAY")
        col.label(text=f"{session.live_compute_ms:.1f} ms compute, "
                       f"{session.live_image_ms:.1f} ms image", icon="BLANK1")
        col.label(text=f"{session.live_total_ms:.1f} ms change to image", icon="BLANK1")
    else:
        _wrapped(box, "Live: " + (session.live_message or "change a setting"), icon="PLAY",
                 width=width)


def draw_panel(layout, context) -> None:
    scene = context.scene
    wm = context.window_manager
    session = wm.aolab
    width = _chars(context)
    for problem in _problems(context):
        _wrapped(layout.box(), problem, icon="ERROR", width=width)
    if not library.available():
        return
    s = scene.aolab
    col = layout.column(align=True)
    col.prop(s, "use_scene_radius")
    sub = col.row(align=True)
    if s.use_scene_radius and scene.world is not None:
        sub.enabled = False
        sub.prop(scene.world.light_settings, "distance", text="Radius")
    else:
        sub.prop(s, "radius")
    col.prop(s, "preview_scale")
    col.prop(s, "reference_samples")

    _draw_methods(layout, scene, width)

    row = layout.row(align=True)
    sub = row.row(align=True)
    sub.enabled = not session.busy
    sub.operator("aolab.preview", icon="HIDE_OFF")
    row.prop(session, "live", toggle=True, icon="PLAY")
    if session.live:
        _draw_live(layout, session, s, width)
    col = layout.column(align=True)
    col.enabled = not session.busy
    row = col.row(align=True)
    row.operator("aolab.render_reference", icon="RENDER_STILL")
    row.operator("aolab.compare", icon="GRAPH")
    row = col.row(align=True)
    row.operator("aolab.quick_compare", icon="AUTO")
    row.prop(s, "quick_rays", text="Rays")
    row = col.row(align=True)
    row.operator("aolab.write_report", icon="FILE_TEXT")
    if session.report_path:
        row.operator("aolab.open_report", text="", icon="URL")

    if session.busy:
        box = layout.box()
        box.label(text=f"{session.job_name}: {session.stage}", icon="SORTTIME")
        row = box.row(align=True)
        bar = row.row()
        bar.enabled = False
        bar.prop(session, "progress", slider=True, text="")
        row.operator("aolab.cancel", text="", icon="CANCEL")
    elif session.message:
        _wrapped(layout, session.message, icon="ERROR" if session.message_is_error else "INFO",
                 width=width)

    _draw_results(layout, session, scene, width)
    _draw_advice(layout, context, session, width)


class AOLAB_PT_sidebar(bpy.types.Panel):
    bl_label = "AO Lab"
    bl_idname = "AOLAB_PT_sidebar"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "AO Lab"

    def draw(self, context):
        draw_panel(self.layout, context)


class AOLAB_PT_view_layer(bpy.types.Panel):
    bl_label = "AO Lab"
    bl_idname = "AOLAB_PT_view_layer"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "view_layer"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        draw_panel(self.layout, context)


CLASSES = (AOLAB_PT_sidebar, AOLAB_PT_view_layer)
