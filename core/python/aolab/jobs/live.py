"""Live's compute, off Blender's main thread (no bpy).

The add-on's live.py decides on the main thread what to compute (a plan: the cached G-buffer's
EXR, R, threads and the latest runs of the methods that changed) and shows the results; a
LiveWorker computes each plan in a runner.Job, one at a time, and puts every result (or
error) into its `results` queue, which the main thread's timer empties:

- a run whose method changed before it started is skipped, and one that changes while it
  computes is cancelled (`cancel`, through its aolab.Progress): both come back marked
  `cancelled`, so the main thread drops them;
- the G-buffer is loaded from the cache's EXR once per file version and kept in memory;
- a converging run (run["frames"] > 1) blends each frame into its history (`accumulate`:
  aolab.accumulate as a running mean, zero motion, as the G-buffer does not move).
"""

from __future__ import annotations

import queue
import threading
import time
from pathlib import Path
from typing import Callable

import numpy as np

import aolab

from .runner import Job

#: The step's settings for a G-buffer that does not move: alpha 0 makes it the running mean
#: of the frames (docs/temporal.md), and with nothing moving no clamp is needed (it would
#: only hold the mean to each noisy frame's neighbourhood).
ACCUMULATE = {"alpha": 0.0, "clamp": "off"}


class GBufferCache:
    """One G-buffer at a time, loaded from its EXR once (a new render of the file reloads)."""

    def __init__(self):
        self._lock = threading.Lock()
        self._entry: dict = {}   # {"key": (path, mtime_ns), "g": aolab.GBuffer}

    def load(self, path: str) -> tuple:
        """(the G-buffer of `path`, the seconds its loading took: 0 when it was kept)."""
        key = (path, Path(path).stat().st_mtime_ns)
        with self._lock:
            if self._entry.get("key") == key:
                return self._entry["g"], 0.0
            t0 = time.perf_counter()
            g = aolab.load_gbuffer(path)
            g.reference = None   # not scored: the G-buffer's AO may be 1 sample
            self._entry = {"key": key, "g": g}
            return g, time.perf_counter() - t0

    def clear(self) -> None:
        with self._lock:
            self._entry = {}


def accumulate(ao, g, run: dict, threads: int):
    """Frame run["frame"] blended into the run's history (one per channel of an RGB result),
    with zero motion: the G-buffer does not move. A history is touched by one worker at a
    time (one runs at once), and a restart makes new ones."""
    channels = [ao] if ao.ndim == 2 else [np.ascontiguousarray(ao[..., c])
                                          for c in range(ao.shape[2])]
    histories = run["histories"]
    while len(histories) < len(channels):
        histories.append(aolab.TemporalHistory())
    motion = np.zeros(ao.shape[:2] + (2,), np.float32)
    # max_history up to the step's own bound (its settings table): a running mean throughout
    bound = next(int(s["max"]) for s in aolab.accumulate_settings() if s["name"] == "max_history")
    settings = {**ACCUMULATE, "max_history": min(run["frames"], bound)}
    out = [aolab.accumulate(c, g, motion, h, threads=threads, **settings)[0]
           for c, h in zip(channels, histories)]
    return out[0] if ao.ndim == 2 else np.stack(out, axis=-1)


def _error_text(e: Exception) -> str:
    return str(e) if isinstance(e, ValueError) else f"{type(e).__name__}: {e}"


class LiveWorker:
    """Live's computes, one plan at a time in a runner.Job; results come back in `results`.

    `is_current(method, generation)` says whether a run is still the latest of its method
    (read by the worker: plain Python data, safe under the GIL); `convert(ao)`, if given, is
    run on each result in the worker too (the add-on's conversion to Blender's pixels, so
    that the main thread only copies)."""

    def __init__(self, is_current: Callable[[str, int], bool],
                 convert: Callable | None = None):
        self.results: queue.Queue = queue.Queue()
        self.job: Job | None = None
        self.gbuffers = GBufferCache()
        self._is_current = is_current
        self._convert = convert
        self._computing: tuple | None = None   # (method, aolab.Progress) of the running run

    # -- main thread --
    def start(self, plan: dict) -> None:
        """Computes `plan` ({exr, radius, threads, size, scene, snapshot_s, runs}) in a new
        Job; the previous one must have ended (busy() False)."""
        self.job = Job(self._compute, plan, name="aolab-live")

    def busy(self) -> bool:
        """Whether a plan is computing. A Job that ended is forgotten here, after its last
        result was put: read this before emptying `results`, and none is missed."""
        if self.job is not None and self.job.done:
            self.job = None
        return self.job is not None

    def cancel(self, methods) -> None:
        """A compute of a method of `methods` is stale: stopped, so that the latest values
        start sooner (a slow method would otherwise finish a result nobody sees)."""
        computing = self._computing
        if computing is not None and computing[0] in methods:
            computing[1].cancel()

    def pending(self) -> bool:
        """Whether a compute runs or a result waits to be shown."""
        return (self.job is not None and not self.job.done) or not self.results.empty()

    def close(self, timeout: float) -> None:
        """Waits up to `timeout` s for the running Job (cancel its run first) and lets the
        G-buffer go."""
        if self.job is not None:
            self.job.wait(timeout)
        self.job = None
        self.gbuffers.clear()

    # -- the worker thread --
    def _compute(self, job: Job, plan: dict) -> None:
        """Each run of the plan on its G-buffer; every result (or error) put into `results`.
        Frame 0 of a converging run is shown as computed (aolab.accumulate returns a first
        frame bit for bit) and its history made after it is put, so a change shows no
        later."""
        for run in plan["runs"]:
            item = {**run, "scene": plan["scene"], "size": plan["size"], "exr": plan["exr"],
                    "radius": plan["radius"], "threads": plan["threads"], "ao": None,
                    "rgba": None, "snapshot_s": plan["snapshot_s"], "compute_s": 0.0,
                    "rgba_s": 0.0, "load_s": 0.0, "accumulate_s": 0.0, "error": None,
                    "cancelled": False}
            if not self._is_current(run["method"], run["generation"]):
                item["cancelled"] = True
                self.results.put(item)
                continue
            first, g = self._run(item, plan)
            self.results.put(item)
            if first is not None:
                self._first_history(item, first, g, plan["threads"])

    def _run(self, item: dict, plan: dict):
        """Fills `item` with the run's result, times, error or cancellation. Returns frame 0
        of a converging run (its history is made after the item is shown; else None) and the
        G-buffer."""
        progress = aolab.Progress()
        self._computing = (item["method"], progress)
        first = g = None
        try:
            g, item["load_s"] = self.gbuffers.load(plan["exr"])
            converging = item["frames"] > 1
            item["started_at"] = t0 = time.perf_counter()
            ao = aolab.compute(
                item["method"], g, radius=plan["radius"], threads=plan["threads"],
                blur=item["blur"], progress=progress,
                frame=item["frame"] if converging else None, **item["settings"])
            t1 = time.perf_counter()
            item["compute_s"] = t1 - t0
            if converging and item["frame"] == 0:
                first = ao
            item["ao"] = accumulate(ao, g, item, plan["threads"]) \
                if converging and first is None else ao
            item["accumulate_s"] = time.perf_counter() - t1
            t1 = time.perf_counter()
            item["rgba"] = self._convert(item["ao"]) if self._convert else None
            item["finished_at"] = time.perf_counter()
            item["rgba_s"] = item["finished_at"] - t1
        except aolab.Cancelled:
            item["cancelled"] = True
        except Exception as e:  # noqa: BLE001 - shown in the panel, never a traceback
            item["error"] = _error_text(e)
        finally:
            self._computing = None
        return first, g

    def _first_history(self, item: dict, first, g, threads: int) -> None:
        """The history of a converging run, from its frame 0 (already shown); an error is
        put as a result of its own, and no frame follows it."""
        try:
            accumulate(first, g, item, threads)
        except Exception as e:  # noqa: BLE001 - as in _run
            self.results.put({**item, "ao": None, "rgba": None, "error": f"accumulate: {e}"})
