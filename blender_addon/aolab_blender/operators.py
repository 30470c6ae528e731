"""The add-on's operators (bpy).

Preview, Render Reference, Compare, Quick Compare, Advise and Write Report share one pattern
(_JobOperator):
`prepare()` reads everything it needs from Blender on the main thread and checks what the
user can fix (inputs.py: UserError); an aolab.jobs.runner.Job runs the heavy part
(aolab.jobs.tasks) in a thread (aolab's C++ with the GIL released, or a child process
rendering the reference); `finish()` writes images and the results table on the main thread.

- invoke() (a click in the panel) is modal: an event timer polls the job, the panel and the
  window's progress indicator follow it, Esc or the panel's Cancel button stop it.
- execute() (scripts, tests, `bpy.ops.aolab.preview()` from Python) runs the same job and
  waits for it, blocking, then finishes the same way.
"""

import json
import os
import shutil
import tempfile
from pathlib import Path

import bpy

from . import images, library, live, properties
from .inputs import UserError, find_reference, folder_problem, reference_inputs, scene_inputs

TIMER_S = 0.1
ACTIVE = {}   # the running job's operator class name -> its Job (tests use it)


# ---- on the main thread: the copy of the file a job renders, redraws ----

def save_copy(context) -> tuple[str, str]:
    """A copy of the open file in a new temporary folder (the user's file, its path and its
    scene are untouched). Returns (path, folder)."""
    folder = tempfile.mkdtemp(prefix="aolab-scene-")
    name = bpy.path.clean_name(context.scene.name) or "scene"
    path = os.path.join(folder, f"{name}.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path, copy=True, check_existing=False)
    return path, folder


def _redraw(context) -> None:
    for window in context.window_manager.windows:
        for area in window.screen.areas:
            if area.type in ("VIEW_3D", "PROPERTIES", "IMAGE_EDITOR"):
                area.tag_redraw()


# ---- the shared modal / blocking pattern ----

class _JobOperator:
    bl_options = {"REGISTER"}
    task = ""   # the name of an aolab.jobs.tasks.*_task

    @classmethod
    def poll(cls, context):
        if context.window_manager.aolab.busy:
            cls.poll_message_set("AO Lab is busy: wait, or cancel the running job")
            return False
        return True

    def prepare(self, context) -> dict | None:
        """The job's plan, or None when nothing needs computing (then finish(result))."""
        raise NotImplementedError

    def finish(self, context, result: dict) -> str:
        raise NotImplementedError

    def _start(self, context):
        session = context.window_manager.aolab
        try:
            self._plan = self.prepare(context)
        except UserError as e:
            return self._fail(context, str(e))
        except Exception as e:  # noqa: BLE001 - never a traceback in Blender: say what failed
            # (saving the copy of the file into a full or unwritable temporary folder, ...)
            return self._fail(context, f"{self.bl_label}: {type(e).__name__}: {e}")
        if "result" in self._plan:  # served from the cache
            return self._succeed(context, self._plan["result"])
        session.busy, session.cancel_requested = True, False
        session.job_name, session.progress, session.stage = self.bl_label, 0.0, "starting"
        session.message = ""
        self._job = library.runner.Job(getattr(library.tasks, self.task), self._plan)
        ACTIVE[type(self).__name__] = self._job
        return None

    def _update(self, context) -> None:
        session = context.window_manager.aolab
        session.progress = 100.0 * self._job.progress
        session.stage = self._job.stage
        if context.window is not None:
            context.window_manager.progress_update(session.progress)
        _redraw(context)

    def _end(self, context):
        session = context.window_manager.aolab
        session.busy = False
        ACTIVE.pop(type(self).__name__, None)
        folder = self._plan.get("tmpdir")
        if folder:
            shutil.rmtree(folder, ignore_errors=True)
        job, runner = self._job, library.runner
        if isinstance(job.error, runner.Cancelled) or (job.cancelled and job.error is not None):
            session.message, session.message_is_error = f"{self.bl_label}: cancelled", False
            self.report({"WARNING"}, session.message)
            _redraw(context)
            return {"CANCELLED"}
        if job.error is not None:
            kind = "" if isinstance(job.error, (runner.JobError, ValueError)) else \
                f"{type(job.error).__name__}: "
            return self._fail(context, f"{kind}{job.error}")
        return self._succeed(context, job.result)

    def _fail(self, context, message: str):
        session = context.window_manager.aolab
        session.message, session.message_is_error = message, True
        self.report({"ERROR"}, message)
        _redraw(context)
        return {"CANCELLED"}

    def _succeed(self, context, result: dict):
        session = context.window_manager.aolab
        session.message, session.message_is_error = self.finish(context, result), False
        self.report({"INFO"}, session.message)
        _redraw(context)
        return {"FINISHED"}

    def execute(self, context):
        started = self._start(context)
        if started is not None:
            return started
        while not self._job.wait(TIMER_S):
            self._update(context)
        self._update(context)
        return self._end(context)

    def invoke(self, context, event):
        started = self._start(context)
        if started is not None:
            return started
        wm = context.window_manager
        self._timer = wm.event_timer_add(TIMER_S, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0, 100)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        session = context.window_manager.aolab
        if (event.type == "ESC" and event.value == "PRESS") or session.cancel_requested:
            if not self._job.cancelled:
                self._job.cancel()
                session.stage = "cancelling"
            if event.type == "ESC":
                return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        self._update(context)
        if not self._job.done:
            return {"RUNNING_MODAL"}
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        return self._end(context)


def _with_gbuffer(context, inputs: dict) -> dict:
    """The plan of a job that needs the scene's G-buffer with inputs["passes"]: a cached
    render of this content and size (any samples, R), else a copy of the file to render."""
    plan = {**inputs, "cached": find_reference(inputs, spp=None)}
    if plan["cached"] is None:
        plan["blend"], plan["tmpdir"] = save_copy(context)
    return plan


def _quick_plan(context, inputs: dict) -> dict:
    """_with_gbuffer with the scene's triangles (the `mesh` pass) and the quick reference's
    rays."""
    inputs = {**inputs, "passes": list(inputs["passes"]) + ["mesh"],
              "rays": context.scene.aolab.quick_rays}
    return _with_gbuffer(context, inputs)


def _store_results(context, result: dict, kind: str, size) -> None:
    session = context.window_manager.aolab
    session.results.clear()
    for run in result["runs"]:
        row = session.results.add()
        row.method, row.label, row.ms = run["method"], run["label"], run["seconds"] * 1000.0
        row.image = images.image_name(run["method"])
        images.set_image(row.image, run["ao"])
        if run["metrics"] is not None:
            m = run["metrics"]
            row.has_metrics = True
            row.mae, row.ssim, row.rmse, row.bias = m["mae"], m["ssim"], m["rmse"], m["bias"]
            row.metrics_json = json.dumps(m)
            row.error_image = images.image_name(run["method"], "error")
            images.set_image(row.error_image, run["error_rgb"])
    if result.get("reference") is not None:
        images.set_image(images.image_name("reference"), result["reference"])
    session.results_kind, session.results_scene = kind, context.scene.name
    session.results_size = f"{size[0]}x{size[1]}"
    session.gbuffer_folder = result["folder"]
    ref = result.get("reference_info") or {}
    session.results_reference = ref.get("label", "")
    session.results_noise = ref["noise"] if ref.get("noise") is not None else -1.0
    if kind == "Compare":
        session.reference_folder = result["folder"]


def _lowest_mae(result: dict) -> str:
    best = min(result["runs"], key=lambda r: r["metrics"]["mae"])
    return f"lowest MAE: {best['method']} {best['metrics']['mae']:.4f}"


class AOLAB_OT_preview(_JobOperator, bpy.types.Operator):
    """Run the ticked methods on the scene's G-buffer at the preview resolution and show
    each result as an image with its time"""
    bl_idname = "aolab.preview"
    bl_label = "Preview"
    task = "preview_task"

    def prepare(self, context):
        return _with_gbuffer(context, scene_inputs(context))

    def finish(self, context, result):
        _store_results(context, result, "Preview", self._plan["size"])
        live.gbuffer_exported(context)
        times = ", ".join(f"{r['method']} {r['seconds'] * 1000:.1f} ms" for r in result["runs"])
        return f"Preview {self._plan['size'][0]}x{self._plan['size'][1]}: {times}"


class AOLAB_OT_render_reference(_JobOperator, bpy.types.Operator):
    """Render the Cycles AO reference (the Reference Samples, adaptive sampling off) of a
    copy of this file in the background; cached. Esc cancels"""
    bl_idname = "aolab.render_reference"
    bl_label = "Render Reference"
    task = "reference_task"

    def prepare(self, context):
        inputs = scene_inputs(context, need_runs=False)
        spp = context.scene.aolab.reference_samples
        cached = find_reference(inputs, spp=spp)
        if cached is not None:
            return {**inputs, "result": {"folder": str(cached), "cached": True}}
        blend, tmpdir = save_copy(context)
        return {**inputs, "spp": spp, "blend": blend, "tmpdir": tmpdir}

    def finish(self, context, result):
        session = context.window_manager.aolab
        session.reference_folder = result["folder"]
        how = "found in the cache" if result.get("cached") else "rendered"
        return f"Reference {how}: {result['folder']}"


class AOLAB_OT_compare(_JobOperator, bpy.types.Operator):
    """Score the ticked methods against the cached reference: MAE, SSIM and time in the
    panel, signed error maps as images"""
    bl_idname = "aolab.compare"
    bl_label = "Compare"
    task = "compare_task"

    def prepare(self, context):
        return reference_inputs(context)

    def finish(self, context, result):
        _store_results(context, result, "Compare", self._plan["size"])
        return f"Compared {len(result['runs'])} methods; {_lowest_mae(result)}"


class AOLAB_OT_quick_compare(_JobOperator, bpy.types.Operator):
    """Score the ticked methods in seconds against a quick reference: rtao at the Quick Rays
    against the scene's triangles (exported with its G-buffer, cached), its noise stated
    beside the scores. Compare, against the Cycles reference, has the final word"""
    bl_idname = "aolab.quick_compare"
    bl_label = "Quick Compare"
    task = "quick_compare_task"

    def prepare(self, context):
        return _quick_plan(context, scene_inputs(context))

    def finish(self, context, result):
        _store_results(context, result, "Quick Compare", self._plan["size"])
        q = result["reference_info"]
        warning = f" ({q['warning']})" if q.get("warning") else ""
        return f"Quick Compare against {q['label']} (noise {q['noise']:.4f}): " \
               f"{_lowest_mae(result)}{warning}"


class AOLAB_OT_advise(_JobOperator, bpy.types.Operator):
    """Which method for this scene? Every method's presets (tuned ones included), timed and
    scored against the cached Cycles reference, else the quick reference: this scene's
    accuracy-against-time front, and the best configuration within the Budget"""
    bl_idname = "aolab.advise"
    bl_label = "Advise"
    task = "advise_task"

    def prepare(self, context):
        inputs = scene_inputs(context, need_runs=False)
        cycles = find_reference(inputs, spp=context.scene.aolab.reference_samples)
        if cycles is not None:
            return {**inputs, "cycles": str(cycles)}
        return _quick_plan(context, inputs)

    def finish(self, context, result):
        session = context.window_manager.aolab
        advice = result["advice"]
        session.advice_json = json.dumps(advice)
        session.advice_scene = context.scene.name
        session.advice_size = f"{advice['width']}x{advice['height']}"
        name = images.image_name(images.ADVICE)
        images.set_image(name, result["image"][..., :3])
        images.set_preview(name, result["image"])
        return f"Advise: {len(advice['trials'])} configurations against " \
               f"{advice['reference']['label']} in {advice['seconds']:.1f} s"


class AOLAB_OT_apply_advice(bpy.types.Operator):
    """Tick this method and apply its preset: Preview and Live then show the advised
    configuration"""
    bl_idname = "aolab.apply_advice"
    bl_label = "Apply"
    bl_options = {"REGISTER", "UNDO", "INTERNAL"}

    # F821 below: pyflakes reads the annotation's string as a forward reference to a type.
    method: bpy.props.StringProperty(name="Method")  # noqa: F821
    preset: bpy.props.StringProperty(name="Preset")  # noqa: F821

    def execute(self, context):
        scene = context.scene
        if not library.available() or self.method not in scene.aolab.methods:
            self.report({"ERROR"}, f"no method {self.method!r} in this AO Lab")
            return {"CANCELLED"}
        try:
            names = library.presets.names(self.method)
        except ValueError as e:
            names, problem = [], str(e)
        else:
            problem = "run Advise again"
        if self.preset not in names:
            self.report({"ERROR"}, f"{self.method} has no preset {self.preset!r} in its menu "
                                   f"now: {problem}")
            return {"CANCELLED"}
        group = properties.method_group(scene, self.method)
        group.use_method = True
        group.preset = self.preset
        properties.apply_preset(group, context)   # also when the menu showed it already
        self.report({"INFO"}, f"{self.method} at {self.preset}: ticked, for Preview and Live")
        return {"FINISHED"}


class AOLAB_OT_write_report(_JobOperator, bpy.types.Operator):
    """Run the comparison study on this scene's reference and write its HTML report"""
    bl_idname = "aolab.write_report"
    bl_label = "Write HTML Report"
    task = "report_task"

    def prepare(self, context):
        inputs = reference_inputs(context)
        out = context.scene.aolab.report_dir
        if out.startswith("//") and not bpy.data.filepath:
            out = os.path.join(tempfile.gettempdir(), "aolab_report",
                               bpy.path.clean_name(context.scene.name))
        out = bpy.path.abspath(out)
        problem = folder_problem(out, "the Report Folder")
        if problem:
            raise UserError(problem)
        return {**inputs, "out": out, "methods": [r["method"] for r in inputs["runs"]]}

    def finish(self, context, result):
        context.window_manager.aolab.report_path = result["report"]
        return f"Report written: {result['report']}"


class AOLAB_OT_cancel(bpy.types.Operator):
    """Cancel the running AO Lab job (like Esc)"""
    bl_idname = "aolab.cancel"
    bl_label = "Cancel"
    bl_options = {"INTERNAL"}

    @classmethod
    def poll(cls, context):
        return context.window_manager.aolab.busy

    def execute(self, context):
        context.window_manager.aolab.cancel_requested = True
        return {"FINISHED"}


class AOLAB_OT_show_image(bpy.types.Operator):
    """Show this result in an Image Editor (the screen's, or a new window)"""
    bl_idname = "aolab.show_image"
    bl_label = "Show Image"
    bl_options = {"INTERNAL"}

    # F821 below: pyflakes reads the annotation's string as a forward reference to a type.
    image: bpy.props.StringProperty(name="Image")  # noqa: F821

    def execute(self, context):
        problem = images.show(context, self.image)
        if problem:
            self.report({"ERROR"}, problem)
            return {"CANCELLED"}
        return {"FINISHED"}


class AOLAB_OT_open_report(bpy.types.Operator):
    """Open the written HTML report in the web browser"""
    bl_idname = "aolab.open_report"
    bl_label = "Open Report"
    bl_options = {"INTERNAL"}

    @classmethod
    def poll(cls, context):
        return bool(context.window_manager.aolab.report_path)

    def execute(self, context):
        bpy.ops.wm.url_open(url=Path(context.window_manager.aolab.report_path).as_uri())
        return {"FINISHED"}


CLASSES = (AOLAB_OT_preview, AOLAB_OT_render_reference, AOLAB_OT_compare,
           AOLAB_OT_quick_compare, AOLAB_OT_advise, AOLAB_OT_apply_advice,
           AOLAB_OT_write_report, AOLAB_OT_cancel, AOLAB_OT_show_image, AOLAB_OT_open_report)
