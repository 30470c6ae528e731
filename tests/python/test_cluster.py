"""References on a Dask cluster (aolab reference --workers / --scheduler, aolab/cluster.py)
and animation frames (--frames). Blender and Dask run for real: a local cluster of 2 workers
on the loopback interface; one worker process is killed during a render, and every frame
must still arrive, bit for bit the sequential render's, with nothing partial in the cache."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import reference

from test_bridge import ROOT, needs_blender

ANIMATION = ROOT / "tests" / "data" / "tiny_animation.py"
FRAMES = "1-4"
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
    assert reference.parse_frames("3") == [3]
    assert reference.parse_frames("1-8:3") == [1, 4, 7]
    assert reference.parse_frames("-2-1") == [-2, -1, 0, 1]
    for bad in ("", "4-1", "1-8:0", "a", "1-2000000", "0-200000"):
        with pytest.raises(ValueError, match="--frames"):
            reference.parse_frames(bad)


def test_a_frame_has_its_own_cache_key_and_stills_keep_theirs():
    scene = reference.resolve_scene(str(ANIMATION))
    still = reference.make_plan(scene, spp=4)
    framed = reference.per_frame([still], [1, 2])
    assert [p.frame for p in framed] == [1, 2]
    keys = {still.key()} | {p.key() for p in framed}
    assert len(keys) == 3 and "-f0002-" in framed[1].key() and "-f0" not in still.key()


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


@needs_blender
def test_a_killed_worker_loses_no_frame_and_leaves_nothing_partial(tmp_path):
    seq = aolab_reference(str(ANIMATION), "--frames", FRAMES, "--spp", "256", "--cache",
                          str(tmp_path / "seq_cache"), "--out", str(tmp_path / "seq"))
    out, err = seq.communicate(timeout=600)
    assert seq.returncode == 0, err[-2000:]
    cache = tmp_path / "cluster_cache"
    run = aolab_reference(str(ANIMATION), "--frames", FRAMES, "--spp", "256", "--cache",
                          str(cache), "--out", str(tmp_path / "cluster"), "--workers", "2")
    killed = None
    try:
        # Wait for a Blender rendering into our cache, and kill its worker process (SIGKILL:
        # no clean-up of any kind, as when a machine goes away).
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
    assert killed is not None, "no render was caught running: " + err[-2000:]
    assert run.returncode == 0, err[-3000:]
    # The killed worker's Blender died with it; no Blender of ours is left.
    time.sleep(0.5)
    assert not blender_children_of(set(), str(cache))
    # Every frame arrived, the same bits as the sequential render.
    expected, got = frames_of(tmp_path / "seq"), frames_of(tmp_path / "cluster")
    assert sorted(got) == sorted(expected) == reference.parse_frames(FRAMES)
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
    assert "--scheduler tcp://127.0.0.1:9" in r.stderr and "Traceback" not in r.stderr


@needs_blender
def test_ctrl_c_stops_the_cluster_renders_and_leaves_the_cache_consistent(tmp_path):
    """Ctrl-C at a terminal sends SIGINT to the whole foreground process group: the command,
    its local workers and their Blenders. The command ends with status 130, no Blender is
    left, and the cache holds complete entries only; the same command then resumes."""
    cache = tmp_path / "cache"
    args = [sys.executable, "-m", "aolab", "reference", "--quiet", str(ANIMATION), "--frames",
            FRAMES, "--spp", "1024", "--cache", str(cache), "--workers", "2"]
    run = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           start_new_session=True)
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
