"""`aolab reference --workers N` and `--scheduler ADDRESS`: references rendered on a Dask
cluster (Debian's python3-distributed), not a scheduler of AO Lab's own (docs/scale_out.md).

Each job is one plan (a scene, camera and frame) and runs `aolab.cycles.run.render` on a worker,
exactly as `aolab reference` does in one process: Blender in the background, the result
written to a temporary folder in the cache and renamed into place. So the cache keys, the
atomic writes and the resume are the same, and the cache must be storage every worker and
this process see at the same path (a shared file system when workers are on several
machines).

- **A worker lost mid-render** (its machine or process gone): the scheduler gives its job to
  another worker (Dask's own retry of tasks whose worker died); the lost Blender dies with its
  worker (`setpriv --pdeathsig`), and its temporary folder, never visible as an entry, is
  removed by the next render's clean-up on that machine.
- **Submission** is a window of jobs (a few per worker thread), topped up as jobs finish, so
  results and progress start at once and the client's memory stays flat however many frames.
- **Progress** counts jobs done / running / queued.
- **Ctrl-C** (or SIGTERM) sets a cluster-wide event that every running job polls at each line
  Blender prints, so their renders stop and clean up; queued jobs are cancelled. Finished
  entries stay: running the same command again resumes.
"""

from __future__ import annotations

import sys
import time
import uuid
from pathlib import Path

from ..util.dask_cluster import (ClusterSecurity, check_scheduler, client_security_of, connect,
                                 threads)
from . import run
from .blender import Stopped
from .cache import cached_result, remove_stale_temporaries
from .console import interrupted_line, jobs_line, result_line
from .plan import Plan

#: How often a running job asks the cluster whether to stop (s): each ask is a round trip to
#: the scheduler, and Blender prints several lines a second.
STOP_POLL_S = 1.0
#: How often the progress line is redrawn (s).
PROGRESS_S = 0.5
#: Jobs submitted and not yet collected per worker thread of the cluster: enough that a worker
#: finishing a job finds the next one queued, and that cache hits, which return at once, do not
#: leave the workers waiting for the client; few enough that the client holds a bounded
#: number, whatever the number of frames.
WINDOW_PER_THREAD = 4
#: The smallest window: jobs queue for a remote cluster's workers before they have joined.
MIN_WINDOW = 8
#: How often the window follows the cluster's number of worker threads (s).
THREADS_POLL_S = 5.0


def render_job(plan: Plan, cache: str, force: bool, stop_event: str) -> dict:
    """One plan on a worker: run.render, stopping when the client sets ``stop_event``."""
    from distributed import Client, Event, get_worker
    import socket
    t0 = time.perf_counter()
    hit = None if force else cached_result(Path(cache), plan)
    if hit is not None:   # at once: no client, no connection to the scheduler for a resume
        return {"folder": str(hit), "cached": True, "seconds": time.perf_counter() - t0,
                "worker": socket.gethostname()}
    last = [0.0, False]
    # A client of the job's own, closed when the job ends. The worker's shared client
    # (Event's default) is left to the worker process's exit, and when an interrupt stops
    # the cluster, Debian 13's distributed then prints "IOLoop is closed" from its __del__.
    worker = get_worker()
    with Client(worker.scheduler.address, set_as_default=False,
                security=client_security_of(worker)) as client:
        event = Event(stop_event, client=client)
        if event.is_set():   # started after Ctrl-C (queued on this worker): no Blender at all
            raise Stopped(f"{plan.scene.name}: stopped")

        def should_stop() -> bool:
            now = time.monotonic()
            if now - last[0] >= STOP_POLL_S:
                last[0], last[1] = now, event.is_set()
            return last[1]

        folder, cached = run.render(plan, Path(cache), force=force, progress=False,
                                    should_stop=should_stop)
    return {"folder": str(folder), "cached": cached, "seconds": time.perf_counter() - t0,
            "worker": socket.gethostname()}


def window(n_threads: int) -> int:
    """How many jobs are submitted and not yet collected at most, for a cluster of ``n_threads``
    worker threads in all."""
    return max(MIN_WINDOW, WINDOW_PER_THREAD * n_threads)


def run_plans(plans: list[Plan], delivery: run.Delivery, *, scheduler: str | None = None,
              workers: int = 1, security: ClusterSecurity | None = None) -> int:
    """The plans as jobs on the cluster at ``scheduler`` (None: a local one of ``workers``),
    a window of them at a time (``window``); their files copied to ``delivery.out`` as they
    finish. The exit status."""
    if scheduler is not None:   # a bad address or TLS file is refused before the cache is made
        check_scheduler(scheduler, security, warn=False)   # connect() warns
    cache = delivery.cache_folder().resolve()
    cache.mkdir(parents=True, exist_ok=True)
    client, cluster = connect(scheduler, workers, security)
    jobs = Jobs(client, plans, delivery, cache)
    with run.terminate_as_interrupt():   # `kill` stops the jobs like Ctrl-C
        try:
            jobs.run_all(quiet=delivery.quiet or not sys.stderr.isatty())
        except KeyboardInterrupt:
            jobs.stop_all()
            print("\n" + interrupted_line(jobs.done, plans, cache,
                                          "the running renders are stopped; "),
                  file=sys.stderr)
            return 130
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
            remove_stale_temporaries(cache)
    return 0


class Jobs:
    """The plans of one run_plans on the cluster: submitted a window at a time, collected as
    they finish (their files delivered, their lines printed), stopped together on Ctrl-C."""

    def __init__(self, client, plans: list[Plan], delivery: run.Delivery, cache: Path):
        from distributed import Event, as_completed
        self.client, self.plans, self.delivery, self.cache = client, plans, delivery, cache
        self.several = run.several_scenes(plans)
        self.stop = Event(f"aolab-stop-{uuid.uuid4().hex}", client=client)
        # Jobs are submitted as earlier ones are collected, never all at once: submitting
        # costs the client a few milliseconds and its memory per job, so 100000 frames
        # submitted up front meant minutes of silence before the first result and a client
        # that only grew.
        self.todo = iter(plans)
        self.in_flight = {}   # future -> plan: submitted, not yet collected
        self.finished = as_completed(loop=client.loop)
        self.done = 0

    def run_all(self, quiet: bool) -> None:
        """Submits, collects and shows progress until every plan is collected."""
        last = sized = -float("inf")
        size = MIN_WINDOW
        while True:
            now = time.monotonic()
            if now - sized >= THREADS_POLL_S:   # workers join and leave a remote cluster
                size, sized = window(threads(self.client)), now
            self.top_up(size)
            if not self.in_flight:
                break
            self.collect()
            now = time.monotonic()
            if not quiet and now - last >= PROGRESS_S:
                print(jobs_line(self.plans, self.done, _running(self.client, self.in_flight)),
                      end="", file=sys.stderr, flush=True)
                last = now
            if not self.finished.has_ready():
                time.sleep(0.05)
        if not quiet:
            print(file=sys.stderr)

    def top_up(self, size: int) -> None:
        """Submits plans until ``size`` are in flight or none is left."""
        while len(self.in_flight) < size and (plan := next(self.todo, None)) is not None:
            # pure=False: a key per submission, so that a second run re-submits; the cache
            # makes a finished job return at once.
            f = self.client.submit(render_job, plan, str(self.cache), self.delivery.force,
                                   self.stop.name, pure=False,
                                   key=f"aolab-reference-{plan.key()}-{uuid.uuid4().hex[:8]}")
            self.in_flight[f] = plan
            self.finished.add(f)

    def collect(self) -> None:
        """The jobs finished since the last call: delivered, counted and printed."""
        for f in self.finished.next_batch(block=False):
            plan = self.in_flight[f]
            result = f.result()   # a job's error (a ReferenceError) is the command's
            folder = Path(result["folder"])
            self.delivery.deliver(plan, folder, self.several)
            # Done once copied, before its line: a job interrupted earlier is still in
            # flight, and counted there if it finished.
            del self.in_flight[f]
            self.done += 1
            how = "cached" if result["cached"] else \
                f"rendered in {result['seconds']:.1f} s on {result['worker']}"
            print(result_line(plan, folder, how, self.delivery.out), flush=True)

    def stop_all(self) -> None:
        """On Ctrl-C: the running jobs stopped (their Blender killed), the queued cancelled."""
        self.stop.set()
        # Jobs that finished but were not collected yet are done all the same.
        self.done += sum(1 for f in self.in_flight if f.status == "finished")
        # Wait first, cancel after: a cancelled job is no longer the scheduler's to report
        # as running, though its thread goes on until its Blender is killed; closing the
        # cluster then left that Blender to its worker's exit (Debian 13's distributed
        # returns from close() before its worker processes have ended).
        _wait_for_stops(self.client, self.in_flight)
        self.client.cancel(list(self.in_flight))


def _running(client, pending: dict) -> int:
    """How many of the pending jobs a worker is running now."""
    keys = {f.key for f in pending}
    try:
        processing = client.processing()
    except Exception:   # the scheduler busy or gone: the count is only a display
        return 0
    return sum(1 for tasks in processing.values() for k in tasks if k in keys)


def _wait_for_stops(client, futures: dict, timeout_s: float = 30.0) -> None:
    """Gives the running jobs time to kill their Blender and remove their temporary folders
    (they poll the stop event every STOP_POLL_S; a job that starts after it is set stops at
    once): until none of ``futures`` is running, before they are cancelled."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline and _running(client, futures):
        time.sleep(0.2)
