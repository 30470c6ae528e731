"""Inside Blender: the `mesh` export of the scene whose build script follows `--`
(tests/data/mesh_scene.py). Exports it from a scene dressed as a user's, then compares:
- the user's scene before and after a successful export and a failed one (every setting the
  export changes to evaluate as for render: modifiers, levels, hide flags, eye icons...);
- the exported objects with what Blender evaluates for a real render: a minimal render engine
  registered here receives the render-mode depsgraph (as Cycles does) and lists each
  instance's triangle count and world-space vertex sum.
Prints one JSON line `RESULT {...}`."""
import json
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import diff, scene_from_argv, scene_state, use_checkout  # noqa: E402

use_checkout()
import bpy  # noqa: E402

from aolab_blender.export import mesh, reference  # noqa: E402
from aolab_blender.export.scene_record import Cancelled  # noqa: E402

scene = scene_from_argv(dressed=True)
out_dir = tempfile.mkdtemp(prefix="aolab-mesh-")
results = {}


def attempt(label, call):
    before = scene_state(scene)
    try:
        value = call()
        outcome = "ok"
    except Cancelled:
        value, outcome = None, "cancelled"
    except Exception as e:
        value, outcome = None, f"failed: {type(e).__name__}: {e}"
    results[label] = {"outcome": outcome, "diff": diff(before, scene_state(scene))}
    return value


stages = []
info = attempt("export", lambda: mesh.export_mesh(
    scene, os.path.join(out_dir, "scene.mesh"), report=stages.append))
results["stages"] = stages
results["info"] = {k: info[k] for k in ("objects", "skipped", "vertices", "triangles",
                                        "scene_hash")}
attempt("failed", lambda: mesh.export_mesh(scene, "/proc/aolab-cannot-write-here/x.mesh",
                                                  report=lambda s: None))
sidecar = attempt("reference_with_mesh", lambda: reference.export_reference(
    scene, os.path.join(out_dir, "reference.exr"), radius=0.5, spp=1,
    passes=["depth", "mesh"], report=lambda s: None))
results["sidecar"] = {k: sidecar[k] for k in ("passes", "mesh_file", "scene_hash")}
with open(os.path.join(out_dir, "reference.mesh.json")) as f:
    results["reference_mesh_hash"] = json.load(f)["scene_hash"]
reported = []
attempt("cancel_mesh", lambda: reference.export_reference(
    scene, os.path.join(out_dir, "cancelled.exr"), radius=0.5, spp=1, passes=["depth", "mesh"],
    report=reported.append, cancel=lambda: reported[-1:] == ["reference"]))
results["cancel_mesh"]["reported"] = reported
results["cancel_mesh"]["left"] = sorted(os.listdir(out_dir))

rendered = []


class RenderDepsgraphProbe(bpy.types.RenderEngine):
    """Lists the surfaces of the depsgraph Blender evaluates for a render."""
    bl_idname = "AOLAB_RENDER_DEPSGRAPH_PROBE"
    bl_label = "AO Lab render depsgraph probe"

    def render(self, depsgraph):
        for inst in depsgraph.object_instances:
            obj = inst.object
            if not inst.show_self or obj.type != "MESH":
                continue
            co, tri = mesh._object_triangles(obj, inst.matrix_world)
            rendered.append({"name": obj.name, "instance": bool(inst.is_instance),
                             "triangles": len(tri), "vertex_sum": float(np.sum(co, dtype=float)),
                             "visible_shadow": bool(obj.visible_shadow)})


bpy.utils.register_class(RenderDepsgraphProbe)
scene.render.engine = RenderDepsgraphProbe.bl_idname
bpy.ops.render.render()
results["render_depsgraph"] = rendered
exported = np.fromfile(os.path.join(out_dir, "scene.mesh"), np.uint8)
v = np.frombuffer(exported.tobytes(), "<f4", 3 * info["vertices"], 24).reshape(-1, 3)
sums, start = [], 0
for obj in info["objects"]:
    tri_start = 24 + 12 * info["vertices"] + 12 * obj["first_triangle"]
    t = np.frombuffer(exported.tobytes(), "<u4", 3 * obj["triangles"], tri_start).reshape(-1, 3)
    used = np.unique(t)
    sums.append(float(np.sum(v[used], dtype=float)))
results["exported_vertex_sums"] = sums
print("RESULT " + json.dumps(results))
