"""`aolab tune` and `aolab compare` with --workers: the accuracy computed on a local Dask
cluster is the accuracy computed in one process, a worker killed mid-run loses no trial, and
Ctrl-C keeps the finished trials (docs/scale_out.md)."""
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import optuna
import psutil
import pytest

ROOT = Path(__file__).resolve().parents[3]
SCENES = ROOT / "reference_scenes"
COMMON = ["--scenes-dir", str(SCENES), "--warmup", "0", "--repeat", "1", "--no-progress"]


def aolab(*args, **kw):
    return subprocess.run([sys.executable, "-m", "aolab", *args], capture_output=True,
                          text=True, timeout=600, **kw)


def test_compare_on_a_cluster_scores_every_row_as_one_process_does(tmp_path):
    base = ["compare", "grille", "engine", "--crop", "96x54", "--methods", "hbao", "vao",
            "--rtao-rays", "none", *COMMON]
    here = aolab(*base, "--out", str(tmp_path / "here"))
    there = aolab(*base, "--out", str(tmp_path / "there"), "--workers", "2")
    assert here.returncode == 0 and there.returncode == 0, there.stderr
    assert there.stderr == ""   # no warning from the cluster

    def metrics(folder):
        rows = json.loads((folder / "results.json").read_text())["rows"]
        return {r["key"]: r.get("metrics") for r in rows}
    a, b = metrics(tmp_path / "here"), metrics(tmp_path / "there")
    assert a.keys() == b.keys() and len(a) > 20
    assert all(a[k] == b[k] for k in a)


def test_a_scheduler_that_does_not_answer_is_one_line_naming_the_option(tmp_path):
    # Port 9 on the loopback (discard) has no scheduler: the client gives up after its
    # timeout and the command says which option was wrong.
    r = aolab("compare", "grille", "--crop", "32x18", "--methods", "hbao", *COMMON,
              "--out", str(tmp_path / "out"), "--scheduler", "tcp://127.0.0.1:9")
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        "aolab: --scheduler 'tcp://127.0.0.1:9': no Dask scheduler answers there"), r.stderr


def workers_of(pid: int) -> list:
    """The Dask worker processes a local cluster started (multiprocessing's spawned
    children), not its resource tracker."""
    return [c for c in psutil.Process(pid).children(recursive=True)
            if "spawn_main" in " ".join(c.cmdline())]


def complete_trials(db: Path, method: str) -> list:
    study = optuna.load_study(study_name=f"aolab-tune-{method}", storage=f"sqlite:///{db}")
    return [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]


def _count(db: Path, where: str) -> int:
    """Trials in the store (a plain SQLite read: no Optuna storage to set up while the run
    writes); 0 before the table exists."""
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=1) as con:
            return con.execute(f"SELECT count(*) FROM trials {where}").fetchone()[0]
    except sqlite3.Error:
        return 0


def trials_asked(db: Path) -> int:
    return _count(db, "")


def trials_done(db: Path) -> int:
    return _count(db, "WHERE state = 'COMPLETE'")


def test_a_worker_killed_mid_tune_loses_no_trial(tmp_path):
    out = tmp_path / "tune"
    cmd = [sys.executable, "-m", "aolab", "tune", "--methods", "hbao", "--trials", "12",
           "--workers", "2", "--out", str(out), "--presets-file", str(tmp_path / "p.json"),
           "--scenes", "grille", "engine", "--crop", "320x180", *COMMON]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    killed = None
    deadline = time.monotonic() + 300
    while proc.poll() is None and time.monotonic() < deadline and killed is None:
        kids = workers_of(proc.pid)
        if kids and trials_asked(out / "tune.db") >= 1:   # the cluster is at work
            kids[0].kill()
            killed = trials_done(out / "tune.db")
        time.sleep(0.02)
    stdout, stderr = proc.communicate(timeout=300)
    assert killed is not None and killed < 12, \
        f"the worker was not killed mid-run (status {proc.returncode}): {stderr[-2000:]}"
    assert proc.returncode == 0, stderr
    trials = complete_trials(out / "tune.db", "hbao")
    assert len(trials) == 12 and all(len(t.user_attrs["scenes"]) == 2 for t in trials)


def test_ctrl_c_on_a_cluster_keeps_the_finished_trials(tmp_path):
    out = tmp_path / "tune"
    cmd = [sys.executable, "-m", "aolab", "tune", "--methods", "lsao", "--trials", "100000",
           "--workers", "2", "--out", str(out), "--presets-file", str(tmp_path / "p.json"),
           "--scenes", "grille", "engine", "--crop", "96x54", *COMMON]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    # A plain SQLite read while the run writes: an Optuna storage opened here sets up its
    # schema too, and racing the run's own set-up made the run fail ("UNIQUE constraint
    # failed: alembic_version.version_num").
    while time.monotonic() < deadline and proc.poll() is None:
        if trials_done(out / "tune.db") >= 2:
            break
        time.sleep(0.1)
    if proc.poll() is not None:   # it ended before the interrupt: say why
        pytest.fail(f"aolab tune ended by itself (status {proc.returncode}): "
                    f"{proc.communicate()[1][-2000:]}")
    os.kill(proc.pid, signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    assert len(complete_trials(out / "tune.db", "lsao")) >= 2
    assert not (tmp_path / "p.json").exists()   # no presets from half a search
