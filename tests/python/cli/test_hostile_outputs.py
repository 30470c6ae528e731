"""Hostile inputs must never lose results: an interrupted `aolab compare` keeps the complete
results of an earlier run, an output folder that cannot be made is refused before any work,
`aolab reference --resolution` is bounded, and VAO / VAO++ stay stable up to the largest
accepted radius (docs/conventions.md, "Output folders" and "Radius: where each method is
stable")."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import cli
from aolab.study import compare, output, report_files
from aolab.util.arguments import check_resolution, parse_resolution
from hostile_support import FILES, compare_cli, small_scenes, snapshot


def names_found(out: Path) -> bool:
    """Whether every file that out/report.html names is there."""
    html = (out / "report.html").read_text(encoding="utf-8")
    return all((out / name).is_file() for name in report_files.referenced(html))


# ---------------------------------------------------------------------------------------
# aolab compare: staging folder and swap


def test_an_interrupted_rerun_keeps_the_complete_results(tmp_path, monkeypatch, capsys):
    scenes = small_scenes(tmp_path / "scenes")
    out, staging = tmp_path / "out", tmp_path / "out.partial"
    assert compare_cli(scenes, out) == 0
    assert sorted(p.name for p in out.iterdir()) == FILES and not staging.exists()
    (out / "notes.txt").write_text("mine")   # the user's own file in the output folder
    complete = snapshot(out)
    assert json.loads(complete["results.json"])["meta"]["partial"] is False

    real = compare.Study._run_config

    def interrupting(self, scene, *a, **k):
        if scene.name == "beta":   # alpha completes, beta is interrupted
            raise KeyboardInterrupt
        return real(self, scene, *a, **k)

    monkeypatch.setattr(compare.Study, "_run_config", interrupting)
    capsys.readouterr()
    assert compare_cli(scenes, out) == 130
    err = capsys.readouterr().err
    assert f"are in {staging}/" in err and f"earlier run in {out}/ are untouched" in err
    assert snapshot(out) == complete                  # the complete results, byte for byte
    partial = json.loads((staging / "results.json").read_text())
    assert partial["meta"]["partial"] is True and partial["meta"]["complete_scenes"] == ["alpha"]
    assert "PARTIAL results" in (staging / "report.html").read_text(encoding="utf-8")

    monkeypatch.setattr(compare.Study, "_run_config", real)
    assert compare_cli(scenes, out) == 0              # a complete run replaces them
    assert not staging.exists()
    assert sorted(p.name for p in out.iterdir()) == sorted(FILES + ["notes.txt"])
    assert (out / "notes.txt").read_text() == "mine"
    data = json.loads((out / "results.json").read_text())
    assert data["meta"]["partial"] is False and data["meta"]["complete_scenes"] == ["alpha",
                                                                                    "beta"]


def test_a_failing_scene_leaves_the_complete_results(tmp_path, monkeypatch):
    """Not only Ctrl-C: an error in the middle of the study does not touch <out> either."""
    scenes = small_scenes(tmp_path / "scenes")
    out = tmp_path / "out"
    assert compare_cli(scenes, out) == 0
    complete = snapshot(out)

    real = compare.Study._run_scene

    def failing(self, folder, *a, **k):
        if folder.name == "beta":   # after alpha is complete
            raise MemoryError("out of memory")
        return real(self, folder, *a, **k)

    monkeypatch.setattr(compare.Study, "_run_scene", failing)
    assert compare_cli(scenes, out) == 2
    assert snapshot(out) == complete
    partial = json.loads((tmp_path / "out.partial" / "results.json").read_text())
    assert partial["meta"]["complete_scenes"] == ["alpha"]


def test_an_interrupt_while_publishing_finishes_the_publish(tmp_path, monkeypatch, capsys):
    scenes = small_scenes(tmp_path / "scenes")
    out = tmp_path / "out"
    real = compare.Study.publish

    def interrupted(self):   # Ctrl-C after the first file was moved
        if not (out / "results.csv").exists():   # (out exists: the run's lock is in it)
            (self.staging / "results.csv").replace(out / "results.csv")
            raise KeyboardInterrupt
        return real(self)

    monkeypatch.setattr(compare.Study, "publish", interrupted)
    assert compare_cli(scenes, out) == 130
    assert "after the study was complete" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == FILES
    assert not (tmp_path / "out.partial").exists()
    assert json.loads((out / "results.json").read_text())["meta"]["partial"] is False


def test_a_new_report_never_leaves_the_one_in_place_without_its_files(tmp_path, monkeypatch):
    """report_files/ is published file by file: while the new files move in, the earlier
    report.html still finds all of its own (a name holds one content); once the new page is
    in, the files only the earlier one named are removed."""
    scenes = small_scenes(tmp_path / "scenes", names=("alpha",))
    out = tmp_path / "out"
    assert compare_cli(scenes, out, "lsao") == 0 and names_found(out)
    before = report_files.referenced((out / "report.html").read_text(encoding="utf-8"))
    seen = []
    real = report_files.move_in

    def checking(staging, dest):
        real(staging, dest)
        seen.append(names_found(dest))   # the earlier page, beside the new files

    monkeypatch.setattr(report_files, "move_in", checking)
    assert compare_cli(scenes, out, "hbao") == 0
    assert seen == [True] and names_found(out)
    after = report_files.referenced((out / "report.html").read_text(encoding="utf-8"))
    assert before - after   # lsao's images are gone from the page ...
    assert {f"report_files/{p.name}" for p in (out / "report_files").iterdir()} == after


def test_the_staging_folder_sits_beside_the_output_folder():
    assert output.staging_folder(Path("out/compare")) == Path("out/compare.partial")
    assert output.staging_folder(Path("/tmp/x/")) == Path("/tmp/x.partial")
    assert output.staging_folder(Path(".")).name == Path.cwd().name + ".partial"


@pytest.mark.parametrize("where", ["file", "file/sub", "file/sub/deeper", "staging"])
def test_out_under_an_existing_file_is_refused_before_any_work(tmp_path, capsys, where):
    scenes = small_scenes(tmp_path / "scenes", names=("alpha",))
    (tmp_path / "file").write_text("not a folder")
    (tmp_path / "x.partial").write_text("not a folder")
    out = tmp_path / ("x" if where == "staging" else where)
    assert compare_cli(scenes, out) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"aolab: --out must be a folder, got {str(out)!r}")
    assert "is an existing file, not a folder" in err
    with pytest.raises(ValueError, match="--out must be a folder"):
        output.check_out(out)
    assert (tmp_path / "file").read_text() == "not a folder"


# ---------------------------------------------------------------------------------------
# aolab reference --resolution


@pytest.mark.parametrize("text", ["0x0", "0x720", "1280x0", "100000x100000", "16385x4",
                                  "-5x5", "abc", "1280x", "1280x720x3", "1.5x2", "１２x３",
                                  "1x1", "3x720", "1280x3"])
def test_reference_resolution_out_of_range_is_refused(text, capsys):
    with pytest.raises(ValueError, match=r"--resolution must be WxH with integers in "
                                         r"\[4, 16384\] \(Blender renders at least 4x4\), got " +
                                         repr(text).replace(".", r"\.")):
        parse_resolution(text)
    # the command refuses it before looking for Blender or the scene
    assert cli.main(["reference", "no_such_scene", f"--resolution={text}"]) == 2
    assert "--resolution must be WxH" in capsys.readouterr().err


def test_reference_resolution_in_range_is_accepted():
    assert parse_resolution("4x4") == (4, 4)
    assert parse_resolution("16384X16384") == (16384, 16384)
    assert parse_resolution(" 1280x720 ") == (1280, 720)
    assert check_resolution([640, 360]) == (640, 360)
    for bad in ([0, 0], (3, 4), (100000, 100000), (1.5, 2), ("a", 1), (1,), None, (True, 1)):
        with pytest.raises(ValueError, match="resolution must be a width and a height"):
            check_resolution(bad)


# ---------------------------------------------------------------------------------------
# VAO and VAO++ at the largest radii


def convex_room(width=96, height=54, fov_deg=100.0):
    """A convex room around the camera (tests/cpp/methods/vao/convex_room.h): planes
    n·X >= c with inward normals; the left wall turns away from the view axis (n.z < 0), the
    only kind of surface whose VAO tangent sphere stays in front of the camera as R grows."""
    planes = [((1.0, 0.0, -0.5), -1.5), ((0.0, 1.0, 0.0), -1.0), ((-1.0, 0.0, 0.0), -2.0),
              ((0.0, -1.0, 0.0), -1.5), ((0.0, 0.0, 1.0), -8.0)]
    f = width / 2 / np.tan(np.radians(fov_deg) / 2)
    i, j = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    v = np.stack([(i - width / 2) / f, -(j - height / 2) / f, -np.ones_like(i)], axis=-1)
    depth = np.full((height, width), np.inf)
    normal = np.zeros((height, width, 3))
    for n, c in planes:
        n = np.asarray(n) / np.linalg.norm(n)
        nv = v @ n
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(nv < 0, c / nv, np.inf)
        closer = t < depth
        depth[closer], normal[closer] = t[closer], n
    return aolab.GBuffer(depth.astype(np.float32), normal.astype(np.float32), fx=f, fy=f,
                         cx=width / 2, cy=height / 2)


@pytest.mark.parametrize("method,settings", [
    ("vao", {}), ("vao", {"view_ray_pipes": False}), ("vao_pp", {}),
    ("vao_pp", {"range_check": True})])
def test_vao_is_stable_up_to_the_largest_radius(method, settings):
    """Beyond the scene's extent (depths 1.5 to 8) a larger R cannot change the occlusion.
    Before the fix VAO's mean drifted from 0.90 (R up to 1e19) to 0.99 at 1e20 and 1 at 1e22."""
    g = convex_room()
    valid = g.valid_mask()
    largest = next(s["max"] for s in aolab.method_info(method)["settings"]
                   if s["name"] == "radius")

    def mean(radius):
        return float(np.asarray(aolab.compute(method, g, radius=radius, threads=2,
                                              **settings))[valid].mean())

    at_scale = mean(8e6)
    assert at_scale < 0.999   # the turned-away wall sees occlusion: the test means something
    for radius in (1e19, 1e20, 1e25, largest):
        assert mean(radius) == pytest.approx(at_scale, abs=1e-3), radius
