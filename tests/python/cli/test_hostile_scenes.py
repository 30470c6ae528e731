"""Scene folders are confined (docs/file_formats.md, "Scene folders" and "Checksums"): a
scene's files are regular files inside its folder. A symbolic link among them (a file, a
subfolder such as frames/0001) is refused with one line naming it and where it points, before
it is hashed or opened, unless --follow-symlinks (follow_symlinks=True) says to read it, which
a warning line then names; a SHA256SUMS names only plain file names of its folder. The folder
given may itself be a link (the user's). Each case: one line, exit status 2, the user's files
unchanged."""
from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from aolab import scenes
from aolab.util import files
from compare_support import SCENES
from cli_support import aolab_cmd, assert_one_error_line

#: The smallest committed scene (about 0.8 MB with its peers and limits).
SMALL = "thin_balustrade"
QUICK = ["--methods", "crytek_ssao", "--crop", "32x32", "--repeat", "1", "--warmup", "0",
         "--rtao-rays", "none", "--no-progress"]


def copied(tmp_path: Path, name: str = SMALL) -> Path:
    """A copy of the small committed scene (its SHA256SUMS, peers and limits included)."""
    folder = tmp_path / "scenes" / name
    shutil.copytree(SCENES / SMALL, folder)
    return folder


def snapshot(*roots: Path) -> dict:
    """Every file under ``roots`` (links as links) -> its bytes or its target."""
    out = {}
    for root in roots:
        for top, dirs, names in os.walk(root):
            for name in dirs + names:
                p = Path(top) / name
                out[p] = ("link", os.readlink(p)) if p.is_symlink() else \
                    (p.read_bytes() if p.is_file() else "folder")
    return out


def compare(folder: Path, out: Path, *extra: str):
    return aolab_cmd("compare", str(folder), "--out", str(out), *QUICK, *extra, timeout=600)


def link_elsewhere(folder: Path, name: str, elsewhere: Path) -> Path:
    """Moves ``folder/name`` to ``elsewhere`` (same bytes: the sums still match) and leaves a
    symbolic link to it in its place."""
    elsewhere.mkdir(parents=True, exist_ok=True)
    target = elsewhere / name
    shutil.move(folder / name, target)
    os.symlink(target, folder / name)
    return target


def assert_refused(run, link: Path, target: Path, before: dict, out: Path) -> None:
    assert run.returncode == 2, run.stderr
    assert_one_error_line(run.stderr, f"{str(link)!r} is a symbolic link to {str(target)!r}",
                          "must be regular files inside its folder", "--follow-symlinks")
    assert "SHA-256" not in run.stderr      # nothing was hashed
    assert snapshot(*before["roots"]) == before["files"]
    assert not out.exists()


def taken(*roots: Path) -> dict:
    return {"roots": roots, "files": snapshot(*roots)}


def test_a_symlinked_reference_with_matching_sums_is_refused_before_it_is_hashed(tmp_path):
    folder = copied(tmp_path)
    target = link_elsewhere(folder, "reference.exr", tmp_path / "elsewhere")
    before = taken(tmp_path / "scenes", tmp_path / "elsewhere")
    out = tmp_path / "out"
    assert_refused(compare(folder, out), folder / "reference.exr", target, before, out)


def test_result_files_linked_to_another_scenes_are_refused(tmp_path):
    """Was: four result files symlinked to another scene's, with its sums, were scored under
    this folder's name."""
    folder = copied(tmp_path, "mine")
    for name in scenes.RESULT_FILES:
        (folder / name).unlink()
        os.symlink(SCENES / "room" / name, folder / name)
    shutil.copyfile(SCENES / "room" / files.CHECKSUMS_NAME, folder / files.CHECKSUMS_NAME)
    before = taken(tmp_path / "scenes")
    out = tmp_path / "out"
    first = sorted(scenes.RESULT_FILES)[0]
    assert_refused(compare(folder, out), folder / first, SCENES / "room" / first, before, out)


def sequence_with_linked_frame(tmp_path: Path, linked: str) -> tuple[Path, Path, Path]:
    """A one-frame sequence whose ``linked`` part ("frames" or "frames/0001") is a symbolic
    link to a folder elsewhere; returns (sequence, link, target)."""
    seq = tmp_path / "scenes" / "seq"
    frame = tmp_path / "elsewhere" / "frames" / "0001"
    frame.mkdir(parents=True)
    for name in ("reference.exr", "reference.json"):
        shutil.copyfile(SCENES / SMALL / name, frame / name)
    seq.mkdir(parents=True)
    manifest = json.loads((SCENES / SMALL / "manifest.json").read_text())
    manifest["frames"] = {"start": 1, "end": 1, "step": 1}
    (seq / "manifest.json").write_text(json.dumps(manifest))
    if linked == "frames":
        os.symlink(frame.parent, seq / "frames")
        return seq, seq / "frames", frame.parent
    (seq / "frames").mkdir()
    os.symlink(frame, seq / "frames" / "0001")
    return seq, seq / "frames" / "0001", frame


@pytest.mark.parametrize("linked", ["frames", "frames/0001"])
def test_a_sequence_whose_frames_lead_out_of_its_folder_is_refused(tmp_path, linked):
    seq, link, target = sequence_with_linked_frame(tmp_path, linked)
    before = taken(tmp_path / "scenes", tmp_path / "elsewhere")
    out = tmp_path / "out"
    assert_refused(compare(seq, out), link, target, before, out)


#: Each command that reads a scene folder, with the options that keep it small; none gets as
#: far as its work (Blender, for reference and mesh).
READERS = {"limits": ["--rays", "1"],
           "tune": ["--trials", "1", "--crop", "32x32", "--presets-file", "presets.json"],
           "reference": ["--cache", "cache"], "mesh": ["--cache", "cache"],
           "rtao": ["--rays", "1"], "advise": ["--cache", "cache"]}


@pytest.mark.parametrize("command", sorted(READERS))
def test_each_command_that_reads_a_scene_refuses_a_symlinked_file(tmp_path, command,
                                                                  monkeypatch):
    monkeypatch.chdir(tmp_path)
    folder = copied(tmp_path)
    target = link_elsewhere(folder, "reference.exr", tmp_path / "elsewhere")
    before = taken(tmp_path / "scenes", tmp_path / "elsewhere")
    out = tmp_path / "out"
    scene = ["--scenes", str(folder)] if command == "tune" else [str(folder)]
    extra = [] if command in ("limits", "advise") else ["--out", str(out)]
    run = aolab_cmd(command, *scene, *READERS[command], *extra)
    assert_refused(run, folder / "reference.exr", target, before, out)
    assert not (tmp_path / "cache").exists()


@pytest.mark.parametrize("command", sorted({*READERS, "compare", "radius-study"}))
def test_each_command_the_refusal_sends_to_follow_symlinks_has_the_option(command):
    """The refusal names --follow-symlinks: every command that gives it takes it."""
    run = aolab_cmd(command, "--help")
    assert run.returncode == 0 and "--follow-symlinks" in run.stdout, run.stdout


def test_follow_symlinks_reads_the_link_and_says_so(tmp_path):
    folder = copied(tmp_path)
    target = link_elsewhere(folder, "reference.exr", tmp_path / "elsewhere")
    before = taken(tmp_path / "scenes", tmp_path / "elsewhere")
    run = compare(folder, tmp_path / "out", "--follow-symlinks")
    assert run.returncode == 0, run.stderr
    warning = (f"aolab: warning: scene {SMALL!r}: {str(folder / 'reference.exr')!r} is a "
               f"symbolic link to {str(target)!r}, followed (--follow-symlinks)")
    assert run.stderr.count(warning) == 1, run.stderr
    assert (tmp_path / "out" / "report.html").is_file()
    assert snapshot(tmp_path / "scenes", tmp_path / "elsewhere") == before["files"]


def test_the_api_refuses_a_link_unless_follow_symlinks(tmp_path, capfd):
    folder = copied(tmp_path)
    target = link_elsewhere(folder, "reference.exr", tmp_path / "elsewhere")
    for load in (scenes.load_scene, scenes.load_cropped):
        with pytest.raises(ValueError, match="is a symbolic link to") as e:
            load(folder)
        assert str(target) in str(e.value) and "follow_symlinks=True" in str(e.value)
    with pytest.raises(ValueError, match="is a symbolic link to"):
        scenes.resolve_scenes([str(folder)], None)
    scene = scenes.load_scene(folder, scenes.Crop(16, 16), follow_symlinks=True)
    assert scene.reference.shape == (16, 16)
    assert "followed (--follow-symlinks)" in capfd.readouterr().err


def test_the_scene_folder_itself_may_be_a_link(tmp_path):
    """The user's link to a scene folder elsewhere is theirs to make: only links inside the
    folder lead its files out."""
    folder = copied(tmp_path)
    mine = tmp_path / "mine"
    os.symlink(folder, mine)
    run = compare(mine, tmp_path / "out")
    assert run.returncode == 0, run.stderr
    assert "warning" not in run.stderr


@pytest.mark.parametrize("name", ["..", ".", ".hidden", "sub/reference.exr", "a\\b"])
def test_a_checksum_entry_that_is_no_plain_file_name_is_refused(tmp_path, name):
    folder = copied(tmp_path)
    sums = folder / files.CHECKSUMS_NAME
    lines = sums.read_text().splitlines()
    lines.insert(2, f"{'0' * 64}  {name}")
    sums.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError) as e:
        files.read_checksums(folder)
    assert str(e.value) == (f"{sums}: line 3: {name!r} is not the plain name of a file in "
                            "this folder (no '/', '\\', '.' or '..', nothing hidden)")
    before = taken(tmp_path / "scenes")
    out = tmp_path / "out"
    run = compare(folder, out)
    assert run.returncode == 2, run.stderr
    assert_one_error_line(run.stderr, f"line 3: {name!r} is not the plain name of a file")
    assert snapshot(tmp_path / "scenes") == before["files"] and not out.exists()


def test_an_escaped_sha256sum_line_is_refused_naming_the_line(tmp_path):
    """sha256sum writes a name holding a newline or a backslash escaped, the line starting
    with a backslash: such a name is no plain file name."""
    folder = copied(tmp_path)
    sums = folder / files.CHECKSUMS_NAME
    sums.write_text(sums.read_text() + f"\\{'0' * 64}  a\\nb\n")
    with pytest.raises(ValueError, match=r"line 5: not a SHA256SUMS line: '\\\\0000"):
        files.read_checksums(folder)


def test_a_peer_entry_naming_a_file_out_of_its_folder_is_not_used(tmp_path):
    folder = copied(tmp_path)
    peers = folder / "peers"
    listing = json.loads((peers / "peers.json").read_text())
    listing["entries"][0]["file"] = "../../room/reference.exr"
    (peers / "peers.json").write_text(json.dumps(listing))
    scenes.write_folder_checksums(peers)
    scene = scenes.load_scene(folder, scenes.Crop(16, 16))
    name = listing["entries"][0]["name"]
    assert name not in [p.name for p in scene.peers]
    assert any(n.startswith(f"peer {name}: not used (its file '../../room/reference.exr' is "
                            "not a plain file name") for n in scene.notes), scene.notes


def test_a_manifest_naming_a_build_script_out_of_the_folder_is_refused(tmp_path):
    folder = copied(tmp_path)
    manifest = json.loads((folder / "manifest.json").read_text())
    (folder / "manifest.json").write_text(json.dumps({**manifest, "build": "../../evil.py"}))
    before = taken(tmp_path / "scenes")
    run = aolab_cmd("reference", str(folder), "--cache", str(tmp_path / "cache"))
    assert run.returncode == 2, run.stderr
    assert_one_error_line(run.stderr, '"build" must be the name of a file in the scene\'s '
                          "folder, got '../../evil.py'")
    assert snapshot(tmp_path / "scenes") == before["files"]
