"""The AO Lab panel (bpy): the 3D viewport sidebar tab "AO Lab" and Properties > View Layer
show the same content (draw_panel)."""

from __future__ import annotations

import bpy

from . import lab, operators, properties, study

RESULT_COLUMNS = (0.34, 0.19, 0.19, 0.16)   # method | MAE | SSIM | ms, then image buttons


def _problems(context) -> list[str]:
    scene = context.scene
    if not lab.available():
        return [lab.NOT_BUILT]
    out = []
    problem = operators.camera_problem(scene)
    if problem:
        out.append(problem)
    if properties.effective_radius(scene) is None:
        out.append("no world: set the radius by hand")
    if not properties.chosen_runs(scene):
        out.append("nothing selected: tick a method")
    return out


def _wrapped(layout, text: str, icon: str = "NONE", width: int = 48) -> None:
    col = layout.column(align=True)
    words, line, first = text.split(), "", True
    for w in words:
        if line and len(line) + len(w) + 1 > width:
            col.label(text=line, icon=icon if first else "BLANK1")
            line, first = "", False
        line = f"{line} {w}".strip()
    if line:
        col.label(text=line, icon=icon if first else "BLANK1")


def _draw_methods(layout, scene) -> None:
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
    if not study.preset_names(scene.aolab.methods[0] if scene.aolab.methods else ""):
        box.label(text="Presets: " + study.UNAVAILABLE.split(" (")[0], icon="INFO")


def _draw_results(layout, session, scene) -> None:
    if not len(session.results) or session.results_scene != scene.name:
        return
    box = layout.box()
    box.label(text=f"{session.results_kind} {session.results_size}", icon="IMAGE_DATA")
    scored = session.results_kind == "Compare"

    def columns(row):
        cols, rest = [], row
        for f in RESULT_COLUMNS:
            split = rest.split(factor=f / (1 - sum(RESULT_COLUMNS[:len(cols)])), align=True)
            cols.append(split.row(align=True))
            rest = split
        cols.append(rest.row(align=True))
        return cols

    head = columns(box.row())
    for col, text in zip(head, ("Method", "MAE", "SSIM", "ms", "")):
        col.label(text=text)
    for r in session.results:
        cols = columns(box.row())
        cols[0].label(text=r.method)
        cols[1].label(text=f"{r.mae:.4f}" if r.has_metrics else "-")
        cols[2].label(text=f"{r.ssim:.3f}" if r.has_metrics else "-")
        cols[3].label(text=f"{r.ms:.1f}")
        op = cols[4].operator("aolab.show_image", text="", icon="IMAGE_RGB_ALPHA")
        op.image = r.image
        if r.error_image:
            op = cols[4].operator("aolab.show_image", text="", icon="MOD_MASK")
            op.image = r.error_image
    if scored:
        row = box.row()
        op = row.operator("aolab.show_image", text="Reference", icon="RENDER_RESULT")
        op.image = "AO Lab reference"
        box.label(text="Error map: blue = lighter, red = darker than the reference")


def draw_panel(layout, context) -> None:
    scene = context.scene
    wm = context.window_manager
    session = wm.aolab
    for problem in _problems(context):
        _wrapped(layout.box(), problem, icon="ERROR")
    if not lab.available():
        return
    s = scene.aolab
    col = layout.column(align=True)
    row = col.row(align=True)
    row.prop(s, "use_scene_radius")
    sub = row.row(align=True)
    if s.use_scene_radius and scene.world is not None:
        sub.enabled = False
        sub.prop(scene.world.light_settings, "distance", text="R")
    else:
        sub.prop(s, "radius", text="R")
    col.prop(s, "preview_scale")
    col.prop(s, "reference_samples")

    _draw_methods(layout, scene)

    col = layout.column(align=True)
    col.enabled = not session.busy
    col.operator("aolab.preview", icon="HIDE_OFF")
    row = col.row(align=True)
    row.operator("aolab.render_reference", icon="RENDER_STILL")
    row.operator("aolab.compare", icon="GRAPH")
    row = col.row(align=True)
    row.operator("aolab.write_report", icon="FILE_TEXT")
    if session.report_path:
        row.operator("aolab.open_report", text="", icon="URL")
    if not study.report_available():
        col.label(text=study.UNAVAILABLE.split(" (")[0], icon="INFO")

    if session.busy:
        box = layout.box()
        box.label(text=f"{session.job_name}: {session.stage}", icon="SORTTIME")
        row = box.row(align=True)
        bar = row.row()
        bar.enabled = False
        bar.prop(session, "progress", slider=True, text="")
        row.operator("aolab.cancel", text="", icon="CANCEL")
    elif session.message:
        _wrapped(layout, session.message, icon="ERROR" if session.message_is_error else "INFO")

    _draw_results(layout, session, scene)


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
