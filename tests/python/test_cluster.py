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
from aolab import cli, reference

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
    scene = reference.resolve_scene(str(ANIMATION))
    for plan in reference.per_frame([reference.make_plan(scene, spp=1)], range(19991, 20001)):
        write_entry(cache, plan)

    def render(plan, cache, *, force=False, progress=True, blender=None, should_stop=None):
        folder = write_entry(Path(cache), plan)
        if plan.frame == 4:
            raise KeyboardInterrupt
        return folder, False

    monkeypatch.setattr(reference, "render", render)
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
    top = reference.MAX_FRAMES
    assert len(reference.parse_frames(f"1-{top}")) == top
    with pytest.raises(ValueError, match="--frames"):
        reference.parse_frames(f"1-{top + 1}")
    copy = tmp_path / "other.py"
    copy.write_text(ANIMATION.read_text())
    r = subprocess.run([sys.executable, "-m", "aolab", "reference", str(ANIMATION), str(copy),
                        "--frames", f"1-{top}", "--cache", str(tmp_path / "cache"), "--workers",
                        "2"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and f"more than {top} references" in r.stderr, r.stderr
    assert not (tmp_path / "cache").exists()
