"""Inside Blender (under xvfb-run, for EEVEE): the comparison peers of a user's scene — the
Cycles ladder and EEVEE's GTAO (blender_addon/aolab_blender/export/peers.py) — leave every
setting as it was, after a full render and after cancelling at each stage. Prints `RESULT {...}`
with the outcomes, diffs, the files written and peers.json."""
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import diff, scene_from_argv, scene_state, use_checkout  # noqa: E402

use_checkout()
from aolab_blender.export import peers  # noqa: E402
from aolab_blender.export.scene_record import Cancelled  # noqa: E402

scene = scene_from_argv(dressed=True)
before = scene_state(scene)
out_dir = tempfile.mkdtemp(prefix="aolab-peers-")
results = {}

stages = []
result = peers.render_peers(scene, os.path.join(out_dir, "full"), radius=0.75, ladder=(1, 4),
                            report=stages.append)
results["full"] = {"stages": stages, "diff": diff(before, scene_state(scene)),
                   "files": sorted(os.listdir(os.path.join(out_dir, "full"))), "peers": result}

STAGES = ["prepare", "cycles 1 spp", "cycles 4 spp", "eevee"]
for i, stage in enumerate(STAGES):
    reported = []
    folder = os.path.join(out_dir, f"cancel-{i}")
    try:
        peers.render_peers(scene, folder, radius=0.75, ladder=(1, 4), report=reported.append,
                           cancel=lambda reported=reported, i=i: len(reported) == i)
        outcome = "ok"
    except Cancelled:
        outcome = "cancelled"
    results[f"cancel_{stage}"] = {"outcome": outcome, "reported": reported,
                                  "diff": diff(before, scene_state(scene)),
                                  "peers_json": os.path.exists(os.path.join(folder, "peers.json")),
                                  "leftovers": [f for f in os.listdir(folder) if f.startswith(".")
                                                or f.startswith("aolab-peers-")]}
print("RESULT " + json.dumps(results))
