"""What every command that runs on a Dask cluster shares (``aolab reference``, ``tune`` and
``compare`` with ``--workers N`` / ``--scheduler ADDRESS``; docs/scale_out.md): the
connection, the cluster's size, waiting for a batch of jobs with Ctrl-C, and a worker
process's cache of the scenes its jobs read. Debian's python3-distributed is imported only
when a cluster is asked for.
"""

from __future__ import annotations

import ipaddress
import logging
import re
import signal
import sys
import time
from dataclasses import dataclass
from . import pem

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


#: The schemes of the addresses a client may give (Dask's others are for clusters of one
#: machine or need packages Debian does not ship).
SCHEMES = ("tcp", "tls")
#: A host name: dot-separated labels of letters, digits, hyphens (not at either end) and
#: underscores (container names), as a resolver takes them.
_HOST_NAME = re.compile(r"(?!-)[A-Za-z0-9_-]{1,63}(?<!-)(\.(?!-)[A-Za-z0-9_-]{1,63}(?<!-))*\.?")


@dataclass(frozen=True)
class SchedulerAddress:
    """A scheduler's address as :func:`parse_scheduler` read it."""
    scheme: str
    host: str
    port: int

    @property
    def url(self) -> str:
        """The address as Dask is given it: scheme in lower case, an IPv6 host in brackets."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{self.scheme}://{host}:{self.port}"


def parse_scheduler(address) -> SchedulerAddress:
    """``address`` read as a client's scheduler address, [SCHEME://]HOST:PORT: the scheme tcp
    (Dask's default) or tls, the host a name, an IPv4 address or an IPv6 address in
    brackets, the port 1 to 65535 and nothing after it. Anything else is a ValueError naming
    --scheduler and quoting the value, before any connection is tried (Dask's own errors
    come after one, or after its 20 s of waiting, and name no option)."""
    def bad(why: str) -> ValueError:
        return ValueError(f"--scheduler {address!r}: {why}")
    if not isinstance(address, str) or not address.strip():
        raise bad("give the scheduler's address, e.g. tls://10.0.0.5:8786, or leave "
                  "--scheduler out to work on this machine")
    scheme, sep, rest = address.partition("://")
    scheme, rest = (scheme.lower(), rest) if sep else ("tcp", address)
    if scheme not in SCHEMES:
        raise bad(f"the address must be tls://HOST:PORT (or tcp:// on this machine's loopback "
                  f"interface), not {scheme}://")
    host, port = _host_and_port(rest, bad)
    if not port:
        raise bad("no port: the address ends with :PORT (8786 is Dask's default)")
    if not (port.isascii() and port.isdigit() and len(port) <= 5 and 1 <= int(port) <= 65535):
        raise bad(f"the port must be an integer from 1 to 65535, got {port!r}")
    return SchedulerAddress(scheme, host, int(port))


def _host_and_port(rest: str, bad) -> tuple[str, str]:
    """(host, the text after its ':' or '') of HOST:PORT; the host checked (see
    parse_scheduler)."""
    if rest.startswith("["):
        host, closed, tail = rest[1:].partition("]")
        if not closed:
            raise bad("an IPv6 address opened with [ has no closing ]")
        if not _is_ip(host, ipaddress.IPv6Address):
            raise bad(f"{host!r} in brackets is not an IPv6 address")
    else:
        if rest.count(":") > 1:
            raise bad("an IPv6 address goes in brackets, e.g. tls://[::1]:8786")
        host, _, port = rest.partition(":")
        tail = ":" + port if ":" in rest else ""
        if not host:
            raise bad("no host: the address is [tls://]HOST:PORT")
        if host.replace(".", "").isdigit():
            if not _is_ip(host, ipaddress.IPv4Address):
                raise bad(f"{host!r} is not an IPv4 address")
        elif not _HOST_NAME.fullmatch(host):
            raise bad(f"{host!r} is not a host name or an IP address")
    if tail and not tail.startswith(":"):
        raise bad(f"{tail!r} after the host: the address ends with :PORT")
    return host, tail[1:]


def _is_ip(text: str, kind) -> bool:
    try:
        kind(text)
        return True
    except ValueError:
        return False


def is_loopback(host: str) -> bool:
    """Whether ``host`` names this machine's loopback interface (localhost, 127.0.0.0/8, ::1);
    a name is not resolved: only these spellings count."""
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def check_scheduler(scheduler: str, security: ClusterSecurity | None = None, *,
                    warn: bool = True):
    """The Security a client of ``scheduler`` needs, or None for plain tcp; a ValueError
    naming the option for an address this refuses: one parse_scheduler refuses, tcp://
    beyond the loopback interface without ``insecure``, a tls:// address without a CA,
    certificate or key (in the options or Dask's configuration) or with a file that is not
    one (tls_files). Allowed with ``insecure``, a tcp:// address on the network prints a
    warning if ``warn``."""
    security = security or ClusterSecurity()
    address = parse_scheduler(scheduler)
    if address.scheme == "tcp":
        if not is_loopback(address.host):
            if not security.insecure:
                raise ValueError(
                    f"--scheduler {scheduler!r}: refused: {OPEN_SCHEDULER_RISK}; run the farm "
                    "with TLS (a tls:// address with --tls-ca-file, --tls-cert and --tls-key; "
                    "docs/scale_out.md, \"Security\") or pass --insecure to accept the risk")
            if warn:
                print(f"aolab: warning: --insecure: {scheduler}: {OPEN_SCHEDULER_RISK}; use "
                      "tls:// (docs/scale_out.md, \"Security\")", file=sys.stderr)
        return None
    ca, cert, key = tls_files(scheduler, security)
    from distributed.security import Security
    return Security(tls_ca_file=ca, tls_client_cert=cert, tls_client_key=key,
                    require_encryption=True)


#: Each TLS option and its key under Dask's distributed.comm.tls configuration.
TLS_OPTIONS = {"--tls-ca-file": "ca-file", "--tls-cert": "client.cert", "--tls-key": "client.key"}


def tls_files(scheduler: str, security: ClusterSecurity) -> tuple[str, str, str]:
    """(CA, certificate, key) for the tls:// ``scheduler``: each option's file, else Dask's
    configuration's, checked before any connection (a regular, readable PEM of the right
    kind, the key the certificate's: util.pem); a ValueError names the option, or the
    configuration key the file came from."""
    given = dict(zip(TLS_OPTIONS, (security.ca_file, security.cert, security.key)))
    found = {}
    for option, key in TLS_OPTIONS.items():
        label, path = option, given[option]
        if path is None:
            import dask
            label = f"Dask's configuration distributed.comm.tls.{key}"
            path = dask.config.get(f"distributed.comm.tls.{key}", None)
        if path is None or path == "":
            raise ValueError(f"--scheduler {scheduler!r}: a tls:// scheduler needs {option} "
                             "(or Dask's DASK_DISTRIBUTED__COMM__TLS__* configuration)")
        found[option] = (label, str(path))
    (ca_label, ca), (cert_label, cert), (key_label, key) = found.values()
    pem.check_certificate(ca_label, ca)
    pem.check_certificate(cert_label, cert)
    pem.check_key(key_label, key, cert_label, cert)
    return ca, cert, key


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
    if scheduler is not None:   # "" too: refused, never taken for no scheduler
        tls = check_scheduler(scheduler, security)
        try:
            return Client(parse_scheduler(scheduler).url, timeout="20s", security=tls), None
        except (OSError, TimeoutError) as e:
            # The files were checked: what is left is the other end, or the pair's CAs.
            why = ("no scheduler answers there, or it did not accept this client's "
                   "certificate, or --tls-ca-file's CA did not sign the scheduler's"
                   if tls else "no Dask scheduler answers there")
            raise ValueError(
                f"--scheduler {scheduler!r}: {why} ({e}); start one with `dask scheduler` and "
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
