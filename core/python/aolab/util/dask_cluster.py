"""What every command that runs on a Dask cluster shares (``aolab reference``, ``tune`` and
``compare`` with ``--workers N`` / ``--scheduler ADDRESS``; docs/scale_out.md): the
connection, the cluster's size, waiting for a batch of jobs with Ctrl-C, and a worker
process's cache of the scenes its jobs read. Debian's python3-distributed is imported only
when a cluster is asked for.
"""

from __future__ import annotations

import ipaddress
import logging
import signal
import sys
import time
from dataclasses import dataclass
from pathlib import Path

#: A worker process's loaded scenes: key -> whatever the loader returned. Jobs of one study
#: run on the same scenes again and again, and reading a scene's EXR files costs more than
#: scoring a configuration on it.
_WORKER_SCENES: dict = {}


@dataclass(frozen=True)
class ClusterSecurity:
    """How a client meets a remote scheduler (docs/scale_out.md, "Security"): the TLS files
    for a tls:// address (each None: Dask's configuration, e.g.
    DASK_DISTRIBUTED__COMM__TLS__CA_FILE), and ``insecure``, the user's consent to a plain
    tcp:// address beyond this machine."""
    ca_file: str | None = None
    cert: str | None = None
    key: str | None = None
    insecure: bool = False


#: What a plain tcp:// scheduler on the network allows, said where it is refused or allowed.
OPEN_SCHEDULER_RISK = ("a plain tcp:// Dask scheduler accepts any client that reaches its "
                       "port, and a client can run any code on every worker")


def scheme_and_host(address: str) -> tuple[str, str]:
    """(scheme, host) of a Dask address: "tls://10.0.0.5:8786" -> ("tls", "10.0.0.5"); no
    scheme is Dask's default, tcp; "[::1]:8786" -> ("tcp", "::1")."""
    scheme, _, rest = address.rpartition("://")
    host = rest
    if host.startswith("["):                  # [IPv6]:port
        host = host[1:].partition("]")[0]
    elif host.count(":") == 1:                # host:port
        host = host.partition(":")[0]
    return (scheme or "tcp").lower(), host


def is_loopback(host: str) -> bool:
    """Whether ``host`` names this machine's loopback interface (localhost, 127.0.0.0/8, ::1);
    a name is not resolved: only these spellings count."""
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def tls_setting(given: str | None, config_key: str) -> str | None:
    """A TLS file: the option's, else Dask's configuration's (``config_key`` under
    distributed.comm.tls)."""
    if given:
        return given
    import dask
    return dask.config.get(f"distributed.comm.tls.{config_key}", None)


def check_scheduler(scheduler: str, security: ClusterSecurity | None = None):
    """The Security a client of ``scheduler`` needs, or None for plain tcp; a ValueError
    naming the option for an address this refuses: tcp:// beyond the loopback interface
    without ``insecure``, a scheme other than tcp and tls, a tls:// address without a CA,
    certificate or key (in the options or Dask's configuration) or with a file that is not
    there. Allowed with ``insecure``, a tcp:// address on the network prints a warning."""
    security = security or ClusterSecurity()
    scheme, host = scheme_and_host(scheduler)
    if scheme == "tcp":
        if not is_loopback(host):
            if not security.insecure:
                raise ValueError(
                    f"--scheduler {scheduler}: refused: {OPEN_SCHEDULER_RISK}; run the farm "
                    "with TLS (a tls:// address with --tls-ca-file, --tls-cert and --tls-key; "
                    "docs/scale_out.md, \"Security\") or pass --insecure to accept the risk")
            print(f"aolab: warning: --insecure: {scheduler}: {OPEN_SCHEDULER_RISK}; use tls:// "
                  "(docs/scale_out.md, \"Security\")", file=sys.stderr)
        return None
    if scheme != "tls":
        raise ValueError(f"--scheduler {scheduler}: the address must be tls://HOST:PORT (or "
                         f"tcp:// on this machine's loopback interface), not {scheme}://")
    files = {"--tls-ca-file": tls_setting(security.ca_file, "ca-file"),
             "--tls-cert": tls_setting(security.cert, "client.cert"),
             "--tls-key": tls_setting(security.key, "client.key")}
    for option, path in files.items():
        if not path:
            raise ValueError(f"--scheduler {scheduler}: a tls:// scheduler needs {option} (or "
                             "Dask's DASK_DISTRIBUTED__COMM__TLS__* configuration)")
        if not Path(path).is_file():
            raise ValueError(f"{option} {path}: no such file")
    from distributed.security import Security
    return Security(tls_ca_file=files["--tls-ca-file"], tls_client_cert=files["--tls-cert"],
                    tls_client_key=files["--tls-key"], require_encryption=True)


def client_security_of(worker):
    """The Security for a client that a job opens from ``worker``: on a TLS farm the worker's
    own CA, certificate and key in the client's role (a client checks its certificate
    against the client slots, which a worker's options leave empty); else the worker's."""
    from distributed.security import Security
    sec = worker.security
    if not sec.tls_worker_cert:
        return sec
    return Security(tls_ca_file=sec.tls_ca_file, tls_client_cert=sec.tls_worker_cert,
                    tls_client_key=sec.tls_worker_key,
                    require_encryption=sec.require_encryption)


def connect(scheduler: str | None, workers: int, security: ClusterSecurity | None = None):
    """(client, cluster): a client of the scheduler at ``scheduler`` (checked by
    check_scheduler, with ``security``), or of a new local cluster of ``workers``
    single-threaded worker processes on the loopback interface (Blender and the timed runs use
    every core of the machine themselves). A scheduler that does not answer, or refuses this
    client, is a ValueError naming ``--scheduler``."""
    from distributed import Client, LocalCluster
    if scheduler:
        tls = check_scheduler(scheduler, security)
        try:
            return Client(scheduler, timeout="20s", security=tls), None
        except (OSError, TimeoutError) as e:
            why = ("the scheduler did not accept this client's certificate, or does not answer"
                   if tls else "no Dask scheduler answers there")
            raise ValueError(
                f"--scheduler {scheduler}: {why} ({e}); start one with `dask scheduler` and "
                "workers with `dask worker ADDRESS` (docs/scale_out.md)") from None
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
