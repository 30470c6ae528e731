"""Inside Blender: the user's scene is unchanged — every setting the bridge touches, compared
before and after — after an export, a failed render and a cancelled one (at every stage), and
for a scene without a world. Also records which passes each render had enabled.
Prints one JSON line `RESULT {...}`."""
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import diff, run_build_script, scene_state  # noqa: E402

import bpy  # noqa: E402
from aolab_blender import export  # noqa: E402

tiny = sys.argv[sys.argv.index("--") + 1]
run_build_script(tiny)
scene = bpy.context.scene

# A user's scene with deliberately non-default settings everywhere the bridge reaches.
scene.render.engine = "BLENDER_EEVEE"
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
        export.export_reference(scene, kw.pop("out", os.path.join(out_dir, label + ".exr")),
                                radius=0.5, spp=2, passes=kw.pop("passes", ["depth", "normal"]),
                                report=lambda s: None, **kw)
        outcome = "ok"
    except export.Cancelled:
        outcome = "cancelled"
    except Exception as e:  # a failed render
        outcome = f"failed: {type(e).__name__}"
    results[label] = {"outcome": outcome, "diff": diff(before, scene_state(scene))}


attempt("export")
passes_of_export = list(enabled_per_render)
attempt("failed", out="/proc/aolab-cannot-write-here/x.exr")  # before any render
occupied = os.path.join(out_dir, "occupied.exr")
os.makedirs(occupied)  # a folder where the result should go: fails after both renders
attempt("failed_late", out=occupied)
STAGES = ["prepare", "gbuffer", "reference", "merge"]
for stage in STAGES:
    reported = []
    try:
        # cancel() is polled before each stage is reported: cancel at `stage`.
        export.export_reference(scene, os.path.join(out_dir, f"c-{stage}.exr"), radius=0.5, spp=2,
                                passes=["depth"], report=reported.append,
                                cancel=lambda reported=reported, stage=stage:
                                len(reported) == STAGES.index(stage))
        outcome = "ok"
    except export.Cancelled:
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
export.export_reference(scene, os.path.join(out_dir, "with_render.exr"), radius=0.5, spp=2,
                        passes=["depth"], report=lambda s: None)
slots_after = [slot.name for slot in image.render_slots], image.render_slots.active_index
results["user_render_result"] = {"outcome": "ok", "diff": diff(before_render, scene_state(scene)),
                                 "slots_before": slots_before, "slots_after": slots_after}

# A scene without a world: the temporary one must be gone afterwards.
scene.world = None
before_no_world = scene_state(scene)
export.export_reference(scene, os.path.join(out_dir, "noworld.exr"), radius=0.5, spp=2,
                        passes=["depth"], report=lambda s: None)
results["no_world"] = {"outcome": "ok", "diff": diff(before_no_world, scene_state(scene))}
results["passes_of_export"] = passes_of_export
print("RESULT " + json.dumps(results))
