"""References on a Dask cluster (aolab reference --workers / --scheduler, aolab/cluster.py)
and animation frames (--frames). Blender and Dask run for real: a local cluster of 2 workers
on the loopback interface; one worker process is killed during a render, and every frame
must still arrive, bit for bit the sequential render's, with nothing partial in the cache."""
import dataclasses
import functools
import io
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import cli
from aolab.cycles import cluster
from aolab.cycles import run as cycles_run
from aolab.cycles.blender import Stopped
from aolab.cycles.cache import count_cached
from aolab.cycles.plan import make_plan, per_frame, resolve_scene
from aolab.cycles.run import Delivery
from aolab.util.arguments import MAX_FRAMES, parse_frames

from blender_support import needs_blender
from farm_support import (ANIMATION, FRAMES, blender_children_of, ctrl_c_while_rendering,
                          kill_a_worker_while_rendering)

distributed = pytest.importorskip("distributed", reason="python3-distributed is not installed "
                                  "(scripts/install-deps.sh installs it)")


def aolab_reference(*args):
    return subprocess.Popen([sys.executable, "-m", "aolab", "reference", "--quiet", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def frames_of(out: Path) -> dict:
    return {int(p.name): aolab.load_gbuffer(p / "reference.exr")
            for p in sorted((out / "frames").iterdir())}


def same_bits(a, b) -> bool:
    return all(np.array_equal(getattr(a, k), getattr(b, k), equal_nan=True)
               for k in ("depth", "normal", "reference"))


def test_frames_are_parsed_and_checked():
    assert parse_frames("3") == [3]
    assert parse_frames("1-8:3") == [1, 4, 7]
    assert parse_frames("-2-1") == [-2, -1, 0, 1]
    for bad in ("", "4-1", "1-8:0", "a", "1-2000000", "0-200000"):
        with pytest.raises(ValueError, match="--frames"):
            parse_frames(bad)


def test_a_frame_has_its_own_cache_key_and_stills_keep_theirs():
    scene = resolve_scene(str(ANIMATION))
    still = make_plan(scene, spp=4)
    framed = per_frame([still], [1, 2])
    assert [p.frame for p in framed] == [1, 2]
    keys = {still.key()} | {p.key() for p in framed}
    assert len(keys) == 3 and "-f0002-" in framed[1].key() and "-f0" not in still.key()


@needs_blender
def test_a_killed_worker_loses_no_frame_and_leaves_nothing_partial(tmp_path):
    seq = aolab_reference(str(ANIMATION), "--frames", FRAMES, "--spp", "256", "--cache",
                          str(tmp_path / "seq_cache"), "--out", str(tmp_path / "seq"))
    out, err = seq.communicate(timeout=600)
    assert seq.returncode == 0, err[-2000:]
    cache = tmp_path / "cluster_cache"
    run = aolab_reference(str(ANIMATION), "--frames", FRAMES, "--spp", "256", "--cache",
                          str(cache), "--out", str(tmp_path / "cluster"), "--workers", "2")
    killed, out, err = kill_a_worker_while_rendering(run, cache)
    assert killed is not None, "no render was caught running: " + err[-2000:]
    assert run.returncode == 0, err[-3000:]
    # The killed worker's Blender died with it; no Blender of ours is left.
    time.sleep(0.5)
    assert not blender_children_of(set(), str(cache))
    # Every frame arrived, the same bits as the sequential render.
    expected, got = frames_of(tmp_path / "seq"), frames_of(tmp_path / "cluster")
    assert sorted(got) == sorted(expected) == parse_frames(FRAMES)
    for f in expected:
        assert same_bits(expected[f], got[f]), f"frame {f}"
        assert got[f].sidecar["frame"] == f
    # Nothing partial: no temporary folder, and every entry complete.
    assert not [p.name for p in cache.iterdir() if p.name.startswith(".")]
    assert all((p / "reference.json").exists() for p in cache.iterdir())


def test_a_scheduler_that_does_not_answer_is_a_clear_error(tmp_path):
    r = subprocess.run([sys.executable, "-m", "aolab", "reference", str(ANIMATION), "--frames",
                        "1", "--cache", str(tmp_path), "--scheduler", "tcp://127.0.0.1:9"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert "--scheduler 'tcp://127.0.0.1:9'" in r.stderr and "Traceback" not in r.stderr


@needs_blender
def test_ctrl_c_stops_the_cluster_renders_and_leaves_the_cache_consistent(tmp_path):
    """Ctrl-C at a terminal sends SIGINT to the whole foreground process group: the command,
    its local workers and their Blenders. The command ends with status 130, no Blender is
    left, and the cache holds complete entries only; the same command then resumes."""
    cache = tmp_path / "cache"
    args = [sys.executable, "-m", "aolab", "reference", "--quiet", str(ANIMATION), "--frames",
            FRAMES, "--spp", "1024", "--cache", str(cache), "--workers", "2"]
    run, out, err = ctrl_c_while_rendering(args, cache)
    assert run.returncode == 130, err[-2000:]
    assert "interrupted" in err and "Traceback" not in err
    time.sleep(1.0)
    assert not blender_children_of(set(), str(cache))
    assert not [p.name for p in cache.iterdir() if p.name.startswith(".")]
    assert all((p / "reference.json").exists() for p in cache.iterdir())
    # Resume: the same command finishes what is missing.
    again = subprocess.run(args[:args.index("--spp") + 1] + ["64"] + args[args.index("--spp") + 2:],
                           capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr[-2000:]


# --- many frames, without Blender ------------------------------------------------------
MANY = "1-20000"


def write_entry(cache: Path, plan) -> Path:
    """A complete cache entry for ``plan``, put in place as render does (renamed)."""
    tmp = cache / f".{plan.key()}.tmp-{os.getpid()}"
    tmp.mkdir(parents=True)
    *images, sidecar = plan.result_files(tmp)
    for f in images:
        f.write_bytes(b"fake")
    sidecar.write_text('{"scene_hash": "fake"}')
    os.replace(tmp, cache / plan.key())
    return cache / plan.key()


def test_an_interrupted_sequence_counts_the_frames_in_the_cache(monkeypatch, tmp_path, capsys):
    """Without --workers, frames render one after another: frames 1-3 are printed, frame 4 is
    interrupted once its entry is in place but before its line, and frames 19991-20000 were
    rendered by an earlier run: 3 done, 14 in the cache."""
    cache = tmp_path / "cache"
    cache.mkdir()
    scene = resolve_scene(str(ANIMATION))
    for plan in per_frame([make_plan(scene, spp=1)], range(19991, 20001)):
        write_entry(cache, plan)

    def render(plan, cache, *, force=False, progress=True, blender=None, should_stop=None):
        folder = write_entry(Path(cache), plan)
        if plan.frame == 4:
            raise KeyboardInterrupt
        return folder, False

    monkeypatch.setattr(cycles_run, "render", render)
    assert cli.main(["reference", str(ANIMATION), "--frames", MANY, "--spp", "1",
                     "--cache", str(cache), "--quiet"]) == 130
    out, err = capsys.readouterr()
    assert [line.split(":")[0] for line in out.splitlines()] == \
        [f"tiny_animation frame {f}" for f in (1, 2, 3)]
    assert "interrupted after 3 of 20000 frames (14 in the cache); run the same command " \
        "again to resume" in err


def test_too_many_references_are_refused_before_any_is_planned(tmp_path):
    """--frames takes at most MAX_FRAMES frames, and so does one command in all: two scenes
    of MAX_FRAMES frames each are refused in one line, with nothing rendered."""
    top = MAX_FRAMES
    assert len(parse_frames(f"1-{top}")) == top
    with pytest.raises(ValueError, match="--frames"):
        parse_frames(f"1-{top + 1}")
    copy = tmp_path / "other.py"
    copy.write_text(ANIMATION.read_text())
    r = subprocess.run([sys.executable, "-m", "aolab", "reference", str(ANIMATION), str(copy),
                        "--frames", f"1-{top}", "--cache", str(tmp_path / "cache"), "--workers",
                        "2"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and f"more than {top} references" in r.stderr, r.stderr
    assert not (tmp_path / "cache").exists()


# --- many frames on a cluster: the submission window and the interrupt's count ------------
# A real local cluster runs cluster.render_job; only cycles_run.render is replaced on its
# workers, by one that finishes at once or, past ``fast_until``, renders until told to stop.

def fake_render(plan, cache, *, force=False, progress=True, blender=None, should_stop=None,
                fast_until=0):
    if plan.frame > fast_until:   # a long render: until the stop event is set
        while not should_stop():
            time.sleep(0.05)
        raise Stopped(f"{plan.scene.name}: stopped")
    return write_entry(Path(cache), plan), False


def install_fake_render(fast_until: int) -> None:
    cycles_run.render = functools.partial(fake_render, fast_until=fast_until)


class InterruptingStdout(io.StringIO):
    """stdout that counts the result lines and raises KeyboardInterrupt, as Ctrl-C would, when
    the ``interrupt_at``-th is written."""

    def __init__(self, interrupt_at: int):
        super().__init__()
        self.lines, self.interrupt_at = 0, interrupt_at

    def write(self, text):
        n = super().write(text)
        self.lines += text.count("\n")
        if self.lines == self.interrupt_at and text.endswith("\n"):
            raise KeyboardInterrupt
        return n


def run_many(monkeypatch, tmp_path, fast_until: int, interrupt_at: int):
    """cluster.run_plans over MANY frames of the tiny animation on 2 local workers; returns
    (status, stdout, submissions, plans), each submission (jobs submitted, result lines
    printed)."""
    plans = per_frame([make_plan(resolve_scene(str(ANIMATION)), spp=1)], parse_frames(MANY))
    submissions, stdout = [], InterruptingStdout(interrupt_at)
    real_connect = cluster.connect

    def connect(scheduler, workers, security=None):
        client, local = real_connect(scheduler, workers, security)
        client.run(install_fake_render, fast_until)
        submit = client.submit

        def counted(*a, **k):
            submissions.append((len(submissions) + 1, stdout.lines))
            return submit(*a, **k)

        client.submit = counted
        return client, local

    monkeypatch.setattr(cluster, "connect", connect)
    monkeypatch.setattr(sys, "stdout", stdout)
    delivery = Delivery(cache=str(tmp_path / "cache"), quiet=True)
    # Should the run not reach its interrupt, a real SIGINT ends it and the asserts say so.
    watchdog = threading.Timer(60, os.kill, (os.getpid(), signal.SIGINT))
    watchdog.start()
    try:
        status = cluster.run_plans(plans, delivery, workers=2)
    finally:
        watchdog.cancel()
    return status, stdout.getvalue(), submissions, plans


def test_many_frames_are_submitted_a_window_at_a_time(monkeypatch, tmp_path, capsys):
    status, out, submissions, plans = run_many(monkeypatch, tmp_path, fast_until=20000,
                                               interrupt_at=60)
    assert status == 130
    window = cluster.window(2)
    assert window < 100
    # Never more jobs in flight (submitted, their line not printed) than the window ...
    assert max(n - lines for n, lines in submissions) <= window
    # ... so results were collected long before every job was submitted: the first line came
    # when one window was out, and the interrupt found few of the 20000 ever submitted.
    first = next(n for n, lines in submissions if lines > 0)
    assert first <= window + 1
    assert len(submissions) <= 60 + window
    assert out.count(" frame ") == 60
    err = capsys.readouterr().err
    counts = re.search(r"interrupted after (\d+) of 20000 frames \((\d+) in the cache\)", err)
    assert counts, err
    done, in_cache = map(int, counts.groups())
    assert 60 <= done <= in_cache <= len(submissions), err


def test_the_interrupt_counts_the_frames_in_the_cache(monkeypatch, tmp_path, capsys):
    """Frames 1-5 finish at once, later ones render until stopped; frames 19991-20000 were
    rendered by an earlier run. Interrupted once the 5th is printed, the command counts the
    5 it finished and the 15 in the cache, and stops the renders still running."""
    cache = tmp_path / "cache"
    cache.mkdir()
    scene = resolve_scene(str(ANIMATION))
    for plan in per_frame([make_plan(scene, spp=1)], range(19991, 20001)):
        write_entry(cache, plan)
    status, out, submissions, plans = run_many(monkeypatch, tmp_path, fast_until=5,
                                               interrupt_at=5)
    err = capsys.readouterr().err
    assert status == 130
    assert "interrupted after 5 of 20000 frames (15 in the cache)" in err
    assert "run the same command again to resume" in err
    assert sorted(int(line.split(" frame ")[1].split(":")[0]) for line in out.splitlines()) \
        == [1, 2, 3, 4, 5]
    assert count_cached(cache, plans) == 15
    assert not [p.name for p in cache.iterdir() if p.name.startswith(".")]


def test_a_cached_job_returns_at_once_from_its_worker(tmp_path):
    """A job whose entry is in the cache answers without a client of the scheduler (here: it
    runs outside any worker, where making one would fail), so a resume costs no connection
    per frame."""
    scene = resolve_scene(str(ANIMATION))
    plan = per_frame([make_plan(scene, spp=1)], [7])[0]
    write_entry(tmp_path, plan)
    result = cluster.render_job(plan, str(tmp_path), False, "aolab-stop-unused")
    assert result["cached"] is True and result["folder"] == str(tmp_path / plan.key())
    with pytest.raises(ValueError, match="[Nn]o worker"):   # not cached: it needs a worker
        cluster.render_job(dataclasses.replace(plan, frame=8), str(tmp_path), False, "unused")
