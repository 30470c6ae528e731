"""The farm's security (docs/scale_out.md, "Security"): a plain tcp:// scheduler beyond this
machine is refused unless --insecure says otherwise; a tls:// scheduler needs its CA,
certificate and key; a real TLS farm (a scheduler and two workers on the loopback
interface, certificates made here with openssl) renders a reference for a client with a
certificate of its CA and refuses one without; and a cache entry whose files no longer
have the SHA-256 recorded when they were rendered is rendered again, never served."""
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest

from aolab.util.arguments import parse_frames
from aolab.util import files
from aolab.util.dask_cluster import (ClusterSecurity, check_scheduler, is_loopback,
                                     parse_scheduler)

from blender_support import TINY, needs_blender
from farm_support import (ANIMATION, FRAMES, blender_children_of, ctrl_c_while_rendering,
                          kill_a_worker_while_rendering)
from farm_support import make_ca, make_cert, needs_openssl

distributed = pytest.importorskip("distributed", reason="python3-distributed is not installed "
                                  "(scripts/install-deps.sh installs it)")


def aolab(*args, timeout=300):
    return subprocess.run([sys.executable, "-m", "aolab", *args], capture_output=True,
                          text=True, timeout=timeout)


def test_addresses_are_read_as_dask_reads_them():
    def scheme_and_host(address):
        parsed = parse_scheduler(address)
        return parsed.scheme, parsed.host
    assert scheme_and_host("tls://10.0.0.5:8786") == ("tls", "10.0.0.5")
    assert scheme_and_host("10.0.0.5:8786") == ("tcp", "10.0.0.5")
    assert scheme_and_host("TCP://[::1]:8786") == ("tcp", "::1")
    assert scheme_and_host("tcp://render-01:8786") == ("tcp", "render-01")
    for host in ("127.0.0.1", "127.8.9.10", "::1", "localhost"):
        assert is_loopback(host), host
    for host in ("10.0.0.5", "0.0.0.0", "render-01", "::", "192.0.2.1"):
        assert not is_loopback(host), host


@pytest.mark.parametrize("command", [
    ["reference", str(TINY)],
    ["compare", "room", "--methods", "hbao"],
    ["tune", "--methods", "hbao", "--trials", "1"],
])
def test_plain_tcp_beyond_this_machine_is_refused(command, tmp_path):
    """Every command that takes --scheduler refuses tcp:// to another host before any work,
    with one line that names the risk and the fix."""
    r = aolab(*command, "--scheduler", "tcp://10.0.0.5:8786", "--out", str(tmp_path / "o"))
    lines = r.stderr.splitlines()
    assert r.returncode == 2 and len(lines) == 1, r.stderr
    assert lines[0].startswith("aolab: --scheduler 'tcp://10.0.0.5:8786': refused")
    assert "can run any code on every worker" in lines[0]
    assert "tls://" in lines[0] and "--insecure" in lines[0]
    assert not (tmp_path / "o").exists()


def test_insecure_allows_it_and_warns_each_time(capsys):
    for _ in range(2):
        assert check_scheduler("tcp://10.0.0.5:8786", ClusterSecurity(insecure=True)) is None
        err = capsys.readouterr().err
        assert err.startswith("aolab: warning: --insecure: tcp://10.0.0.5:8786")
    # on this machine's loopback interface plain tcp is allowed, and silent
    for address in ("tcp://127.0.0.1:8786", "localhost:8786", "tcp://[::1]:8786"):
        assert check_scheduler(address) is None
    assert capsys.readouterr().err == ""


def test_tls_needs_its_three_files(tmp_path, monkeypatch):
    for var in ("CA_FILE", "CLIENT__CERT", "CLIENT__KEY"):
        monkeypatch.delenv(f"DASK_DISTRIBUTED__COMM__TLS__{var}", raising=False)
    with pytest.raises(ValueError, match="a tls:// scheduler needs --tls-ca-file"):
        check_scheduler("tls://10.0.0.5:8786")
    ca = tmp_path / "ca.pem"
    ca.write_text("x")
    with pytest.raises(ValueError, match="needs --tls-cert"):
        check_scheduler("tls://10.0.0.5:8786", ClusterSecurity(ca_file=str(ca)))
    # all three named, each file is then read (test_hostile_farm.py has every case)
    with pytest.raises(ValueError, match=f"--tls-ca-file '{ca}': holds no PEM certificate"):
        check_scheduler("tls://10.0.0.5:8786", ClusterSecurity(
            ca_file=str(ca), cert=str(ca), key=str(tmp_path / "none.key")))
    with pytest.raises(ValueError, match="must be tls://HOST:PORT .*not ws://"):
        check_scheduler("ws://10.0.0.5:8786")
    r = aolab("reference", str(TINY), "--scheduler", "tls://127.0.0.1:8786")
    assert r.returncode == 2 and "needs --tls-ca-file" in r.stderr, r.stderr


#: Dask's comm timeouts for every process of the test farm (scheduler, workers, the jobs'
#: clients, the aolab client): a loaded machine's TLS handshakes and first reads must not
#: be what fails a test. Timeouts only, never a pace: the tests wait on events.
FARM_CONFIG = {"DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "120s",
               "DASK_DISTRIBUTED__COMM__TIMEOUTS__TCP": "120s"}
#: How long the farm may take to come up on a loaded machine: a guard against a hang only.
FARM_START_S = 300


def farm_env() -> dict:
    return dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path), **FARM_CONFIG)


def farm_logs(folder: Path) -> str:
    """The farm's own logs, for a failing assert's message."""
    return "".join(f"\n--- {log.name}\n" + log.read_text(errors="replace")[-3000:]
                   for log in sorted(folder.glob("*.log")))


def scheduler_address(file: Path, scheduler: subprocess.Popen, logs: Path) -> str:
    """The address in the scheduler's file once it is there whole: the scheduler writes it
    with a plain write, so a reader can see it empty or cut (no JSON yet)."""
    import json
    deadline = time.monotonic() + FARM_START_S
    while time.monotonic() < deadline:
        assert scheduler.poll() is None, "the TLS scheduler exited" + farm_logs(logs)
        try:
            return json.loads(file.read_text())["address"]
        except (OSError, ValueError, KeyError):
            time.sleep(0.2)
    pytest.fail("the TLS scheduler did not start" + farm_logs(logs))


#: How many times the farm's start may start again a worker that ended before the farm was up.
WORKER_RESTARTS = 3


def registered_workers(address: str, security) -> int:
    """How many workers the scheduler has, asked by a client of its own: a client whose
    stream the scheduler dropped (below) is not asked again."""
    from distributed import Client
    with warnings.catch_warnings():   # Debian 12's tornado: make_current is deprecated
        warnings.simplefilter("ignore", DeprecationWarning)
        with Client(address, security=security, timeout=FARM_START_S) as client:
            return len(client.scheduler_info()["workers"])


def wait_for_workers(address: str, node, ca, workers: list, start_worker, logs: Path) -> None:
    """Returns once every worker of ``workers`` is registered with the scheduler (asked over
    TLS with a node's certificate): a job submitted then finds a worker, not a farm still
    starting. A worker whose process ended before then is started again by
    ``start_worker(i)``, at most WORKER_RESTARTS times: on Debian 13 (Dask 2024.12 with
    OpenSSL 3.5) the scheduler was seen to close a TLS worker's stream just after registering
    it, and the worker then exits. That is Dask's start-up, not what these tests check."""
    from distributed.security import Security
    security = Security(tls_ca_file=str(ca[0]), tls_client_cert=str(node[0]),
                        tls_client_key=str(node[1]), require_encryption=True)
    restarts, deadline = 0, time.monotonic() + FARM_START_S
    while registered_workers(address, security) < len(workers):
        for i, p in enumerate(workers):
            if p.poll() is not None:
                if restarts == WORKER_RESTARTS:
                    pytest.fail(f"worker{i} ended {restarts + 1} times" + farm_logs(logs))
                restarts += 1
                workers[i] = start_worker(i)
        if time.monotonic() > deadline:
            pytest.fail(f"{len(workers)} workers did not join the TLS farm" + farm_logs(logs))
        time.sleep(0.5)   # a poll of the farm's state, not a pace of the test


@pytest.fixture
def tls_farm(tmp_path):
    """A TLS scheduler and two workers on 127.0.0.1, each with a certificate of one CA, both
    workers registered; yields (address, the folder of the certificates, the CA). Their logs
    go to tmp_path/*.log (farm_logs)."""
    certs = tmp_path / "certs"
    certs.mkdir()
    ca = make_ca(certs, "farm")
    node = make_cert(certs, "node", ca)
    tls = ["--tls-ca-file", str(ca[0]), "--tls-cert", str(node[0]), "--tls-key", str(node[1])]
    file = tmp_path / "scheduler.json"

    def start(name: str, args: list[str]) -> subprocess.Popen:
        with open(tmp_path / f"{name}.log", "ab") as log:   # a restart appends
            return subprocess.Popen(["dask", *args, *tls], env=farm_env(),
                                    stdout=log, stderr=subprocess.STDOUT)
    scheduler = start("scheduler", ["scheduler", "--protocol", "tls", "--host", "127.0.0.1",
                                    "--port", "0", "--no-dashboard", "--scheduler-file",
                                    str(file)])
    workers = []
    try:
        address = scheduler_address(file, scheduler, tmp_path)
        assert address.startswith("tls://127.0.0.1:")

        def start_worker(i: int) -> subprocess.Popen:
            # by address: a worker reading the scheduler's file could see it cut too
            return start(f"worker{i}", ["worker", address, "--nthreads", "1",
                                        "--no-dashboard", "--host", "127.0.0.1"])
        workers = [start_worker(i) for i in range(2)]
        wait_for_workers(address, node, ca, workers, start_worker, tmp_path)
        yield address, certs, ca
    finally:
        # the workers first, then the scheduler they report to
        for group in (workers, [scheduler]):
            for p in group:
                p.terminate()
            for p in group:
                try:
                    p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()


def farm_aolab(*args, timeout=600):
    """aolab with the farm's Dask configuration (FARM_CONFIG)."""
    return subprocess.run([sys.executable, "-m", "aolab", *args], capture_output=True,
                          text=True, timeout=timeout, env=farm_env())


@needs_blender
@needs_openssl
def test_a_tls_farm_renders_for_its_clients_only(tls_farm, tmp_path):
    address, certs, ca = tls_farm
    client = make_cert(certs, "client", ca)
    cache = tmp_path / "cache"
    r = farm_aolab("reference", str(TINY), "--spp", "1", "--quiet", "--cache", str(cache),
                   "--scheduler", address, "--tls-ca-file", str(ca[0]), "--tls-cert",
                   str(client[0]), "--tls-key", str(client[1]))
    assert r.returncode == 0, r.stderr[-2000:] + farm_logs(tmp_path)
    assert "tiny_scene: rendered" in r.stdout and " on " in r.stdout   # on a worker
    assert [p for p in cache.iterdir() if (p / "reference.exr").is_file()]
    # A certificate of another CA: the farm does not accept it.
    other = make_cert(certs, "intruder", make_ca(certs, "other"))
    r = farm_aolab("reference", str(TINY), "--spp", "1", "--quiet", "--cache",
                   str(tmp_path / "c2"), "--scheduler", address, "--tls-ca-file", str(ca[0]),
                   "--tls-cert", str(other[0]), "--tls-key", str(other[1]), timeout=120)
    lines = r.stderr.splitlines()
    assert r.returncode == 2 and len(lines) == 1, r.stderr[-2000:] + farm_logs(tmp_path)
    assert "did not accept this client's certificate" in lines[0]
    assert not (tmp_path / "c2").exists() or not any((tmp_path / "c2").iterdir())
    # Plain tcp to the TLS port: no connection either.
    r = farm_aolab("reference", str(TINY), "--spp", "1", "--quiet", "--cache",
                   str(tmp_path / "c3"), "--scheduler", address.replace("tls://", "tcp://"),
                   timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr[-2000:]


def test_checksums_name_what_changed(tmp_path):
    (tmp_path / "a.exr").write_bytes(b"abc")
    (tmp_path / "a.json").write_text("{}")
    files.write_checksums(tmp_path, ["a.exr", "a.json"])
    sums = subprocess.run(["sha256sum", "-c", files.CHECKSUMS_NAME], cwd=tmp_path,
                          capture_output=True, text=True)
    assert sums.returncode == 0, sums.stdout   # the format sha256sum checks
    assert files.checksum_mismatch(tmp_path, ["a.exr", "a.json"]) is None
    (tmp_path / "a.exr").write_bytes(b"abd")
    assert files.checksum_mismatch(tmp_path, ["a.exr", "a.json"]).startswith(
        "a.exr: SHA-256 ba7816bf8f01… recorded, ")
    (tmp_path / "a.exr").write_bytes(b"abc")
    (tmp_path / "b.exr").write_bytes(b"new")
    assert files.checksum_mismatch(tmp_path, ["a.exr", "a.json", "b.exr"]) == (
        "b.exr: not in SHA256SUMS")
    (tmp_path / "a.json").unlink()
    assert files.checksum_mismatch(tmp_path, ["a.exr"]).startswith("a.json: ")
    (tmp_path / files.CHECKSUMS_NAME).write_text("nonsense\n")
    assert "not a SHA256SUMS line" in files.checksum_mismatch(tmp_path, ["a.exr"])


@needs_blender
def test_a_changed_cache_entry_is_rendered_again_never_served(tmp_path):
    cache = tmp_path / "cache"
    args = ("reference", str(TINY), "--spp", "1", "--quiet", "--cache", str(cache))
    r = aolab(*args)
    assert r.returncode == 0 and "rendered" in r.stdout, r.stderr
    (entry,) = [p for p in cache.iterdir() if not p.name.startswith(".")]
    sums = subprocess.run(["sha256sum", "-c", files.CHECKSUMS_NAME], cwd=entry,
                          capture_output=True, text=True)
    assert sums.returncode == 0 and "reference.exr: OK" in sums.stdout, sums.stdout
    assert "cached" in aolab(*args).stdout
    # One byte of the EXR changed (a flipped bit on the disk, or an edit): reported, rendered
    # again, and the new entry's files match their sums.
    exr = entry / "reference.exr"
    data = bytearray(exr.read_bytes())
    data[len(data) // 2] ^= 0x01
    exr.write_bytes(bytes(data))
    r = aolab(*args)
    assert r.returncode == 0 and "tiny_scene: rendered" in r.stdout, r.stdout + r.stderr
    assert f"aolab: warning: cache entry {entry}: reference.exr: SHA-256 " in r.stderr
    assert files.checksum_mismatch(entry, ["reference.exr", "reference.json"]) is None
    # An entry from before the checksums is served and gets them, once.
    (entry / files.CHECKSUMS_NAME).unlink()
    r = aolab(*args)
    assert "tiny_scene: cached" in r.stdout and r.stderr == "", r.stderr
    assert (entry / files.CHECKSUMS_NAME).is_file()


def tls_args(certs: Path, ca) -> list[str]:
    client = certs / "client.pem"
    if not client.exists():
        make_cert(certs, "client", ca)
    return ["--tls-ca-file", str(ca[0]), "--tls-cert", str(client),
            "--tls-key", str(certs / "client.key")]


@needs_blender
@needs_openssl
def test_ctrl_c_stops_the_tls_farm_renders(tls_farm, tmp_path):
    """As on the local cluster (test_cluster.py): Ctrl-C ends the command with status 130,
    the workers' Blenders stop (told through the farm, over TLS), and the cache holds
    complete entries only."""
    address, certs, ca = tls_farm
    cache = tmp_path / "cache"
    args = [sys.executable, "-m", "aolab", "reference", "--quiet", str(ANIMATION), "--frames",
            FRAMES, "--spp", "1024", "--cache", str(cache), "--scheduler", address,
            *tls_args(certs, ca)]
    run, out, err = ctrl_c_while_rendering(args, cache)
    assert run.returncode == 130 and "interrupted" in err and "Traceback" not in err, err
    deadline = time.monotonic() + 30   # the jobs poll the stop event every STOP_POLL_S
    while blender_children_of(set(), str(cache)) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not blender_children_of(set(), str(cache))
    assert not [p.name for p in cache.iterdir() if p.name.startswith(".")]
    assert all((p / "reference.json").exists() for p in cache.iterdir())


@needs_blender
@needs_openssl
def test_a_killed_tls_worker_loses_no_frame(tls_farm, tmp_path):
    """A worker process killed mid-render (SIGKILL, as when a machine goes away): every frame
    still arrives, rendered by the other worker or the restarted one, over TLS."""
    address, certs, ca = tls_farm
    cache = tmp_path / "cache"
    run = subprocess.Popen(
        [sys.executable, "-m", "aolab", "reference", "--quiet", str(ANIMATION), "--frames",
         FRAMES, "--spp", "256", "--cache", str(cache), "--out", str(tmp_path / "out"),
         "--scheduler", address, *tls_args(certs, ca)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    killed, out, err = kill_a_worker_while_rendering(run, cache)
    assert killed is not None, "no render was caught running: " + err[-2000:]
    assert run.returncode == 0, err[-3000:]
    frames = sorted(int(p.name) for p in (tmp_path / "out" / "frames").iterdir())
    assert frames == parse_frames(FRAMES)
    assert all((p / "reference.json").exists() for p in cache.iterdir())
