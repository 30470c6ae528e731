"""The one worker mechanism of the add-on's panel (no bpy): a Job runs a task in a thread.

A Job runs one function in a daemon thread. Blender's main thread (a modal operator's timer,
an operator's execute() waiting in a loop, or Live's timer) polls `progress`, `stage` and
`done`, and reads `result` or `error` once done; `cancel()` sets a flag the task checks and
terminates the child process it may be waiting on. Tasks receive plain Python data prepared
on the main thread and never touch bpy: images and results are made on the main thread
afterwards. The panel's tasks are in tasks.py, Live's compute in live.py.
"""

from __future__ import annotations

import os
import signal
import subprocess
import threading
import time

TERMINATE_GRACE_S = 10.0


class Cancelled(Exception):
    pass


class JobError(Exception):
    """A problem the user can act on; the message says what to do."""


class Job:
    """task(job, *args) run in a daemon thread named `name`."""

    def __init__(self, task, *args, name: str = "aolab-job"):
        self._progress = 0.0
        self._samples = None  # (lo, hi, done, total, t_first, t_last) of a running render
        self.stage = "starting"
        self.result = None
        self.error: Exception | None = None
        self.done = False
        self._cancel = threading.Event()
        self._proc = None
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, args=(task, args), name=name,
                                        daemon=True)
        self._thread.start()

    def _run(self, task, args):
        try:
            self.result = task(self, *args)
        except Exception as e:  # reported on the main thread
            self.error = e
        finally:
            self.done = True

    # -- called by tasks (worker thread) --
    def report(self, progress: float, stage: str) -> None:
        self._progress, self.stage = max(0.0, min(1.0, progress)), stage
        self._samples = None

    def report_samples(self, lo: float, hi: float, done: int, total: int, stage: str) -> None:
        """Cycles prints its sample count rarely (after sample 1, then every few seconds):
        between reports, `progress` moves on at the rate measured so far."""
        now = time.monotonic()
        first = self._samples[4] if self._samples and done > 0 else now
        self.report(lo + (hi - lo) * done / max(total, 1), stage)
        self._samples = (lo, hi, done, total, first, now)

    @property
    def progress(self) -> float:
        s = self._samples
        if s is None or not 0 < s[2] < s[3]:
            return self._progress
        lo, hi, done, total, first, last = s
        per_sample = max(last - first, 1e-3) / done
        estimate = min(done + (time.monotonic() - last) / per_sample, 0.99 * total)
        return lo + (hi - lo) * estimate / total

    def check(self) -> None:
        if self._cancel.is_set():
            raise Cancelled()

    def run_process(self, cmd: list[str], on_line, env: dict | None = None) -> int:
        """Runs cmd, calling on_line(line) for each output line; cancel() terminates it."""
        with self._lock:
            self.check()
            self._proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                          stdin=subprocess.DEVNULL, text=True,
                                          start_new_session=True, env=env)
        try:
            for line in self._proc.stdout:
                on_line(line.rstrip("\n"))
            return self._proc.wait()
        finally:
            with self._lock:
                self._proc = None

    # -- called by the main thread --
    @property
    def cancelled(self) -> bool:
        return self._cancel.is_set()

    def cancel(self) -> None:
        """Asks the task to stop; a child process gets SIGTERM (reference_job.py then kills
        its Blender and removes its temporary folder), SIGKILL to its group after a grace
        period."""
        self._cancel.set()
        with self._lock:
            proc = self._proc
        if proc is not None and proc.poll() is None:
            proc.terminate()
            threading.Thread(target=_kill_later, args=(proc,), daemon=True).start()

    def wait(self, timeout: float | None = None) -> bool:
        self._thread.join(timeout)
        return self.done


def _kill_later(proc) -> None:
    try:
        proc.wait(TERMINATE_GRACE_S)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
