"""Inside Blender: the user's scene is unchanged — every setting the bridge touches, compared
before and after — after an export (also with the `mesh` pass), a failed render and a
cancelled one (at every stage), and for a scene without a world. Also records which passes
each render had enabled.
Prints one JSON line `RESULT {...}`."""
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import diff, scene_from_argv, scene_state, use_checkout  # noqa: E402

use_checkout()
import bpy  # noqa: E402

from aolab_blender.export import reference  # noqa: E402
from aolab_blender.export.scene_record import Cancelled  # noqa: E402

scene = scene_from_argv(dressed=True)

enabled_per_render = []


def record_passes(*_):
    layer = bpy.context.view_layer
    enabled_per_render.append(sorted(p for p in layer.bl_rna.properties.keys()
                                     if p.startswith("use_pass_") and getattr(layer, p)))


bpy.app.handlers.render_pre.append(record_passes)
before = scene_state(scene)
results = {}
out_dir = tempfile.mkdtemp(prefix="aolab-restore-")


def attempt(label, **kw):
    try:
        reference.export_reference(
            scene, kw.pop("out", os.path.join(out_dir, label + ".exr")), radius=0.5, spp=2,
            passes=kw.pop("passes", ["depth", "normal"]), report=lambda s: None, **kw)
        outcome = "ok"
    except Cancelled:
        outcome = "cancelled"
    except Exception as e:  # a failed render
        outcome = f"failed: {type(e).__name__}"
    results[label] = {"outcome": outcome, "diff": diff(before, scene_state(scene))}


attempt("export")
passes_of_export = list(enabled_per_render)
attempt("export_mesh_pass", passes=["depth", "normal", "mesh"])  # also evaluates as for render
attempt("failed", out="/proc/aolab-cannot-write-here/x.exr")  # before any render
occupied = os.path.join(out_dir, "occupied.exr")
os.makedirs(occupied)  # a folder where the result should go: fails after both renders
attempt("failed_late", out=occupied)
STAGES = ["prepare", "gbuffer", "reference", "merge"]
for stage in STAGES:
    reported = []
    try:
        # cancel() is polled before each stage is reported: cancel at `stage`.
        reference.export_reference(
            scene, os.path.join(out_dir, f"c-{stage}.exr"), radius=0.5, spp=2,
            passes=["depth"], report=reported.append,
            cancel=lambda reported=reported, stage=stage: len(reported) == STAGES.index(stage))
        outcome = "ok"
    except Cancelled:
        outcome = "cancelled"
    results[f"cancel_{stage}"] = {"outcome": outcome, "reported": reported,
                                  "diff": diff(before, scene_state(scene))}

# A user's own render result survives: its slot and active index are untouched.
scene.render.engine = "CYCLES"
scene.cycles.use_denoising = False
scene.cycles.samples = 1
bpy.ops.render.render()
image = next(im for im in bpy.data.images if im.type == "RENDER_RESULT")
before_render = scene_state(scene)
slots_before = [slot.name for slot in image.render_slots], image.render_slots.active_index
reference.export_reference(scene, os.path.join(out_dir, "with_render.exr"), radius=0.5, spp=2,
                           passes=["depth"], report=lambda s: None)
slots_after = [slot.name for slot in image.render_slots], image.render_slots.active_index
results["user_render_result"] = {"outcome": "ok", "diff": diff(before_render, scene_state(scene)),
                                 "slots_before": slots_before, "slots_after": slots_after}

# A scene without a world: the temporary one must be gone afterwards.
scene.world = None
before_no_world = scene_state(scene)
reference.export_reference(scene, os.path.join(out_dir, "noworld.exr"), radius=0.5, spp=2,
                           passes=["depth"], report=lambda s: None)
results["no_world"] = {"outcome": "ok", "diff": diff(before_no_world, scene_state(scene))}
results["passes_of_export"] = passes_of_export
print("RESULT " + json.dumps(results))
