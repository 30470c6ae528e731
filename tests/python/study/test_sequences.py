"""Sequences in the study: the frames/NNNN layout, each frame scored as a scene, the flicker
and the reference's flicker floor, the report's temporal section and docs/results.md's.
Runs on a synthetic sequence cut from room's reference (compare_support.make_sequence)."""
from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import scenes
from aolab import cli
from aolab.study import results_doc
from aolab.study import results as results_mod
from aolab.study import findings
from compare_support import (ROOT, SEQUENCE_FRAMES, make_sequence, parse_report, read_csv)

FRAMES = list(range(SEQUENCE_FRAMES["start"], SEQUENCE_FRAMES["end"] + 1,
                    SEQUENCE_FRAMES["step"]))
METHODS = ("hbao", "lsao")


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("sequence")
    scenes = tmp / "scenes"
    folder = make_sequence(scenes, "pan")
    out = tmp / "out"
    assert cli.main(["compare", "pan", "--scenes-dir", str(scenes), "--out", str(out),
                     "--methods", *METHODS, "--repeat", "1", "--warmup", "0", "--threads", "2",
                     "--no-progress"]) == 0
    return {"folder": folder, "out": out, "rows": read_csv(out / "results.csv"),
            "json": json.loads((out / "results.json").read_text()),
            "html": (out / "report.html").read_text(encoding="utf-8")}


def load_frames(folder: Path) -> list:
    return [aolab.load_gbuffer(scenes.frame_folder(folder, f) / "reference.exr") for f in FRAMES]


def test_the_flicker_is_the_formula_on_a_hand_made_pair():
    ref0 = np.array([[0.5, 0.8], [1.0, 0.2]])
    ref1 = np.array([[0.6, 0.8], [1.0, 0.4]])
    ao0 = np.array([[0.5, 0.7], [0.9, 0.9]])
    ao1 = np.array([[0.7, 0.9], [0.9, 0.0]])
    valid0 = np.array([[True, True], [True, False]])
    valid1 = np.array([[True, True], [False, True]])
    # pixels scored in both: (0, 0) and (0, 1): |0.2 - 0.1| and |0.2 - 0|
    assert results_mod.flicker(ao0, ao1, ref0, ref1, valid0, valid1) == pytest.approx(0.15)
    # the reference against itself, and any constant bias of it, does not flicker
    assert results_mod.flicker(ref0, ref1, ref0, ref1, valid0, valid1) == 0
    assert results_mod.flicker(ref0 - 0.1, ref1 - 0.1, ref0, ref1, valid0, valid1) == \
        pytest.approx(0, abs=1e-15)
    assert results_mod.flicker(ao0, ao1, ref0, ref1, valid0, ~valid0) is None


def test_the_flicker_floor_is_the_binomial_noise_of_two_frames():
    ref0, ref1 = np.full((2, 2), 0.5), np.full((2, 2), 0.9)
    valid = np.ones((2, 2), bool)
    n = 1024
    expected = math.sqrt((0.25 + 0.09) / n) * math.sqrt(2 / math.pi)
    assert results_mod.flicker_floor(ref0, ref1, valid, valid, n) == pytest.approx(expected)
    assert results_mod.flicker_floor(ref0, ref1, valid, valid, 0) is None
    # two independent renders of noise with that variance: the same mean |difference|
    rng = np.random.default_rng(3)
    a = 0.5 + rng.normal(size=200_000) * math.sqrt(0.25 / n)
    b = 0.9 + rng.normal(size=200_000) * math.sqrt(0.09 / n)
    assert np.mean(np.abs((a - 0.5) - (b - 0.9))) == pytest.approx(expected, rel=0.01)


def test_every_frame_is_scored_as_a_scene_of_its_own(study):
    rows = study["rows"]
    names = [scenes.frame_scene_name("pan", f) for f in FRAMES]
    assert names[0] == "pan@0001"
    configs = {(r["kind"], r["method"], r["label"]) for r in rows if r["scene"] == "pan"}
    assert {m for k, m, _ in configs if k == "method"} == set(METHODS)
    for frame, name in zip(FRAMES, names):
        mine = [r for r in rows if r["scene"] == name]
        assert {(r["kind"], r["method"], r["label"]) for r in mine} == configs
        assert all(r["sequence"] == "pan" and int(r["frame"]) == frame for r in mine)
        assert all(r["all_mae"] and r["runs"] for r in mine if r["kind"] == "method")
    # the sequence's rows: means over its frames, no frame; ALL leaves sequences out
    for r in (r for r in rows if r["scene"] == "pan"):
        assert r["sequence"] == "pan" and r["frame"] == "" and int(r["n_scenes"]) == len(FRAMES)
        frames = [float(x["all_mae"]) for x in rows if x["sequence"] == "pan" and x["frame"]
                  and (x["kind"], x["method"], x["label"]) == (r["kind"], r["method"], r["label"])]
        assert float(r["all_mae"]) == pytest.approx(np.mean(frames))
    info = study["json"]["scenes"]["pan"]
    assert info["sequence"] is True and info["frames"] == FRAMES and info["frame_scenes"] == names
    assert study["json"]["meta"]["scenes"] == ["pan"]
    assert study["json"]["meta"]["complete_scenes"] == ["pan"]
    assert not [r for r in rows if r["scene"] == "ALL"]   # a sequence alone: no ALL rows


def test_flicker_is_set_for_every_row_and_is_the_formula(study):
    rows, folder = study["rows"], study["folder"]
    for r in rows:
        if r["sequence"] == "pan":
            first = r["frame"] == str(FRAMES[0])
            assert (r["flicker"] == "") == first, r["key"]   # the first frame has no pair
    for r in (r for r in rows if r["scene"] == "pan"):
        pairs = [float(x["flicker"]) for x in rows if x["sequence"] == "pan" and x["flicker"]
                 and x["frame"] and x["method"] == r["method"] and x["label"] == r["label"]]
        assert len(pairs) == len(FRAMES) - 1
        assert float(r["flicker"]) == pytest.approx(np.mean(pairs))
    # recomputed from the files: the baseline (AO = 1 does not change, so its flicker is the
    # reference's own change) and HBAO at its defaults (no blur)
    gs = load_frames(folder)
    by_key = {r["key"]: r for r in rows}
    for i in range(1, len(gs)):
        p, g = gs[i - 1], gs[i]
        name = scenes.frame_scene_name("pan", FRAMES[i])
        args = (p.reference, g.reference, p.valid_mask(), g.valid_mask())
        ones = np.ones_like(g.reference)
        assert float(by_key[f"{name}/baseline_one/AO=1"]["flicker"]) == \
            pytest.approx(results_mod.flicker(ones, ones, *args))
        hbao = [aolab.compute("hbao", x, radius=0.5) for x in (p, g)]
        assert float(by_key[f"{name}/hbao/default"]["flicker"]) == \
            pytest.approx(results_mod.flicker(*hbao, *args), rel=1e-9)
    floor = study["json"]["scenes"]["pan"]["flicker_floor"]
    assert len(floor["pairs"]) == len(FRAMES) - 1 and floor["estimated"] is True
    assert floor["value"] == pytest.approx(np.mean(floor["pairs"]))
    assert 0 < floor["value"] < 0.02


def test_per_pixel_noise_names_the_random_settings():
    assert findings.per_pixel_noise("hbao", {}) == ["random_rotation", "jitter"]
    assert findings.per_pixel_noise("hbao", {"jitter": False}) == ["random_rotation"]
    assert findings.per_pixel_noise("lsao", {}) == []
    assert findings.per_pixel_noise("crytek_ssao", {"rotation": "none"}) == []
    assert findings.per_pixel_noise("crytek_ssao", {}) == ["rotation tiled4x4"]
    assert findings.per_pixel_noise("baseline_one", {}) == []
    # every setting a method describes as random per pixel is one the table names
    for m in aolab.methods():
        for s in aolab.method_info(m)["settings"]:
            d = s["description"].lower()
            if s["name"] != "seed" and ("randomly per pixel" in d or "random factor" in d
                                        or "per pixel by" in d):
                assert s["name"] in findings.NOISE_SETTINGS, (m, s["name"])


def test_the_report_plots_mae_per_frame_and_tables_the_flicker(study):
    rows = {r["key"]: r for r in study["rows"]}
    report = parse_report(study["out"] / "report.html")
    frames_plots = [p for p in report.plots if "frames" in p["class"].split()]
    assert [p["id"] for p in frames_plots] == ["plot-pan-frames"]
    points = [p for p in report.points if p["data-key"].split("/")[0].startswith("pan@")]
    best = findings.sequence_best([r for r in study["json"]["rows"] if r["scene"] == "pan"],
                                  study["json"]["meta"]["budget_ms"])
    assert {r["method"] for r in best} == set(METHODS)
    assert len(points) == len(best) * len(FRAMES)
    for p in points:
        row = rows[p["data-key"]]
        assert int(p["data-x"]) == int(row["frame"])
        assert float(p["data-y"]) == pytest.approx(float(row["all_mae"]), rel=1e-12)
    html = study["html"]
    assert 'id="temporal-pan"' in html and "show what they cost in motion" in html
    table = html[html.index('class="check flicker"'):]
    table = table[:table.index("</table>")]
    shown = [float(x.split('"')[0]) for x in table.split('data-flicker="')[1:]]
    assert shown == sorted(shown)
    assert len(shown) == len([r for r in rows.values() if r["scene"] == "pan"])
    assert "random_rotation, jitter" in table and "reference flicker floor" in table


def test_the_report_renders_in_headless_chromium(study):
    chromium = shutil.which("chromium")
    if chromium is None:
        pytest.skip("chromium is not installed")
    import subprocess
    out = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--dump-dom",
                          (study["out"] / "report.html").as_uri()], capture_output=True,
                         text=True, timeout=120)
    assert "AO Lab report: ok" in out.stdout


def test_results_doc_has_a_temporal_stability_section(study):
    text = "\n".join(results_doc.pages(study["json"]).values())
    part = text[text.index("## Temporal stability"):]
    assert "### pan" in part and "reference flicker floor" in part
    assert "| method | setting | 1 | 3 | 5 | 7 |" in part
    for r in (r for r in study["rows"] if r["scene"] == "pan" and r["kind"] == "method"):
        assert f'| {r["method"]} | {r["label"]} | {float(r["flicker"]):.4f} |' in part
    none = results_doc.temporal_section({"meta": {"scenes": ["room"]}, "scenes": {}, "rows": []})
    assert "No sequence scene in this run" in "\n".join(none)


def test_sequence_errors_name_the_frame(tmp_path):
    folder = make_sequence(tmp_path / "scenes", "pan")
    shutil.rmtree(scenes.frame_folder(folder, FRAMES[2]))
    with pytest.raises(ValueError, match=r"scene 'pan': frame 5 has no reference.exr"):
        scenes.check_sequence(folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["frames"] = {"start": 3, "end": 1, "step": 1}
    (folder / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ValueError, match=r'"frames" must be .* got \{.start.: 3'):
        scenes.frame_numbers(folder)


def test_an_unrendered_sequence_is_left_out_and_named_with_its_frame():
    folder = ROOT / "reference_scenes"
    assert scenes.frame_numbers(folder / "flythrough") == list(range(1, 9))
    if not (folder / "flythrough" / "frames").exists():
        assert "flythrough" not in [p.name for p in scenes.resolve_scenes([], folder)]
        with pytest.raises(ValueError, match=r"frames/0001/reference.exr \(a sequence"):
            scenes.resolve_scenes(["flythrough"], folder)


def test_the_flythrough_build_moves_its_camera_in_blender():
    """reference_scenes/flythrough/build.py runs in Blender as the bridge runs it (factory
    settings, empty scene), and its camera moves between frames 1 and 8 as keyframed."""
    blender = shutil.which("blender")
    if blender is None:
        pytest.skip("Blender is not installed")
    import subprocess
    build = ROOT / "reference_scenes" / "flythrough" / "build.py"
    script = ("import bpy, runpy\n"
              "bpy.ops.wm.read_factory_settings(use_empty=True)\n"
              f"runpy.run_path({str(build)!r}, run_name='__main__')\n"
              "s = bpy.context.scene\n"
              "for f in (1, 8):\n"
              "    s.frame_set(f)\n"
              "    print('CAMERA', f, *s.camera.matrix_world.translation)\n"
              "print('SIZE', s.render.resolution_x, s.render.resolution_y, s.frame_start, "
              "s.frame_end, s.world.light_settings.distance)\n")
    out = subprocess.run([blender, "-b", "--factory-startup", "--python-expr", script],
                         capture_output=True, text=True, timeout=300)
    lines = {ln.split()[0] + ln.split()[1]: [float(v) for v in ln.split()[2:]]
             for ln in out.stdout.splitlines() if ln.startswith(("CAMERA", "SIZE"))}
    assert lines["CAMERA1"] == pytest.approx([-1.4, -4.6, 1.45], abs=1e-5), out.stdout
    assert lines["CAMERA8"] == pytest.approx([0.9, -4.0, 1.25], abs=1e-5)
    manifest = json.loads((build.parent / "manifest.json").read_text())
    assert lines["SIZE320"] == [180, 1, 8, manifest["radius"]]
    assert manifest["resolution"] == [320, 180]
