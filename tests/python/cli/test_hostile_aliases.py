"""No output aliases an input or another output: every command compares the real paths (after
symbolic links) of the files it reads and of every file it writes before any work, and refuses
a match with one line naming both, exit status 2, the user's files unchanged
(docs/conventions.md, "Files")."""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import cli
from aolab.bridge.outputs import check_export, export_files
from aolab.checks import rtao_check
from aolab.util import files

SMALL = 16


def gbuffer(path: Path, mesh: bool = False) -> Path:
    """A 16x16 analytic G-buffer with its sidecar (R 0.25) at ``path``, and with ``mesh``
    some bytes as ``<stem>.mesh`` and ``<stem>.mesh.json`` (never read: the check comes
    first)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    g = aolab.analytic_scene("blocks", SMALL, SMALL, radius=0.25)
    ref = np.nan_to_num(np.asarray(g.reference, np.float32), nan=1.0)
    aolab.save_gbuffer(path, g, reference=ref, sidecar={"ao_distance": 0.25})
    if mesh:
        path.with_suffix(".mesh").write_bytes(b"triangles")
        path.with_suffix(".mesh.json").write_text("{}")
    return path


def snapshot(folder: Path) -> dict:
    """Every file below ``folder``: relative path -> bytes (a symlink as its target)."""
    return {str(p.relative_to(folder)): (os.readlink(p) if p.is_symlink() else p.read_bytes())
            for p in sorted(folder.rglob("*")) if p.is_file() or p.is_symlink()}


def refused(argv: list[str], folder: Path, capsys, message: str) -> None:
    """``aolab argv`` run in ``folder`` exits with 2 and the one line ``aolab: message``,
    and leaves every file of ``folder`` as it was (none added, none changed)."""
    before = snapshot(folder)
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        capsys.readouterr()
        status = cli.main(argv)
    finally:
        os.chdir(cwd)
    err = capsys.readouterr().err
    assert status == 2, err
    assert err == f"aolab: {message}\n"
    assert snapshot(folder) == before


OVERWRITE = "an output would overwrite an input"


# --- aolab run ------------------------------------------------------------------------------

def test_run_out_that_is_the_input_is_refused(tmp_path, capsys):
    gbuffer(tmp_path / "in.exr")
    refused(["run", "sao", "in.exr", "--out", "in"], tmp_path, capsys,
            f"--out's in.exr is the input in.exr: {OVERWRITE}")


def test_run_json_that_is_the_input_sidecar_is_refused(tmp_path, capsys):
    gbuffer(tmp_path / "in.exr")
    refused(["run", "sao", "in.exr", "--json", "in.json"], tmp_path, capsys,
            f"--json in.json is the input's sidecar in.json: {OVERWRITE}")


def test_run_json_that_is_an_out_file_is_refused(tmp_path, capsys):
    gbuffer(tmp_path / "in.exr")
    refused(["run", "sao", "in.exr", "--out", "y", "--json", "y.exr"], tmp_path, capsys,
            "--json y.exr is also written as --out's y.exr")
    (tmp_path / "sub").mkdir()
    refused(["run", "sao", "analytic:blocks", "--width", "8", "--height", "8", "--out",
             "sub/y.png", "--json", "sub/y.png"], tmp_path, capsys,
            "--json sub/y.png is also written as --out's sub/y.png")


def test_run_out_that_is_a_symlink_to_the_input_is_refused(tmp_path, capsys):
    gbuffer(tmp_path / "in.exr")
    (tmp_path / "link.exr").symlink_to("in.exr")
    refused(["run", "sao", "in.exr", "--out", "link"], tmp_path, capsys,
            f"--out's link.exr is the input in.exr: {OVERWRITE}")
    (tmp_path / "side.json").symlink_to(tmp_path / "in.json")
    refused(["run", "sao", "in.exr", "--json", "side.json"], tmp_path, capsys,
            f"--json side.json is the input's sidecar in.json: {OVERWRITE}")


def test_run_input_through_a_symlinked_folder_is_found(tmp_path, capsys):
    gbuffer(tmp_path / "in.exr")
    (tmp_path / "same").symlink_to(tmp_path, target_is_directory=True)
    refused(["run", "sao", "same/in.exr", "--out", "in"], tmp_path, capsys,
            f"--out's in.exr is the input same/in.exr: {OVERWRITE}")


def test_run_with_distinct_outputs_still_writes(tmp_path, capsys):
    gbuffer(tmp_path / "in.exr")
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        assert cli.main(["run", "sao", "in.exr", "--out", "new/ao", "--json", "ao.json",
                         "--threads", "1"]) == 0
    finally:
        os.chdir(cwd)
    assert (tmp_path / "new" / "ao.exr").is_file() and (tmp_path / "new" / "ao.png").is_file()
    assert json.loads((tmp_path / "ao.json").read_text())["method"] == "sao"


# --- aolab rtao -----------------------------------------------------------------------------

def test_rtao_out_that_is_the_reference_is_refused(tmp_path, capsys):
    gbuffer(tmp_path / "reference.exr", mesh=True)
    refused(["rtao", "reference.exr", "--rays", "4", "--out", "reference"], tmp_path, capsys,
            f"--out's reference.exr is the input reference.exr: {OVERWRITE}")


def test_rtao_json_that_is_the_mesh_is_refused(tmp_path, capsys):
    gbuffer(tmp_path / "reference.exr", mesh=True)
    refused(["rtao", "reference.exr", "--rays", "4", "--json", "reference.mesh"], tmp_path,
            capsys, f"--json reference.mesh is the input's mesh reference.mesh: {OVERWRITE}")
    refused(["rtao", "reference.exr", "--rays", "4", "--json", "reference.mesh.json"],
            tmp_path, capsys, "--json reference.mesh.json is the input's mesh's JSON "
            f"reference.mesh.json: {OVERWRITE}")


def test_rtao_json_that_is_the_mesh_option_is_refused(tmp_path, capsys):
    gbuffer(tmp_path / "in.exr")
    (tmp_path / "m.mesh").write_bytes(b"triangles")
    refused(["rtao", "in.exr", "--mesh", "m.mesh", "--json", "m.mesh"], tmp_path, capsys,
            f"--json m.mesh is --mesh m.mesh: {OVERWRITE}")
    refused(["rtao", "in.exr", "--mesh", "m.mesh", "--out", "m.mesh.json"], tmp_path, capsys,
            "--out is the output path without extension (aolab run writes OUT.exr and "
            "OUT.png), got 'm.mesh.json' with the suffix '.json'")


def test_rtao_on_a_scene_folder_refuses_its_reference(tmp_path, capsys):
    gbuffer(tmp_path / "scene" / "reference.exr", mesh=True)
    refused(["rtao", "scene", "--out", "scene/reference"], tmp_path, capsys,
            f"--out's scene/reference.exr is the input scene/reference.exr: {OVERWRITE}")


# --- aolab advise ---------------------------------------------------------------------------

def test_advise_json_that_is_the_input_is_refused(tmp_path, capsys):
    gbuffer(tmp_path / "c.exr")
    refused(["advise", "c.exr", "--json", "c.exr"], tmp_path, capsys,
            f"--json c.exr is the input c.exr: {OVERWRITE}")
    refused(["advise", "c.exr", "--plot", "c.json.png", "--json", "c.json"], tmp_path, capsys,
            f"--json c.json is the input's sidecar c.json: {OVERWRITE}")


def test_advise_json_and_plot_the_same_file_is_refused(tmp_path, capsys):
    gbuffer(tmp_path / "c.exr")
    refused(["advise", "c.exr", "--json", "a.png", "--plot", "a.png"], tmp_path, capsys,
            "--plot a.png is also written as --json a.png")


def test_advise_json_that_is_a_scene_folder_file_is_refused(tmp_path, capsys):
    scene = tmp_path / "room"
    scene.mkdir()
    (scene / "manifest.json").write_text('{"name": "room"}')
    (scene / "build.py").write_text("# builds the room\n")
    refused(["advise", "room", "--json", "room/manifest.json"], tmp_path, capsys,
            f"--json room/manifest.json is the scene's file room/manifest.json: {OVERWRITE}")
    (tmp_path / "room.blend").write_bytes(b"BLENDER")
    refused(["advise", "room.blend", "--json", "room.blend"], tmp_path, capsys,
            f"--json room.blend is the scene room.blend: {OVERWRITE}")


# --- aolab analytic, bench-table, rtao-check, bridge-check, tune ----------------------------

def test_analytic_output_that_is_its_own_sidecar_is_refused(tmp_path, capsys):
    refused(["analytic", "plane", "x.json", "--width", "8", "--height", "8"], tmp_path, capsys,
            "OUTPUT's sidecar x.json is also written as OUTPUT x.json")


def test_bench_table_outputs_that_alias_are_refused(tmp_path, capsys):
    refused(["bench-table", "--no-scenes", "sao", "--json", "t.json", "--svg", "t.json"],
            tmp_path, capsys, "--svg t.json is also written as --json t.json")
    (tmp_path / "prof").mkdir()
    (tmp_path / "prof" / "sao.txt").write_text("an earlier profile")
    refused(["bench-table", "--no-scenes", "sao", "--json", "prof/sao.txt", "--profile",
             "prof"], tmp_path, capsys, "--json prof/sao.txt is also written as --profile's "
            "prof/sao.txt")


def test_bench_table_json_that_is_a_scene_file_is_refused(tmp_path, capsys):
    scenes = tmp_path / "scenes"
    gbuffer(scenes / "alpha" / "reference.exr")
    refused(["bench-table", "sao", "--scenes-dir", "scenes", "--json",
             "scenes/alpha/reference.json"], tmp_path, capsys,
            "--json scenes/alpha/reference.json is the scene file "
            f"scenes/alpha/reference.json: {OVERWRITE}")


def doc_with_block(path: Path) -> Path:
    """A Markdown file with rtao-check's generated block, which --update-doc replaces."""
    path.write_text(f"# doc\n\n{rtao_check.DOC_BEGIN}\nold\n{rtao_check.DOC_END}\n")
    return path


def test_rtao_check_update_doc_that_is_its_own_output_is_refused(tmp_path, capsys):
    (tmp_path / "rc").mkdir()
    doc_with_block(tmp_path / "rc" / "agreement.md")
    refused(["rtao-check", "--out", "rc", "--update-doc", "rc/agreement.md"], tmp_path,
            capsys, "--update-doc rc/agreement.md is also written as --out's rc/agreement.md")


def test_bridge_check_update_doc_that_is_its_own_output_is_refused(tmp_path, capsys):
    (tmp_path / "bc").mkdir()
    doc_with_block(tmp_path / "bc" / "agreement.json")
    refused(["bridge-check", "--out", "bc", "--update-doc", "bc/agreement.json"], tmp_path,
            capsys, "--update-doc bc/agreement.json is also written as --out's "
            "bc/agreement.json")


def test_tune_presets_file_that_is_the_trial_store_is_refused(tmp_path, capsys):
    pytest.importorskip("optuna")
    scenes = tmp_path / "scenes"
    gbuffer(scenes / "alpha" / "reference.exr")
    refused(["tune", "--scenes-dir", "scenes", "--out", "tt", "--presets-file", "tt/tune.db",
             "--methods", "sao", "--trials", "1", "--no-progress"], tmp_path, capsys,
            "--presets-file tt/tune.db is also written as --out's tt/tune.db")


# --- aolab compare, radius-study, reference, mesh -------------------------------------------

def test_compare_never_clears_a_folder_that_holds_a_scene(tmp_path, capsys):
    scenes = tmp_path / "out" / "report_files"
    gbuffer(scenes / "alpha" / "reference.exr")
    refused(["compare", "--scenes-dir", "out/report_files", "--out", "out", "--methods", "sao",
             "--repeat", "1", "--warmup", "0", "--no-progress"], tmp_path, capsys,
            "the report folder of --out out/report_files is cleared by this command and the "
            "scene file out/report_files/alpha/reference.exr is in it: an output would destroy "
            "an input")


def scene_folder(root: Path, build: str) -> Path:
    """A scene folder whose manifest names the build script ``build`` (R 1)."""
    root.mkdir(parents=True)
    (root / "manifest.json").write_text(json.dumps({"name": root.name, "build": build,
                                                    "radius": 1.0}))
    (root / build).write_text("# builds the scene\n")
    return root


def test_radius_study_out_never_overwrites_a_scene(tmp_path, capsys):
    scene_folder(tmp_path / "scenes" / "room", "radius_study.md")
    refused(["radius-study", "room", "--scenes-dir", "scenes", "--out", "scenes/room",
             "--scales", "1"], tmp_path, capsys, "--out's scenes/room/radius_study.md is the "
            f"scene scenes/room/radius_study.md: {OVERWRITE}")


@pytest.mark.parametrize("command, build", [("reference", "reference.json"),
                                            ("mesh", "reference.mesh.json")])
def test_reference_and_mesh_never_copy_over_the_scene(tmp_path, capsys, command, build):
    scene_folder(tmp_path / "room", build)
    refused([command, "room", "--out", "room"], tmp_path, capsys,
            f"--out's room/{build} is the scene room/{build}: {OVERWRITE}")


# --- the bridge's export (inside Blender), without Blender ---------------------------------

def test_export_files_are_named_as_the_bridge_writes_them():
    assert export_files("o/ref.exr", passes=["depth", "mesh"]) == {
        "--out": "o/ref.exr", "the sidecar": Path("o/ref.json"), "the mesh": "o/ref.mesh",
        "the mesh's JSON": Path("o/ref.mesh.json")}
    assert export_files("o/ref.mesh", passes=[], mesh_only=True) == {
        "--out": "o/ref.mesh", "the mesh's JSON": Path("o/ref.mesh.json")}


def test_export_over_the_open_blend_or_its_own_files_is_refused(tmp_path):
    blend = tmp_path / "scene.blend"
    blend.write_bytes(b"BLENDER")
    scene = {"--scene": str(blend), "the open .blend": str(blend)}
    with pytest.raises(ValueError, match=f"^--out {blend} is --scene {blend}: {OVERWRITE}$"):
        check_export(str(blend), scene, passes=["depth"])
    with pytest.raises(ValueError, match=f"^the sidecar {tmp_path}/x.json is also written as "
                                         f"--out {tmp_path}/x.json$"):
        check_export(str(tmp_path / "x.json"), scene, passes=["depth"])
    with pytest.raises(ValueError, match=f"^the mesh {tmp_path}/x.mesh is also written as "
                                         f"--out {tmp_path}/x.mesh$"):
        check_export(str(tmp_path / "x.mesh"), scene, passes=["depth", "mesh"])
    with pytest.raises(ValueError, match=f"^--out {tmp_path}/scene.blend is --scene"):
        check_export(str(tmp_path / "scene.blend"), scene, passes=[], mesh_only=True)
    link = tmp_path / "link.exr"
    link.symlink_to(blend)
    with pytest.raises(ValueError, match=f"^--out {link} is --scene {blend}"):
        check_export(str(link), scene, passes=["depth"])
    check_export(str(tmp_path / "ref.exr"), scene, passes=["depth", "mesh"])   # distinct: fine
    check_export(str(tmp_path / "peers"), scene, passes=[], peers=True)
    assert blend.read_bytes() == b"BLENDER"


# --- files.check_distinct -----------------------------------------------------------------

def test_check_distinct_compares_real_paths(tmp_path, monkeypatch):
    (tmp_path / "a").write_text("input")
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "up").symlink_to(tmp_path, target_is_directory=True)
    with pytest.raises(ValueError, match=f"^--x {tmp_path}/d/up/a is the input {tmp_path}/a"):
        files.check_distinct(reads={"the input": tmp_path / "a"},
                             writes={"--x": tmp_path / "d" / "up" / "a"})
    with pytest.raises(ValueError, match="^--y's d/../b is also written as --x b$"):
        monkeypatch.chdir(tmp_path)
        files.check_distinct(writes={"--x": "b", "--y": ["c", "d/../b"]})
    files.check_distinct(reads={"the input": "a"}, writes={"--x": "b", "--y": [None, "c"]})


def test_check_distinct_refuses_a_cleared_folder_that_holds_an_input(tmp_path):
    with pytest.raises(ValueError, match="cleared by this command and the input .* is in it"):
        files.check_distinct(reads={"the input": tmp_path / "out" / "x.exr"},
                             cleared={"--out": tmp_path / "out"})
    with pytest.raises(ValueError, match="cleared by this command and the scenes .* is in it"):
        files.check_distinct(reads={"the scenes": tmp_path}, cleared={"--out": tmp_path})
    files.check_distinct(reads={"the input": tmp_path / "outside"},
                         cleared={"--out": tmp_path / "out"})
