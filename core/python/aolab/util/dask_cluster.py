"""What every command that runs on a Dask cluster shares (``aolab reference``, ``tune`` and
``compare`` with ``--workers N`` / ``--scheduler ADDRESS``; docs/scale_out.md): the
connection, the cluster's size, waiting for a batch of jobs with Ctrl-C, and a worker
process's cache of the scenes its jobs read. Debian's python3-distributed is imported only
when a cluster is asked for.
"""

from __future__ import annotations

import logging
import signal
import time

#: A worker process's loaded scenes: key -> whatever the loader returned. Jobs of one study
#: run on the same scenes again and again, and reading a scene's EXR files costs more than
#: scoring a configuration on it.
_WORKER_SCENES: dict = {}


def connect(scheduler: str | None, workers: int):
    """(client, cluster): a client of the scheduler at ``scheduler``, or of a new local cluster
    of ``workers`` single-threaded worker processes on the loopback interface (Blender and the
    timed runs use every core of the machine themselves). A scheduler that does not answer
    is a ValueError naming ``--scheduler``."""
    from distributed import Client, LocalCluster
    if scheduler:
        try:
            return Client(scheduler, timeout="20s"), None
        except (OSError, TimeoutError) as e:
            raise ValueError(
                f"--scheduler {scheduler}: no Dask scheduler answers there ({e}); start one with "
                "`dask scheduler` and workers with `dask worker ADDRESS` (docs/scale_out.md)") \
                from None
    # Ctrl-C at a terminal reaches the whole process group. The workers start with SIGINT
    # ignored (a disposition a new process keeps, and Python then installs no handler), so
    # that only this process answers it, by stopping the jobs through the cluster.
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               host="127.0.0.1",
                               # its HTTP server on a free loopback port: another cluster on
                               # this machine may hold the default 8787
                               dashboard_address="127.0.0.1:0",
                               # the workers' own log stays quiet: a job's error reaches
                               # the client as its exception, and Debian 13's workers log
                               # a heartbeat error with a traceback when the cluster closes
                               silence_logs=logging.CRITICAL)
    finally:
        signal.signal(signal.SIGINT, previous)
    return Client(cluster), cluster


def threads(client) -> int:
    """The cluster's worker threads in all (0 while none has joined, or when the scheduler is
    too busy to say: the number only sizes batches and windows)."""
    try:
        return sum(client.nthreads().values())
    except Exception:   # noqa: BLE001 — see above: a size, never a reason to fail
        return 0


def wait_all(client, futures: list, should_stop) -> None:
    """Returns when every future is done (finished, failed or cancelled), polling
    ``should_stop`` (it raises to stop: Ctrl-C), which cancels those not done. A worker lost
    mid-task loses nothing: the scheduler gives its tasks to another worker."""
    try:
        while not all(f.done() for f in futures):
            should_stop()
            time.sleep(0.05)
    except BaseException:
        client.cancel([f for f in futures if not f.done()])
        raise


def worker_scene(key: tuple, load):
    """On a worker: ``load()`` the first time ``key`` is asked for in this process, the kept
    value after. ``key`` names the loader's module and everything that makes the scene (its
    folder on shared storage, the crop, the frame), so two studies never share an entry."""
    if key not in _WORKER_SCENES:
        _WORKER_SCENES[key] = load()
    return _WORKER_SCENES[key]


def crop_key(crop) -> tuple | None:
    """A crop (anything with width and height, or None) as part of a :func:`worker_scene`
    key."""
    return None if crop is None else (crop.width, crop.height)
