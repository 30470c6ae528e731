"""The temporal accumulation of a sequence with motion, as `aolab compare` prices it
(docs/comparison.md, "Temporal accumulation"): the per-configuration histories, the step's
time and each frame's disoccluded region (Accumulation), and the sequence's converged and
disoccluded errors (accumulation_scores). The accumulated rows' label is the configuration's
and findings.ACCUMULATED_SUFFIX."""

from __future__ import annotations

import numpy as np

import aolab

from ..scenes import Scene
from .runner import timed

#: The disoccluded region of a frame: scored pixels whose history, after the step, holds
#: fewer frames than this (rejected in this frame or in the DISOCCLUDED_BELOW - 1 before).
DISOCCLUDED_BELOW = 4
#: The key of that region in a frame's Scene.regions (not one of REGIONS: stills lack it).
DISOCCLUDED = "disoccluded"
#: The converged error of a sequence: the mean whole-frame MAE over its frames of index >= this
#: (the 9th on); a sequence at rest, or without such a frame, takes its last frame alone.
CONVERGED_FROM = 8
#: A sequence is at rest when no motion vector on a scored pixel exceeds this (px).
AT_REST_PX = 1e-3


class Accumulation:
    """The temporal accumulation of one sequence with motion (docs/comparison.md, "Temporal
    accumulation"): one aolab.TemporalHistory per configuration output (a method's compute
    settings and its blur switch), empty at the sequence's start, and the step's time and the
    disoccluded region of each frame.

    The step's work depends on the G-buffer, the motion and its settings, never on the AO
    values (which pixels keep which taps follows from depth, normals and motion alone; every
    other read and operation is done whatever the value), so it is timed once per frame, like
    the blur (warm-up + repeat runs, the median), on histories of its own kept in step with
    the configurations' (one per run, fed a constant AO), and that time is added to every
    configuration's. The same lengths give the frame's disoccluded region."""

    def __init__(self, runs: int):
        self.histories: dict[tuple, aolab.TemporalHistory] = {}
        self._timing = [aolab.TemporalHistory() for _ in range(max(1, runs))]
        self.index = -1             # the frame's index in the sequence, 0 first
        self.motion = None          # this frame's motion vectors
        self.times: list[float] = []
        self.largest_motion = 0.0   # px, over the scored pixels of every frame after the first
        self.region_pixels: dict[int, int] = {}   # frame number -> its disoccluded pixels

    def begin_frame(self, scene: Scene, index: int, warmup: int, repeat: int,
                    threads: int) -> None:
        """Times the step on frame ``index`` of the sequence (``scene``) and sets the frame's
        disoccluded region, scene.regions[DISOCCLUDED]."""
        g, valid = scene.g, scene.regions["all"]
        self.index = index
        motion = g.motion
        if motion is None:   # (frame 0 only: the step ignores the motion of the first frame)
            motion = np.zeros((g.height, g.width, 2), np.float32)
        elif index > 0 and valid.any():
            self.largest_motion = max(self.largest_motion,
                                      float(np.max(np.abs(motion[valid]))))
        self.motion = motion
        constant = np.ones((g.height, g.width), np.float32)
        histories = iter(self._timing)
        _, self.times = timed(lambda: aolab.accumulate(constant, g, motion, next(histories),
                                                       threads=threads),
                              warmup, min(repeat, len(self._timing) - warmup))
        length = self._timing[0].length
        scene.regions[DISOCCLUDED] = valid & (np.asarray(length) < DISOCCLUDED_BELOW)
        self.region_pixels[scene.frame] = int(scene.regions[DISOCCLUDED].sum())

    def step(self, key: tuple, ao: np.ndarray, g, threads: int) -> np.ndarray:
        """``ao`` of configuration output ``key`` accumulated into its history."""
        history = self.histories.setdefault(key, aolab.TemporalHistory())
        accumulated, _ = aolab.accumulate(ao, g, self.motion, history, threads=threads)
        return accumulated


def converged_frames(indices: list[int], at_rest: bool) -> list[int]:
    """The frame indices (0 first) whose mean whole-frame MAE is a sequence's converged error:
    those from CONVERGED_FROM on; the last alone for a sequence at rest (its accumulation
    only improves) or without such a frame."""
    later = [i for i in indices if i >= CONVERGED_FROM]
    return later if later and not at_rest else indices[-1:]


def accumulation_scores(frame_rows: list[dict], means: list[dict], frames: list[int],
                        temporal: Accumulation) -> dict:
    """Sets each sequence row's converged error (the mean whole-frame MAE over
    converged_frames) and its disoccluded error (over the frames of index >=
    DISOCCLUDED_BELOW - 1, before which no pixel can have DISOCCLUDED_BELOW frames of
    history: the mean over every region pixel of those frames); returns what
    results.json's scenes.<sequence>.accumulation says of the rules."""
    index = {f: i for i, f in enumerate(frames)}
    at_rest = temporal.largest_motion <= AT_REST_PX
    converged = converged_frames(list(range(len(frames))), at_rest)
    by_config: dict[tuple, dict[int, dict]] = {}
    for r in frame_rows:
        if r.get("frame") is not None and "metrics" in r:
            by_config.setdefault((r["kind"], r["method"], r["label"]), {})[
                index[r["frame"]]] = r
    for r in means:
        got = by_config.get((r["kind"], r["method"], r["label"]), {})
        maes = [got[i]["metrics"]["all"]["mae"] for i in converged if i in got]
        if maes and len(maes) == len(converged):
            r["converged_mae"] = float(np.mean(maes))
        pooled = [(x["disoccluded_mae"], x["disoccluded_count"]) for i, x in got.items()
                  if i >= DISOCCLUDED_BELOW - 1 and x.get("disoccluded_mae") is not None]
        count = sum(c for _, c in pooled)
        if count:
            r["disoccluded_mae"] = float(sum(m * c for m, c in pooled) / count)
            r["disoccluded_count"] = int(count)
    settings = {s["name"]: s["default"] for s in aolab.accumulate_settings()}
    return {"settings": {k: float(f"{v:.6g}") if isinstance(v, float) else v
                         for k, v in settings.items()},
            "disoccluded_below": DISOCCLUDED_BELOW,
            "disoccluded_from_index": DISOCCLUDED_BELOW - 1,
            "converged_from_index": CONVERGED_FROM, "at_rest": at_rest,
            "largest_motion_px": temporal.largest_motion,
            "converged_frames": [frames[i] for i in converged],
            "converged_history": [i + 1 for i in converged],
            "region_pixels": {f: int(x) for f, x in temporal.region_pixels.items()}}
