"""The panel's background jobs (no bpy): what Preview, Render Reference, Compare, Quick
Compare, Advise and Write Report run in a runner.Job, off Blender's main thread.

Each task takes the Job (to report progress and check for cancellation) and a plan of plain
Python data the operator read from Blender on the main thread; it returns plain data too,
which the operator turns into images and rows on the main thread. The tasks: preview,
reference, compare, quick compare (the methods against rtao at a few rays:
aolab.study.quick_reference), advise (aolab.study.advise: every preset, the front drawn) and
report.

References are rendered by `aolab reference` in a child /usr/bin/python3 (reference_job.py,
with this aolab package first on its path; not sys.executable, which inside Blender is
whichever python3.11 comes first on PATH, possibly one without numpy: docs/blender_facts.md,
"Blender's Python") on a copy of the user's file, so the user's scene is never changed. Its
cache is content-keyed by the file's bytes; `find_by_content` (aolab.cycles.cache, which the
add-on's inputs.find_reference calls) also finds a render by the scene's content hash (the
add-on's export/scene_record.content_hash, stored in each sidecar), so that a re-saved,
unchanged scene is served from the cache.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np

import aolab

from ..bridge.constants import RESULT_EXR
from ..cycles.blender import package_path
from ..scoring import error_map, metrics_mask, nothing_to_score
from ..study import advise, compare, quick_reference
from .runner import Job, JobError

PYTHON = "/usr/bin/python3"
DRIVER = "aolab.jobs.reference_job"   # run as python3 -P -m DRIVER (-P: not from the cwd)
# Share of the progress bar per stage of a reference render (G-buffer render, AO render).
STAGE_SPAN = {"start": (0.0, 0.02), "prepare": (0.02, 0.03), "gbuffer": (0.03, 0.06),
              "reference": (0.06, 0.97), "merge": (0.97, 0.99), "done": (0.99, 1.0)}


def _child_env() -> dict:
    """The environment of reference_job.py: this aolab package first on its path, so that the
    child (and the Blender it starts) use the same build as the add-on."""
    paths = [package_path()] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep)
                                if p]
    return dict(os.environ, PYTHONPATH=os.pathsep.join(paths))


def render_reference(job: Job, blend: str, *, spp: int, radius: float, size: tuple[int, int],
                     passes: list[str], cache: Path | None,
                     scale: tuple[float, float] = (0.0, 1.0)) -> Path:
    """Renders (or finds in the `aolab reference` cache) the reference of `blend`; returns the
    folder of reference.exr. Progress is mapped into `scale` of the job's bar."""
    cmd = [PYTHON, "-P", "-m", DRIVER, "--scene", blend, "--spp", str(spp),
           "--radius", repr(float(radius)), "--resolution", f"{size[0]}x{size[1]}",
           "--passes", ",".join(passes)]
    if cache is not None:
        cmd += ["--cache", str(cache)]
    lo, hi = scale
    state = {"result": None, "error": None, "tail": []}

    def on_line(line: str) -> None:
        state["tail"] = (state["tail"] + [line])[-30:]
        kind, _, rest = line.partition(" ")
        if kind == "AOLAB_PROGRESS":
            done, total, stage = rest.split(" ", 2)
            a, b = STAGE_SPAN.get(stage, (0.0, 0.0))
            a, b = lo + (hi - lo) * a, lo + (hi - lo) * b
            if stage == "reference":
                job.report_samples(a, b, int(done), int(total),
                                   f"reference: {done}/{total} samples")
            else:
                job.report(a, f"reference: {stage}")
        elif kind == "AOLAB_RESULT":
            state["result"] = json.loads(rest)
        elif kind == "AOLAB_ERROR":
            state["error"] = rest

    job.report(lo, "reference: starting Blender")
    rc = job.run_process(cmd, on_line, env=_child_env())
    job.check()
    if state["error"]:
        raise JobError(state["error"])
    if rc != 0 or state["result"] is None:
        raise JobError("the reference render failed:\n" + "\n".join(state["tail"]))
    return Path(state["result"]["folder"])


def run_methods(job: Job, g, runs: list[dict], *, radius: float, threads: int,
                scale: tuple[float, float] = (0.0, 1.0)) -> list[dict]:
    """Computes each run ({method, settings, blur}) on G-buffer `g`, timed; with a reference in
    g, also its metrics and signed error map, on the command line's scored pixels. Returns
    dicts with ao, seconds, metrics, error_rgb. aolab.compute releases the GIL."""
    out = []
    lo, hi = scale
    mask = metrics_mask(g)
    for i, run in enumerate(runs):
        job.check()
        job.report(lo + (hi - lo) * i / len(runs), f"computing {run['method']}")
        t0 = time.perf_counter()
        ao = aolab.compute(run["method"], g, radius=radius, threads=threads, blur=run["blur"],
                           **run["settings"])
        item = {**run, "ao": ao, "seconds": time.perf_counter() - t0, "metrics": None,
                "error_rgb": None}
        if mask is not None:
            item["metrics"] = dict(aolab.metrics(ao, g.reference, mask))
            item["error_rgb"] = error_map(ao, g.reference, mask)
        out.append(item)
    job.report(hi, "done")
    return out


def preview_task(job: Job, plan: dict) -> dict:
    """The G-buffer (cached, or rendered at 1 sample), then the methods on it."""
    folder = plan.get("cached")
    if folder is None:
        folder = render_reference(job, plan["blend"], spp=1, radius=plan["radius"],
                                  size=plan["size"], passes=plan["passes"], cache=plan["cache"],
                                  scale=(0.0, 0.7))
    g = aolab.load_gbuffer(Path(folder) / RESULT_EXR)
    g.reference = None  # a preview is not scored (the G-buffer's AO may be 1 sample)
    runs = run_methods(job, g, plan["runs"], radius=plan["radius"], threads=plan["threads"],
                       scale=(0.7, 1.0))
    return {"folder": str(folder), "runs": runs, "reference": None}


def reference_task(job: Job, plan: dict) -> dict:
    folder = render_reference(job, plan["blend"], spp=plan["spp"], radius=plan["radius"],
                              size=plan["size"], passes=plan["passes"], cache=plan["cache"])
    return {"folder": str(folder)}


def compare_task(job: Job, plan: dict) -> dict:
    """The methods on the reference's own G-buffer, scored against its AO."""
    job.report(0.0, "loading the reference")
    g = scorable(aolab.load_gbuffer(Path(plan["folder"]) / RESULT_EXR))
    runs = run_methods(job, g, plan["runs"], radius=plan["radius"], threads=plan["threads"])
    return {"folder": plan["folder"], "runs": runs, "reference": g.reference,
            "reference_info": quick_reference.cycles(g).info()}


def report_task(job: Job, plan: dict) -> dict:
    """The comparison study (`aolab compare`, quick sweep) on one scene: the folder of its
    reference.exr, for the chosen methods; writes report.html, results.csv, results.json."""
    job.report(0.05, "running the comparison study")
    out = Path(plan["out"])
    opts = compare.Options(scenes=[str(plan["folder"])], methods=list(plan["methods"]) or None,
                           out=out, threads=plan["threads"], progress=False)
    compare.Study(opts).run()
    return {"report": str(out / "report.html")}


def gbuffer_with_mesh(job: Job, plan: dict, scale: tuple[float, float]) -> Path:
    """The folder of a cached render of the scene with its triangles (plan["cached"]), else
    a 1-sample render with the `mesh` pass of the copy plan["blend"]."""
    if plan.get("cached"):
        return Path(plan["cached"])
    return render_reference(job, plan["blend"], spp=1, radius=plan["radius"], size=plan["size"],
                            passes=plan["passes"], cache=plan["cache"], scale=scale)


def scorable(g):
    """``g``, whose ``reference`` is what it is scored against; a JobError when no pixel can
    be scored. A frame of background alone (an empty scene, a camera facing away) renders
    fine, but leaves nothing to score: said before any method runs, as aolab compare says
    it."""
    problem = nothing_to_score(g)
    if problem:
        raise JobError(f"nothing to compare: {problem}")
    return g


def _quick(job: Job, folder: Path, plan: dict, at: float) -> tuple:
    """The G-buffer of ``folder`` scored against its quick reference (rtao at plan["rays"]),
    and that reference."""
    job.check()
    job.report(at, f"quick reference: rtao {plan['rays']} rays")
    g = aolab.load_gbuffer(Path(folder) / RESULT_EXR)
    if not np.asarray(g.valid_mask(), bool).any():
        scorable(g)   # says the frame has no geometry, before tracing
    ref = quick_reference.quick(g, radius=plan["radius"], rays=plan["rays"],
                                threads=plan["threads"])
    g.reference = ref.ao
    return scorable(g), ref


def quick_compare_task(job: Job, plan: dict) -> dict:
    """The methods scored against the quick reference: rtao at plan["rays"] on the scene's
    G-buffer and triangles (cached, or rendered at 1 sample with the `mesh` pass)."""
    folder = gbuffer_with_mesh(job, plan, (0.0, 0.7))
    g, ref = _quick(job, folder, plan, 0.7)
    runs = run_methods(job, g, plan["runs"], radius=plan["radius"], threads=plan["threads"],
                       scale=(0.8, 1.0))
    return {"folder": str(folder), "runs": runs, "reference": ref.ao,
            "reference_info": ref.info()}


def advise_task(job: Job, plan: dict) -> dict:
    """Advise (aolab.study.advise) on the scene: against the cached Cycles reference
    (plan["cycles"]) when there is one, else the quick reference; the front drawn."""
    if plan.get("cycles"):
        folder = Path(plan["cycles"])
        job.report(0.0, "loading the Cycles reference")
        g = scorable(aolab.load_gbuffer(folder / RESULT_EXR))
        ref = quick_reference.cycles(g)
    else:
        folder = gbuffer_with_mesh(job, plan, (0.0, 0.3))
        g, ref = _quick(job, folder, plan, 0.3)
    lo, hi = 0.35, 0.97

    def step(i: int, n: int, config: dict) -> None:
        job.check()
        job.report(lo + (hi - lo) * i / max(n, 1),
                   f"advise: {config['method']} {'/'.join(config['names'])} ({i + 1}/{n})")

    result = advise.run(g, ref, plan["radius"], name=plan["scene"], threads=plan["threads"],
                        on_step=step)
    job.report(hi, "drawing the front")
    return {"folder": str(folder), "advice": result, "image": advise.plot(result)}
