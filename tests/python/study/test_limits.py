"""aolab limits: the committed screen-space limits of the reference scenes — computed like the
method, written atomically, kept while up to date, recomputed when the scene changes."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import aolab
from aolab import scenes
from aolab import cli
from aolab.study import limits
from aolab.util import files
from aolab.util.arguments import MAX_THICKNESS_R, parse_thickness

RADIUS = 0.5
RAYS = 16


def analytic_folder(tmp_path, name="scene", scene="crease", width=48, height=27):
    """A scene folder (reference.exr + sidecar) of an analytic scene, as aolab compare reads."""
    folder = tmp_path / name
    folder.mkdir()
    g = aolab.analytic_scene(scene, width, height, radius=RADIUS)
    ref = np.where(np.isfinite(g.reference), g.reference, 1.0).astype(np.float32)
    aolab.save_gbuffer(folder / "reference.exr", g, reference=ref, sidecar=g.sidecar)
    return folder


def test_limits_equal_the_method_and_are_described(tmp_path):
    folder = analytic_folder(tmp_path)
    entries = limits.compute_scene(folder, (0.25, math.inf), RAYS, 1, False, log=lambda m: None)
    assert [e["name"] for e in entries] == ["screen_space_limit_t0.25R", "screen_space_limit_t_inf"]
    g = aolab.load_gbuffer(folder / "reference.exr")
    for e, thickness in zip(entries, (0.25 * RADIUS, limits.HEIGHT_FIELD)):
        assert e["kind"] == "limit" and e["rays"] == RAYS and e["radius"] == RADIUS
        assert e["thickness"] == pytest.approx(thickness)
        assert e["reference_sha256"] == files.sha256_file(folder / "reference.exr")
        want = aolab.compute("screen_space_limit", g, radius=RADIUS, rays=RAYS,
                             thickness=thickness, threads=2)
        got = scenes.read_y_exr(folder / "limits" / e["file"])
        np.testing.assert_allclose(got, want, atol=5e-4)    # stored as half floats
    on_disk = json.loads((folder / "limits" / "limits.json").read_text())["entries"]
    assert on_disk == entries
    assert not [p for p in (folder / "limits").iterdir() if "tmp" in p.name]


def test_up_to_date_entries_are_kept_and_stale_ones_recomputed(tmp_path):
    folder = analytic_folder(tmp_path)
    logged = []
    first = limits.compute_scene(folder, (0.5,), RAYS, 0, False, log=logged.append)
    again = limits.compute_scene(folder, (0.5,), RAYS, 0, False, log=logged.append)
    assert again == first and logged[-1].endswith("up to date")
    more = limits.compute_scene(folder, (0.5,), RAYS * 2, 0, False, log=logged.append)
    assert more[0]["rays"] == RAYS * 2 and "up to date" not in logged[-1]
    forced = limits.compute_scene(folder, (0.5,), RAYS * 2, 0, True, log=logged.append)
    assert forced[0]["date"] >= more[0]["date"] and "up to date" not in logged[-1]
    # another reference (the scene re-rendered): its digest changes, the limit is recomputed
    g = aolab.analytic_scene("wall", 48, 27, radius=RADIUS)
    ref = np.where(np.isfinite(g.reference), g.reference, 1.0).astype(np.float32)
    aolab.save_gbuffer(folder / "reference.exr", g, reference=ref, sidecar=g.sidecar)
    fresh = limits.compute_scene(folder, (0.5,), RAYS * 2, 0, False, log=logged.append)
    assert fresh[0]["reference_sha256"] != forced[0]["reference_sha256"]


def test_the_limit_of_an_analytic_scene_matches_its_closed_form(tmp_path):
    """Where the depth buffer holds all the geometry, the committed limit is the reference
    within its Monte-Carlo error (binomial sd of RAYS rays, 4 sigma on the mean)."""
    folder = analytic_folder(tmp_path, scene="wall", width=64, height=36)
    (entry,) = limits.compute_scene(folder, (math.inf,), RAYS, 0, False, log=lambda m: None)
    g = aolab.load_gbuffer(folder / "reference.exr")
    got = scenes.read_y_exr(folder / "limits" / entry["file"]).astype(np.float64)
    ref = np.asarray(g.reference, np.float64)
    valid = g.valid_mask() & (ref < 1.0)
    sd = np.sqrt(np.mean(ref[valid] * (1 - ref[valid])) / RAYS / valid.sum())
    assert abs(np.mean(got[valid] - ref[valid])) < 4 * sd + 1e-3


def test_command_line(tmp_path):
    folder = analytic_folder(tmp_path)
    assert cli.main(["limits", str(folder), "--thickness", "1", "--rays", "4",
                     "--threads", "1"]) == 0
    assert [e["name"] for e in limits.read_entries(folder)] == ["screen_space_limit_t1R"]
    for bad, word in ((["--thickness", "0"], "--thickness"), (["--thickness", "x"], "--thickness"),
                      (["--rays", "0"], "--rays")):
        res = subprocess.run([sys.executable, "-m", "aolab", "limits", str(folder), *bad],
                             capture_output=True, text=True)
        assert res.returncode == 2 and word in res.stderr and "Traceback" not in res.stderr


def test_committed_limits_are_current():
    """Every committed limit names the reference it was computed from: a re-rendered
    reference without `aolab limits` afterwards would leave a stale limit in the study."""
    folder_of_scenes = scenes.find_scenes_dir()
    for folder in scenes.resolve_scenes([], folder_of_scenes):
        entries = limits.read_entries(folder)
        if not entries:
            continue
        digest = files.sha256_file(folder / "reference.exr")
        side = aolab.load_gbuffer(folder / "reference.exr").sidecar
        for e in entries:
            assert e["reference_sha256"] == digest, (folder.name, e["name"])
            assert e["radius"] == side["ao_distance"] and e["rays"] >= limits.RAYS
            assert (folder / "limits" / e["file"]).exists()


def test_fewer_rays_keep_a_better_entry_without_force(tmp_path):
    """aolab limits room --rays 4 replaced the committed 256-ray entry: a lower-quality result
    must not replace a better one without --force."""
    folder = analytic_folder(tmp_path)
    logged = []
    (better,) = limits.compute_scene(folder, (0.5,), RAYS, 0, False, log=logged.append)
    exr = (folder / "limits" / better["file"]).read_bytes()
    (kept,) = limits.compute_scene(folder, (0.5,), RAYS // 4, 0, False, log=logged.append)
    assert kept == better and (folder / "limits" / better["file"]).read_bytes() == exr
    assert logged[-1] == (f"{folder.name}: {better['name']} kept: it has {RAYS} rays, more "
                          f"than --rays {RAYS // 4} (--force replaces it)")
    (forced,) = limits.compute_scene(folder, (0.5,), RAYS // 4, 0, True, log=logged.append)
    assert forced["rays"] == RAYS // 4
    # A better entry of a reference that changed since is stale: fewer rays replace it.
    (again,) = limits.compute_scene(folder, (0.5,), RAYS, 0, False, log=logged.append)
    g = aolab.analytic_scene("wall", 48, 27, radius=RADIUS)
    ref = np.where(np.isfinite(g.reference), g.reference, 1.0).astype(np.float32)
    aolab.save_gbuffer(folder / "reference.exr", g, reference=ref, sidecar=g.sidecar)
    (fresh,) = limits.compute_scene(folder, (0.5,), RAYS // 4, 0, False, log=logged.append)
    assert fresh["rays"] == RAYS // 4 and fresh["reference_sha256"] != again["reference_sha256"]


@pytest.mark.parametrize("text", ["1e300", "1e7", "1e309", "0", "nan", "x"])
def test_a_thickness_the_method_cannot_take_is_refused_when_read(tmp_path, capsys, text):
    """--thickness 1e300 passed the option check and then failed with "got inf"."""
    folder = analytic_folder(tmp_path)
    assert cli.main(["limits", str(folder), "--thickness", text, "--rays", "1"]) == 2
    err = capsys.readouterr().err
    assert (f"argument --thickness: --thickness must be a multiple of R in (0, 1e+06] or inf "
            f"(a height field), got {text!r}") in err, err
    assert not (folder / "limits").exists()


def test_the_largest_thickness_is_computed(tmp_path):
    assert parse_thickness(" Inf ") == parse_thickness(math.inf) == math.inf
    folder = analytic_folder(tmp_path)
    (entry,) = limits.compute_scene(folder, (MAX_THICKNESS_R,), 1, 0, False,
                                    log=lambda m: None)
    assert entry["thickness"] == pytest.approx(MAX_THICKNESS_R * RADIUS)
