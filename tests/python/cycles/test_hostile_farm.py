"""Hostile --scheduler addresses and TLS files (docs/scale_out.md, "Security"): each is refused
before any connection is tried and before any work, in one line ``aolab: ...`` naming the
option (or the Dask configuration key the file came from) and quoting the value, exit status
2, the user's files unchanged. No scheduler listens during these tests, and the Dask client
is replaced by one that fails the test if it is ever made."""
import os
import subprocess
import sys

import pytest

from aolab import cli
from aolab.cycles import run as cycles_run
from aolab.cycles.plan import make_plan, resolve_scene
from aolab.cycles.run import Delivery
from aolab.util.dask_cluster import parse_scheduler

from blender_support import TINY
from farm_support import OPENSSL, make_ca, make_cert, needs_openssl

distributed = pytest.importorskip("distributed", reason="python3-distributed is not installed "
                                  "(scripts/install-deps.sh installs it)")

#: Where nothing listens: a connection attempt there would fail, and slowly.
NOWHERE = "tls://127.0.0.1:9"


@pytest.fixture
def no_connection(monkeypatch):
    """Any Dask client, local cluster or render made from here on fails the test."""
    def refused(*args, **kwargs):
        pytest.fail(f"a connection or a render was attempted: {args!r}")
    monkeypatch.setattr(distributed, "Client", refused)
    monkeypatch.setattr(distributed, "LocalCluster", refused)
    monkeypatch.setattr(cycles_run, "render", refused)


def refused_line(argv, capsys) -> str:
    """cli.main(argv)'s one error line; its status must be 2 and stdout empty."""
    assert cli.main(argv) == 2
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert out == "" and len(lines) == 1, err
    return lines[0]


ADDRESSES = [
    ("", "give the scheduler's address, e.g. tls://10.0.0.5:8786, or leave --scheduler out "
         "to work on this machine"),
    (" \t", "give the scheduler's address, e.g. tls://10.0.0.5:8786, or leave --scheduler "
            "out to work on this machine"),
    ("tcp://[::1]:x", "the port must be an integer from 1 to 65535, got 'x'"),
    ("tcp://[::1", "an IPv6 address opened with [ has no closing ]"),
    ("tcp://localhost", "no port: the address ends with :PORT (8786 is Dask's default)"),
    ("localhost:99999", "the port must be an integer from 1 to 65535, got '99999'"),
    ("tcp://127.0.0.1:0", "the port must be an integer from 1 to 65535, got '0'"),
    ("tcp://127.0.0.1:8786/x", "the port must be an integer from 1 to 65535, got '8786/x'"),
    ("tcp://[::1]8786", "'8786' after the host: the address ends with :PORT"),
    ("::1:8786", "an IPv6 address goes in brackets, e.g. tls://[::1]:8786"),
    ("tcp://[127.0.0.1]:8786", "'127.0.0.1' in brackets is not an IPv6 address"),
    ("tcp://127.0.0.256:8786", "'127.0.0.256' is not an IPv4 address"),
    ("tls://render 01:8786", "'render 01' is not a host name or an IP address"),
    ("tcp://:8786", "no host: the address is [tls://]HOST:PORT"),
    ("ws://127.0.0.1:8786", "the address must be tls://HOST:PORT (or tcp:// on this "
                            "machine's loopback interface), not ws://"),
]


@pytest.mark.parametrize("address, why", ADDRESSES)
def test_a_bad_address_is_refused_before_connecting(address, why, no_connection, capsys,
                                                    tmp_path):
    line = refused_line(["reference", str(TINY), "--cache", str(tmp_path / "cache"),
                         "--scheduler", address], capsys)
    assert line == f"aolab: --scheduler {address!r}: {why}"
    assert not (tmp_path / "cache").exists()


@pytest.mark.parametrize("command", [
    ["reference", str(TINY)],
    ["compare", "room", "--methods", "hbao"],
    ["tune", "--methods", "hbao", "--trials", "1"],
])
def test_an_empty_scheduler_is_not_taken_for_none(command, tmp_path):
    """The command line as a user runs it: no local render starts, nothing is written."""
    r = subprocess.run([sys.executable, "-m", "aolab", *command, "--out", str(tmp_path / "o"),
                        "--scheduler", ""], capture_output=True, text=True,
                       timeout=60)   # a guard against a hang, not a timing
    assert r.returncode == 2 and r.stdout == "", r.stderr
    assert r.stderr.splitlines() == [f"aolab: --scheduler '': {ADDRESSES[0][1]}"]
    assert not (tmp_path / "o").exists()


def test_the_api_refuses_an_empty_scheduler_too(no_connection, tmp_path):
    from aolab.cycles import cluster
    scene = resolve_scene(str(TINY))
    with pytest.raises(ValueError, match=r"^--scheduler '': give the scheduler's address"):
        cluster.run_plans([make_plan(scene, spp=1)],
                          Delivery(cache=str(tmp_path / "cache")), scheduler="")
    assert not (tmp_path / "cache").exists()


def test_good_addresses_are_given_to_dask_as_it_reads_them():
    assert parse_scheduler("TCP://[::1]:8786").url == "tcp://[::1]:8786"
    assert parse_scheduler("localhost:08786").url == "tcp://localhost:8786"
    assert parse_scheduler("tls://render-01.farm:8786").url == "tls://render-01.farm:8786"
    assert parse_scheduler("tls://10.0.0.5:65535").port == 65535


# --- TLS files --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def pems(tmp_path_factory):
    """A CA, a certificate with its key, a key of another pair, an encrypted key, an empty
    file, a folder and a FIFO: name -> path."""
    if OPENSSL is None:
        pytest.skip("openssl is not installed (scripts/install-deps.sh installs it)")
    d = tmp_path_factory.mktemp("pems")
    ca = make_ca(d, "farm")
    cert, key = make_cert(d, "client", ca)
    other = make_cert(d, "other", ca)[1]
    encrypted = d / "encrypted.key"
    subprocess.run([OPENSSL, "pkey", "-in", str(key), "-aes128", "-passout", "pass:secret",
                    "-out", str(encrypted)], check=True, capture_output=True)
    (d / "empty.pem").write_bytes(b"")
    (d / "folder").mkdir()
    os.mkfifo(d / "fifo")
    return {"ca": ca[0], "cert": cert, "key": key, "other": other, "encrypted": encrypted,
            "empty": d / "empty.pem", "folder": d / "folder", "fifo": d / "fifo"}


def tls_argv(pems, tmp_path, **given) -> list[str]:
    files = {"ca": pems["ca"], "cert": pems["cert"], "key": pems["key"]}
    files.update({k: pems[v] for k, v in given.items()})
    return ["reference", str(TINY), "--cache", str(tmp_path / "cache"), "--scheduler", NOWHERE,
            "--tls-ca-file", str(files["ca"]), "--tls-cert", str(files["cert"]),
            "--tls-key", str(files["key"])]


def contents(pems) -> dict:
    return {k: p.read_bytes() for k, p in pems.items() if p.is_file()}


NOT_A_CERT = ("holds no PEM certificate (-----BEGIN CERTIFICATE-----) that Python's ssl module "
              "can load (no start line: cadata does not contain a certificate); it holds a "
              "private key")
TLS_CASES = [
    ({"ca": "empty"}, "--tls-ca-file", "empty", "the file is empty"),
    ({"cert": "empty"}, "--tls-cert", "empty", "the file is empty"),
    ({"key": "empty"}, "--tls-key", "empty", "the file is empty"),
    ({"cert": "key"}, "--tls-cert", "key", NOT_A_CERT),
    ({"ca": "key"}, "--tls-ca-file", "key", NOT_A_CERT),
    ({"key": "cert"}, "--tls-key", "cert",
     "holds no PEM private key (-----BEGIN PRIVATE KEY-----)"),
    ({"key": "other"}, "--tls-key", "other",
     "not the private key of --tls-cert {cert!r} ([X509: KEY_VALUES_MISMATCH] key values "
     "mismatch)"),
    ({"key": "encrypted"}, "--tls-key", "encrypted",
     "the key is encrypted with a passphrase, which Dask cannot give: use a key without one, "
     "readable by you only"),
]


@needs_openssl
@pytest.mark.parametrize("given, option, name, why", TLS_CASES)
def test_a_wrong_tls_file_is_named_before_connecting(given, option, name, why, pems,
                                                     no_connection, capsys, tmp_path):
    before = contents(pems)
    line = refused_line(tls_argv(pems, tmp_path, **given), capsys)
    why = why.format(cert=str(pems["cert"]))
    assert line == f"aolab: {option} {str(pems[name])!r}: {why}"
    assert contents(pems) == before and not (tmp_path / "cache").exists()


@needs_openssl
def test_a_folder_or_a_missing_file_is_said_so(pems, no_connection, capsys, tmp_path):
    line = refused_line(tls_argv(pems, tmp_path, ca="folder"), capsys)
    assert line == (f"aolab: --tls-ca-file must be a regular file, got "
                    f"{str(pems['folder'])!r}, which is a folder")
    argv = tls_argv(pems, tmp_path)
    argv[-1] = str(tmp_path / "none.key")
    line = refused_line(argv, capsys)
    assert line == f"aolab: --tls-key {str(tmp_path / 'none.key')!r}: no such file"


@needs_openssl
def test_a_fifo_is_never_opened(pems, tmp_path):
    """Opening a FIFO would wait for a writer forever: it is refused from its kind."""
    r = subprocess.run([sys.executable, "-m", "aolab", *tls_argv(pems, tmp_path, cert="fifo")],
                       capture_output=True, text=True, timeout=60)   # a hang guard only
    assert r.returncode == 2 and r.stderr.splitlines() == [
        f"aolab: --tls-cert must be a regular file, got {str(pems['fifo'])!r}, which is a "
        "FIFO (named pipe)"], r.stderr


@needs_openssl
def test_a_file_from_dasks_configuration_is_named_by_its_key(pems, tmp_path):
    """Without --tls-key, Dask's configuration gives the key: an error names that key."""
    argv = tls_argv(pems, tmp_path, key="cert")[:-2]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path),
               DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY=str(pems["cert"]))
    r = subprocess.run([sys.executable, "-m", "aolab", *argv], capture_output=True, text=True,
                       env=env, timeout=60)
    assert r.returncode == 2 and r.stderr.splitlines() == [
        f"aolab: Dask's configuration distributed.comm.tls.client.key {str(pems['cert'])!r}: "
        "holds no PEM private key (-----BEGIN PRIVATE KEY-----)"], r.stderr
    assert not (tmp_path / "cache").exists()


@needs_openssl
def test_good_files_reach_the_connection(pems, monkeypatch, capsys, tmp_path):
    """The files pass, and only then is a client made (here one that refuses at once)."""
    made = []

    def client(address, **kwargs):
        made.append((address, kwargs["security"].tls_client_key))
        raise OSError("refused")
    monkeypatch.setattr(distributed, "Client", client)
    line = refused_line(tls_argv(pems, tmp_path), capsys)
    assert made == [(NOWHERE, str(pems["key"]))]
    assert line.startswith(f"aolab: --scheduler {NOWHERE!r}: no scheduler answers there")


@needs_openssl
@pytest.mark.parametrize("scheduler, where", [
    (None, "none is given"), ("tcp://127.0.0.1:9", "'tcp://127.0.0.1:9' is not one")])
def test_a_tls_file_without_a_tls_scheduler_is_not_ignored(scheduler, where, pems,
                                                           no_connection, capsys, tmp_path):
    argv = ["reference", str(TINY), "--cache", str(tmp_path / "cache"), "--tls-cert",
            str(pems["cert"])] + (["--scheduler", scheduler] if scheduler else [])
    line = refused_line(argv, capsys)
    assert line == (f"aolab: --tls-cert {str(pems['cert'])!r}: only a tls:// --scheduler uses "
                    f"it, and {where}")
    assert not (tmp_path / "cache").exists()
