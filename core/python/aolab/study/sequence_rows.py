"""The rows of a sequence in ``aolab compare``: each frame is a scene of its own (run by
compare.Study); this module adds what makes them a sequence: each row's flicker against the
frame before and the reference's flicker floor, the accumulated row of each configuration on
a sequence with motion (temporal.Accumulation), and the sequence's own rows (means over its
frames) and entry of results.json's scenes."""

import json
from pathlib import Path

import numpy as np

from ..scenes import Scene, manifest
from .results import aggregate, config_row, flicker, flicker_floor, reference_samples, score_row
from .runner import score, time_fields, vs_limit
from .temporal import Accumulation, accumulation_scores

#: How the flicker floor is estimated, as results.json says it.
FLICKER_FLOOR_SOURCE = ("upper estimate from the reference's own values: binomial noise "
                        "v(1 - v)/N per pixel and frame, independent between frames (2-4x "
                        "the noise Cycles' stratified samples have on the stills)")


def accumulated_rows(scene: Scene, compute_settings: dict, settings: list, threads: int,
                     temporal: Accumulation, run):
    """Yields each configuration of a group accumulated: its output of this frame (``run``'s,
    a runner.Run) blended into the history of that output, scored like any output; its time
    the method's and the blur's, as its single-frame row's, plus the step's
    (Accumulation.begin_frame). An RGB output is not accumulated."""
    accumulated: dict[bool, tuple] = {}
    for s in settings:
        blur, out = run.blurred(s.blur), run.output(s.blur)
        row = config_row(scene, run.method, s, threads, temporal, True,
                         runs=len(run.times), **time_fields("method", run.times),
                         **time_fields("blur", out.blur_times),
                         **time_fields("accumulate", temporal.times))
        row["total_ms"] = (row["method_ms"] + (row.get("blur_ms") or 0.0)
                           + row["accumulate_ms"])
        if out.scores is None:
            row["note"] = "RGB output: not accumulated (the step takes 1-channel AO)"
            yield row
            continue
        if blur not in accumulated:
            key = (run.method, json.dumps(compute_settings, sort_keys=True, default=str), blur)
            step = temporal.step(key, out.ao, scene.g, threads)
            accumulated[blur] = (step, score(step, scene), vs_limit(step, scene))
        out, got, limit = accumulated[blur]
        score_row(scene, row, out, got)
        row["occluded_mae_vs_limit"] = limit
        yield row


def set_flicker(previous: Scene, scene: Scene, rows: list[dict]) -> float | None:
    """Sets the flicker of every row of ``scene`` among ``rows`` scored in both frames
    (against ``previous``, whose kept images are then freed) and returns the reference's
    flicker floor for the pair."""
    valid_prev, valid = previous.regions["all"], scene.regions["all"]
    for r in rows:
        if r["scene"] != scene.name:
            continue
        kept = (r["kind"], r["method"], r["label"])
        if kept in previous.outputs and kept in scene.outputs:
            r["flicker"] = flicker(previous.outputs[kept], scene.outputs[kept],
                                   previous.reference, scene.reference, valid_prev, valid)
    previous.outputs = None     # only the frame before is needed: free its images
    return flicker_floor(previous.reference, scene.reference, valid_prev, valid,
                         min(reference_samples(previous), reference_samples(scene)))


def sequence_info(folder: Path, frames: list[int], names: list[str], first: dict, last: Scene,
                  floors: list) -> dict:
    """The sequence's entry of results.json's scenes: its frames (``names``: their scenes),
    size and R (``first``: its first frame's entry), title, samples (``last``: its last
    frame) and the flicker floor over its pairs (``floors``: set_flicker's, None where
    unknown)."""
    floor = [f for f in floors if f is not None]
    return {
        "folder": str(folder), "sequence": True, "frames": frames, "frame_scenes": names,
        "width": first["width"], "height": first["height"], "radius": first["radius"],
        "title": manifest(folder).get("title", folder.name), "samples": reference_samples(last),
        "flicker_floor": {"value": float(np.mean(floor)), "pairs": floors, "estimated": True,
                          "source": FLICKER_FLOOR_SOURCE} if floor else None}


def sequence_means(rows: list[dict], name: str, names: list[str], frames: list[int],
                   info: dict, temporal: Accumulation | None = None) -> list[dict]:
    """The sequence ``name``'s rows: each configuration's means over its frames (``names``)
    among ``rows``, the flicker over its pairs; with ``temporal`` (a sequence with motion)
    also the accumulation's scores in ``info`` (the sequence's entry, sequence_info)."""
    mine = [r for r in rows if r.get("sequence") == name]
    means = aggregate(mine, names, name, unit="frame")
    if temporal is not None:
        info["accumulation"] = accumulation_scores(mine, means, frames, temporal)
    for r in means:
        r["sequence"] = name
    return means
