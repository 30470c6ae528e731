"""Files (aolab.util.files, core/io/files.h; docs/conventions.md, "Files"): every write is durable
and atomic, so a full disk is an error that keeps the earlier file and leaves no temporary;
every read checks for a regular file first, so a FIFO never hangs a command; an output
folder is owned by one run at a time.

The full-disk tests run on a 2 MiB tmpfs mounted for the test, filled to its last byte: the
real ENOSPC of a full disk. Mounting needs root; elsewhere they are skipped with the reason."""
from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import cli
from aolab.util import files
from aolab.cycles.run import copy_result

from hostile_support import FILES, compare_cli, small_scenes, snapshot


def aolab_cmd(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "aolab", *args], capture_output=True,
                          text=True, timeout=timeout)


def one_line_error(res, *fragments) -> str:
    """The command failed with status 2 and a single stderr line containing ``fragments``."""
    assert res.returncode == 2, res.stdout + res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("aolab: "), res.stderr
    for f in fragments:
        assert f in lines[0], lines[0]
    return lines[0]


def fill(mount: Path) -> None:
    """Fills the file system of ``mount`` to its last byte (a file named filler)."""
    fd = os.open(mount / "filler", os.O_WRONLY | os.O_CREAT | os.O_APPEND)
    try:
        for size in (1 << 16, 4096, 1):
            try:
                while True:
                    os.write(fd, b"x" * size)
            except OSError:
                pass
    finally:
        os.close(fd)


@pytest.fixture
def full_disk(tmp_path):
    """A mounted 2 MiB tmpfs (the folder); fill(folder) fills it to the last byte."""
    mount = tmp_path / "small"
    mount.mkdir()
    res = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(mount)],
                         capture_output=True, text=True)
    if res.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs for the full-disk test (needs root): "
                    f"{res.stderr.strip()}")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=False)


def names(folder: Path) -> set[str]:
    return {p.name for p in folder.iterdir()}


# --- writes ------------------------------------------------------------------------------

def test_writes_replace_whole_files_and_leave_no_temporary(tmp_path):
    files.write_text(tmp_path / "a.txt", "first")
    files.write_bytes(tmp_path / "a.txt", b"second")
    files.write_together([(tmp_path / "b.bin", b"\0\1"), (tmp_path / "c.txt", b"c")])
    assert (tmp_path / "a.txt").read_text() == "second"
    assert names(tmp_path) == {"a.txt", "b.bin", "c.txt"}
    with pytest.raises(FileNotFoundError, match="output directory not found"):
        files.write_text(tmp_path / "missing" / "a.txt", "x")
    with pytest.raises(ValueError, match="not a regular file"):
        files.write_text(tmp_path, "x")


def test_a_full_disk_is_an_oserror_that_keeps_the_earlier_files(full_disk):
    files.write_text(full_disk / "a.txt", "good")
    aolab.write_image(full_disk / "ao.exr", np.full((32, 32), 0.5, np.float32))
    before = snapshot(full_disk)
    fill(full_disk)
    before["filler"] = (full_disk / "filler").read_bytes()
    big = np.random.default_rng(1).random((512, 512), dtype=np.float32)
    with pytest.raises(OSError, match="No space left on device") as e:
        files.write_text(full_disk / "a.txt", "x" * 100000)
    assert e.value.errno == 28
    with pytest.raises(OSError, match="No space left on device"):
        aolab.write_image(full_disk / "ao.exr", big)
    with pytest.raises(OSError, match="No space left on device"):
        files.write_together([(full_disk / "new.txt", b"n"), (full_disk / "a.txt", b"y" * 99999)])
    assert snapshot(full_disk) == before   # nothing replaced, nothing new, no temporary


def test_run_and_rtao_on_a_full_disk_exit_2_and_keep_the_earlier_result(tmp_path, full_disk):
    g = tmp_path / "wall.exr"
    assert aolab_cmd("analytic", "wall", str(g), "--radius", "2", "--width", "96",
                     "--height", "54").returncode == 0
    for command in (["run", "hbao"], ["rtao", "--rays", "4"]):
        stem = full_disk / command[0]
        args = [*command, str(g if command[0] == "run" else "analytic:wall"), "--out", str(stem)]
        if command[0] == "rtao":
            args += ["--radius", "2", "--width", "96", "--height", "54"]
        assert aolab_cmd(*args).returncode == 0
        before = snapshot(full_disk)
        fill(full_disk)
        before["filler"] = (full_disk / "filler").read_bytes()
        res = aolab_cmd(*args, "--json", str(full_disk / f"{command[0]}.json"))
        one_line_error(res, "No space left on device")
        assert snapshot(full_disk) == before
        (full_disk / "filler").unlink()


def test_a_reference_copied_out_on_a_full_disk_leaves_nothing_half_written(tmp_path, full_disk):
    cached = tmp_path / "cached"
    cached.mkdir()
    for name in ("reference.exr", "reference.json"):
        (cached / name).write_bytes(os.urandom(600_000))

    class Plan:
        @staticmethod
        def result_files(folder):
            return [folder / "reference.exr", folder / "reference.json"]

    out = full_disk / "out"
    copy_result(Plan, cached, out)
    (out / "reference.json").write_bytes(b"{}")   # an earlier result, smaller
    before = snapshot(out)
    fill(full_disk)
    with pytest.raises(OSError, match="No space left on device"):
        copy_result(Plan, cached, out)
    assert snapshot(out) == before


# --- reads -------------------------------------------------------------------------------

@pytest.mark.parametrize("make", [
    lambda d: d / "fifo.blend", lambda d: d / "fifo.py", lambda d: d / "scene" / "build.py",
    lambda d: d / "scene" / "manifest.json"])
@pytest.mark.parametrize("command", [["reference", "--spp", "4"], ["mesh"],
                                     ["reference", "--spp", "4", "--frames", "1-2",
                                      "--workers", "2"]])
def test_a_fifo_as_scene_is_refused_at_once(tmp_path, make, command):
    """Hashing the scene's files would block forever on a FIFO: refused before Blender is
    even looked for (timeout 60 s; it answers in about a second)."""
    fifo = make(tmp_path)
    fifo.parent.mkdir(exist_ok=True)
    if fifo.parent.name == "scene":
        for name in ("build.py", "manifest.json"):
            (fifo.parent / name).write_text("{}" if name.endswith(".json") else "")
        fifo.unlink()
        spec = fifo.parent
    else:
        spec = fifo
    os.mkfifo(fifo)
    res = aolab_cmd(*command, str(spec), "--cache", str(tmp_path / "cache"))
    one_line_error(res, "a FIFO (named pipe)", str(fifo))


def test_regular_file_names_what_is_there(tmp_path):
    os.mkfifo(tmp_path / "f")
    with pytest.raises(ValueError, match="mesh must be a regular file, got .*a FIFO"):
        files.read_bytes(tmp_path / "f", "mesh")
    with pytest.raises(ValueError, match="which is a folder"):
        files.regular_file(tmp_path, "scene")
    with pytest.raises(FileNotFoundError, match="no such scene file"):
        files.regular_file(tmp_path / "none", "scene")


# --- output folders ----------------------------------------------------------------------

def test_a_second_compare_into_a_held_folder_is_refused_and_changes_nothing(tmp_path, capsys):
    scenes = small_scenes(tmp_path / "scenes")
    out = tmp_path / "out"
    assert compare_cli(scenes, out) == 0
    complete = snapshot(out)
    with files.output_lock(out, "aolab compare (test)"):
        assert compare_cli(scenes, out) == 2
        err = capsys.readouterr().err
        assert "output folder in use by aolab compare (test)" in err
        assert len(err.strip().splitlines()) == 1
        assert not (tmp_path / "out.partial").exists()
    assert snapshot(out) == complete                       # the lock file is gone again
    assert sorted(p.name for p in out.iterdir()) == FILES


def test_two_compare_processes_into_one_folder_never_mix(tmp_path):
    """The issue's case: A (hbao) and B (sao) into one --out at the same time. One of them is
    refused (status 2, naming the holder) or they run one after the other; either way
    results.csv and results.json come from the same run."""
    scenes = small_scenes(tmp_path / "scenes")
    out = tmp_path / "cc"
    runs = [subprocess.Popen([sys.executable, "-m", "aolab", "compare", "--scenes-dir",
                              str(scenes), "--out", str(out), "--methods", m, "--repeat", "1",
                              "--warmup", "0", "--no-progress"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True) for m in ("hbao", "sao")]
    results = [(p.wait(timeout=300), p.stderr.read()) for p in runs]
    assert any(rc == 0 for rc, _ in results), results
    for rc, err in results:
        assert rc == 0 or (rc == 2 and "output folder in use" in err), err
    data = json.loads((out / "results.json").read_text())
    with open(out / "results.csv", newline="") as f:
        csv_methods = {r["method"] for r in csv.DictReader(f) if r["kind"] == "method"}
    assert csv_methods == set(data["meta"]["methods"])


def test_a_lock_left_by_a_killed_run_is_no_obstacle(tmp_path):
    """flock ends with its process: a run killed with SIGKILL leaves the file, not the lock."""
    out = tmp_path / "out"
    code = ("import sys, time; from aolab.util import files\n"
            "with files.output_lock(sys.argv[1], 'killed run'):\n"
            "    print('held', flush=True); time.sleep(60)\n")
    p = subprocess.Popen([sys.executable, "-c", code, str(out)], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "held"
    with pytest.raises(files.FolderInUse, match="killed run"):
        with files.output_lock(out, "second"):
            pass
    p.kill()
    p.wait()
    with files.output_lock(out, "third"):
        assert (out / files.LOCK_NAME).read_text().startswith("third")
    assert not (out / files.LOCK_NAME).exists()


def test_a_failed_run_leaves_no_folder_it_made(tmp_path):
    out = tmp_path / "new" / "out"
    with pytest.raises(RuntimeError):
        with files.output_lock(out, "failing"):
            raise RuntimeError("boom")
    assert not out.exists()


def test_error_line_of_a_busy_folder(tmp_path):
    with files.output_lock(tmp_path / "o", "holder"):
        with pytest.raises(OSError) as e:
            with files.output_lock(tmp_path / "o", "second"):
                pass
    assert cli.error_message(e.value).startswith("output folder in use by holder (pid ")
