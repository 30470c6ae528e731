"""What the Dask farm tests share: the animation they render, finding the Blender processes a
farm started, stopping a render midway, and a small certificate authority for TLS."""
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest

from blender_support import ROOT


ANIMATION = ROOT / "tests" / "data" / "tiny_animation.py"
FRAMES = "1-4"


def blender_children_of(pids: set[int], marker: str) -> dict[int, int]:
    """Running Blender processes whose command line holds ``marker``: pid -> parent pid."""
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cmd = (entry / "cmdline").read_bytes().split(b"\0")
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        if cmd and cmd[0].endswith(b"blender") and marker.encode() in b" ".join(cmd):
            ppid = int(stat.rsplit(")", 1)[1].split()[1])
            if not pids or ppid in pids:
                found[int(entry.name)] = ppid
    return found


def kill_a_worker_while_rendering(run: subprocess.Popen, cache: Path):
    """Waits for a Blender rendering into ``cache`` and kills its worker process (SIGKILL: no
    clean-up of any kind, as when a machine goes away), then lets the command ``run`` finish;
    returns ((Blender's pid, the worker's) or None, stdout, stderr)."""
    killed = None
    try:
        deadline = time.monotonic() + 120
        while killed is None and time.monotonic() < deadline and run.poll() is None:
            for pid, worker in blender_children_of(set(), str(cache)).items():
                if worker != run.pid:      # a worker process, not the command itself
                    os.kill(worker, signal.SIGKILL)
                    killed = (pid, worker)
                    break
            time.sleep(0.05)
        out, err = run.communicate(timeout=600)
    finally:
        if run.poll() is None:
            run.kill()
    return killed, out, err


def ctrl_c_while_rendering(args: list[str], cache: Path):
    """Runs the command ``args`` as a terminal would, sends Ctrl-C (SIGINT to its process
    group) once a Blender renders into ``cache``; returns (process, stdout, stderr)."""
    # A background shell (CI's) starts children with SIGINT ignored, and the command would then
    # run to its end (status 0); a terminal's Ctrl-C reaches a command with the default.
    run = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           start_new_session=True,
                           preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 120
        while not blender_children_of(set(), str(cache)) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert blender_children_of(set(), str(cache)), "no render started"
        os.killpg(run.pid, signal.SIGINT)
        out, err = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
    return run, out, err


OPENSSL = shutil.which("openssl")


needs_openssl = pytest.mark.skipif(OPENSSL is None, reason="openssl is not installed "
                                   "(scripts/install-deps.sh installs it)")


def make_ca(folder: Path, name: str) -> tuple[Path, Path]:
    """A certificate authority: (its certificate, its key)."""
    cert, key = folder / f"{name}-ca.pem", folder / f"{name}-ca.key"
    subprocess.run([OPENSSL, "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2",
                    "-subj", f"/CN={name} CA", "-keyout", str(key), "-out", str(cert)],
                   check=True, capture_output=True)
    return cert, key


def make_cert(folder: Path, name: str, ca: tuple[Path, Path]) -> tuple[Path, Path]:
    """A certificate for 127.0.0.1 signed by ``ca``: (certificate, key)."""
    cert, key, csr = folder / f"{name}.pem", folder / f"{name}.key", folder / f"{name}.csr"
    ext = folder / f"{name}.ext"
    ext.write_text("subjectAltName = IP:127.0.0.1, DNS:localhost\n")
    subprocess.run([OPENSSL, "req", "-newkey", "rsa:2048", "-nodes", "-subj", f"/CN={name}",
                    "-keyout", str(key), "-out", str(csr)], check=True, capture_output=True)
    subprocess.run([OPENSSL, "x509", "-req", "-in", str(csr), "-CA", str(ca[0]), "-CAkey",
                    str(ca[1]), "-CAcreateserial", "-days", "2", "-extfile", str(ext),
                    "-out", str(cert)], check=True, capture_output=True)
    return cert, key
