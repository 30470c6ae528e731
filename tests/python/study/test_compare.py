"""aolab compare: the study's files, rows, peers, baseline, calibration, regions, presets,
interruption. Runs on two committed scenes cropped to 160x90 (one with synthetic peers)."""
from __future__ import annotations

import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import scenes
from aolab import cli, regions
from aolab import named_presets as presets
from aolab.catalog.kinds import MethodEntry
from aolab.cli.options import crop_of
from aolab.study import charts, compare, findings, report_files, report_tables, results_doc, runner
from aolab.study import results as results_mod
from compare_support import (CROP, LADDER, ROOT, SYNTHETIC_LIMITS, make_scenes, parse_report,
                             read_csv)
from compare_support import run_compare


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("compare")
    scenes = make_scenes(tmp)
    out = tmp / "out"
    assert run_compare(scenes, out) == 0
    return {"scenes": scenes, "out": out, "rows": read_csv(out / "results.csv"),
            "json": json.loads((out / "results.json").read_text()),
            "html": (out / "report.html").read_text(encoding="utf-8")}


def test_writes_the_report_files_and_nothing_half_written(study):
    out = study["out"]
    assert sorted(p.name for p in out.iterdir()) == ["report.html", "report_files",
                                                     "results.csv", "results.json"]
    assert study["json"]["meta"]["partial"] is False
    assert "PARTIAL" not in study["html"]
    # report_files/ holds exactly the files the page names: no temporary or stale file
    named = report_files.referenced(study["html"])
    assert {f"report_files/{p.name}" for p in (out / "report_files").iterdir()} == named
    assert any(n.endswith(".webp") for n in named) and any(n.endswith(".js") for n in named)


def studied_methods() -> list[str]:
    """What aolab compare runs when no method is named: every method but the bounds."""
    return [m for m in aolab.methods() if not aolab.method_info(m)["bound"]]


def test_bounds_run_only_when_named(study):
    bounds = [m for m in aolab.methods() if aolab.method_info(m)["bound"]]
    assert "screen_space_limit" in bounds
    assert not [r for r in study["rows"] if r["method"] in bounds]
    assert study["json"]["meta"]["methods"] == studied_methods()


def test_every_method_and_scene_appears(study):
    rows, html = study["rows"], study["html"]
    for scene in ("room", "grille", "ALL"):
        for method in studied_methods():
            mine = [r for r in rows if r["scene"] == scene and r["method"] == method]
            assert mine, (scene, method)
            assert {r["label"] for r in mine} >= {s.label for s in presets.settings_for(method)}
            assert f'data-key="{scene}/{method}/' in html
        assert any(r["kind"] == "baseline" for r in rows if r["scene"] == scene)
        assert f'plot-{scene}-all_mae' in html and f'plot-{scene}-occluded_mae' in html


def test_every_plotted_point_is_a_row_of_results_csv(study):
    rows = {r["key"]: r for r in study["rows"]}
    report = parse_report(study["out"] / "report.html")
    assert len(report.plots) == 9  # 3 plots each for ALL, room, grille
    assert len(report.points) > 0
    for p in report.points:
        row = rows[p["data-key"]]
        assert math.isclose(float(p["data-x"]), float(row["total_ms"]), rel_tol=1e-12)
        assert math.isclose(float(p["data-y"]), float(row[p["data-metric"]]), rel_tol=1e-12)
    for h in report.hlines:   # baseline and noise floor lines name their rows too
        assert h["data-key"] in rows
    # every timed, scored row is plotted on each of the three axes
    plotted = {(p["data-key"], p["data-metric"]) for p in report.points}
    for key, r in rows.items():
        if r["kind"] in ("method", "cycles", "eevee") and r["total_ms"] and r["all_mae"]:
            for metric in ("all_mae", "occluded_mae", "all_ssim"):
                assert (key, metric) in plotted


def test_peers_are_read_scored_and_shown(study):
    rows, html = study["rows"], study["html"]
    room = {r["method"]: r for r in rows if r["scene"] == "room"}
    for n in LADDER:
        r = room[f"cycles_{n}spp"]
        assert r["kind"] == "cycles"
        assert float(r["total_ms"]) == pytest.approx((0.05 * n + 0.4) * 1000)
    maes = [float(room[f"cycles_{n}spp"]["all_mae"]) for n in LADDER]
    assert maes == sorted(maes, reverse=True)       # more samples, less error
    assert room["eevee_gtao"]["kind"] == "eevee" and "not comparable" in room["eevee_gtao"]["note"]
    assert room["cycles_1024spp_seed2"]["kind"] == "noise_floor"
    assert "EEVEE GTAO (time not comparable)" in html
    assert "Cycles (fewer spp)" in html
    floor = study["json"]["scenes"]["room"]["noise_floor"]
    assert floor["estimated"] is False and floor["key"] == room["cycles_1024spp_seed2"]["key"]
    assert floor["all_mae"] == pytest.approx(float(room["cycles_1024spp_seed2"]["all_mae"]))
    assert not any(r["scene"] == "grille" and r["kind"] in ("cycles", "eevee") for r in rows)
    assert study["json"]["scenes"]["grille"]["noise_floor"] is None
    assert "This scene has no peers" in html


def test_limits_are_read_the_best_is_chosen_and_methods_are_measured_against_it(study):
    rows, info = study["rows"], study["json"]["scenes"]
    room = {r["method"]: r for r in rows if r["scene"] == "room"}
    for name, (label, _) in SYNTHETIC_LIMITS.items():
        assert room[name]["kind"] == "limit" and room[name]["label"] == label
    assert float(room["screen_space_limit_t0.25R"]["occluded_mae"]) < \
        float(room["screen_space_limit_t_inf"]["occluded_mae"])
    chosen = info["room"]["limit"]
    assert chosen["name"] == "screen_space_limit_t0.25R"
    assert chosen["occluded_mae"] == pytest.approx(
        float(room["screen_space_limit_t0.25R"]["occluded_mae"]))
    assert info["room"]["limits"] == list(SYNTHETIC_LIMITS) and "limit" not in info["grille"]
    # the approximation error: EEVEE's against the chosen limit, recomputed from the files
    g = aolab.load_gbuffer(ROOT / "reference_scenes" / "room" / "reference.exr")
    crop = crop_of(CROP).fit(g.width, g.height)
    scene = scenes.load_scene(study["scenes"] / "room", crop_of(CROP))
    occluded = scene.regions["occluded"]
    eevee = scenes.read_y_exr(study["scenes"] / "room" / "peers" / "eevee_gtao.exr")
    limit = scenes.read_y_exr(study["scenes"] / "room" / "limits" /
                              "screen_space_limit_t0.25R.exr")
    want = np.mean(np.abs(crop.apply(eevee)[occluded].astype(np.float64) -
                          crop.apply(limit)[occluded]))
    assert float(room["eevee_gtao"]["occluded_mae_vs_limit"]) == pytest.approx(want, rel=1e-6)
    for r in rows:
        if r["kind"] == "method" and r["all_mae"]:
            assert (r["occluded_mae_vs_limit"] != "") == (r["scene"] in ("room", "ALL"))
    # a limit line on the plots of room and ALL, none on grille
    lines = {(h["data-key"], h["data-metric"]) for h in parse_report(study["out"] /
                                                                     "report.html").hlines}
    assert ("room/screen_space_limit_t0.25R/T = 0.25 R", "occluded_mae") in lines
    assert not any(k.startswith("grille/screen_space_limit") for k, _ in lines)


def test_the_error_split_chart_shows_its_rows(study):
    rows = {r["key"]: r for r in study["rows"]}
    bars = parse_report(study["out"] / "report.html").bars
    assert bars
    shown = {b["data-key"] for b in bars}
    for method in studied_methods():
        assert f"ALL/{method}/default" in shown
    for b in bars:
        r = rows[b["data-key"]]
        value = float(b["data-value"])
        if b["data-part"] == "total":
            assert value == pytest.approx(float(r["occluded_mae"]))
        elif b["data-part"] == "approximation":
            assert value == pytest.approx(float(r["occluded_mae_vs_limit"]))
        elif b["data-part"] == "definition":   # an affine fit on the region never raises it
            assert value == pytest.approx(float(r["occluded_mae_definition"]))
            assert 0.0 <= value <= float(r["occluded_mae"])
        else:   # the mean over the scenes of each scene's chosen limit: room only here
            assert b["data-part"] == "screen_space"
            assert value == pytest.approx(study["json"]["scenes"]["room"]["limit"]["occluded_mae"])


def test_the_definition_part_is_what_an_affine_fit_on_the_occluded_region_removes(room):
    occluded = room.regions["occluded"]
    ref = room.reference.astype(np.float64)
    # a method that computes 0.5·reference + 0.4 has the right shape and a wrong definition
    distorted = np.where(room.regions["all"], 0.5 * ref + 0.4, 1.0).astype(np.float32)
    got = runner.score(distorted, room)["occluded_definition"]
    raw = np.mean(np.abs(distorted[occluded] - ref[occluded]))
    assert got == pytest.approx(raw, abs=2e-3)        # nearly all of its error
    assert runner.score(room.reference, room)["occluded_definition"] == pytest.approx(0.0)


def test_the_check_against_eevee_states_each_verdict():
    def row(scene, kind, method, occluded):
        return {"scene": scene, "kind": kind, "method": method, "label": method,
                "key": f"{scene}/{method}/{method}", "metrics": {"occluded": {"mae": occluded}}}

    def fold(mae, train_mae):
        return {"trial": 3, "mae": mae, "ms": 80.0, "within_budget": True,
                "train_mae": train_mae, "train_ms": 80.0}

    rows = []
    for scene, limit, eevee in (("P", 0.05, 0.10), ("F", 0.05, 0.10), ("L", 0.12, 0.10),
                                ("U", 0.05, None)):
        rows.append(row(scene, "limit", "screen_space_limit_t0.25R", limit))
        rows.append(row(scene, "limit", "screen_space_limit_t_inf", limit + 0.2))
        if eevee is not None:
            rows.append(row(scene, "eevee", "eevee_gtao", eevee))
    held = {"P": fold(0.08, 0.1), "F": fold(0.11, 0.1), "L": fold(0.2, 0.1), "U": fold(0.01, 0.1)}
    results = {"meta": {"scenes": ["P", "F", "L", "U"]}, "rows": rows,
               "tuned": {"methods": {"vao": {"selection": {"tuned-100ms": {"held_out": held}}}}}}
    checks = {c["scene"]: c for c in findings.eevee_check(results)}
    assert {s: c["verdict"] for s, c in checks.items()} == \
        {"P": "pass", "F": "fail", "L": "limit", "U": "unknown"}
    assert checks["P"]["limit"] == 0.05 and checks["P"]["limit_label"] == \
        "screen_space_limit_t0.25R" and checks["P"]["method"] == "vao"
    assert all(c["verdict"] == "unknown" for c in findings.eevee_check({**results, "tuned": None}))
    assert 'data-verdict="fail"' in report_tables.eevee_table(list(checks.values()))


def test_rtao_ladder_runs_where_a_mesh_is_timed_and_scored(study):
    rows = [r for r in study["json"]["rows"] if r["kind"] == "rtao"]
    room = sorted((r for r in rows if r["scene"] == "room"), key=lambda r: r["settings"]["rays"])
    assert [r["settings"]["rays"] for r in room] == list(compare.RTAO_LADDER)
    assert not [r for r in rows if r["scene"] == "grille"]   # no mesh there
    assert any("grille: rtao not run" in n for n in study["json"]["notes"])
    info = study["json"]["scenes"]["room"]["rtao"]
    assert info["triangles"] > 1000 and info["bvh_build_ms"] > 0
    for r in room:
        assert r["method"] == "rtao" and r["method_ms"] > 0 and r["total_ms"] == r["method_ms"]
        assert r["settings"]["bvh_build_ms"] == info["bvh_build_ms"]
        assert "built in" in r["note"] and "not in the time" in r["note"]
    # More rays, less error (the 64-ray MAE well under the 1-ray one), and the ray tracer is
    # unbiased: the 64-ray bias within the noise of the crop's pixels.
    mae = [r["metrics"]["all"]["mae"] for r in room]
    assert mae[-1] < 0.5 * mae[0]
    assert abs(room[-1]["metrics"]["all"]["bias"]) < 0.01
    report = parse_report(study["out"] / "report.html")
    keys = {r["key"] for r in room}
    assert keys & {p["data-key"] for p in report.points}
    assert "Against a CPU ray tracer" in study["html"]
    ladder = findings.rtao_ladder([r for r in study["json"]["rows"] if r["scene"] == "room"])
    assert [e["rays"] for e in ladder] == list(compare.RTAO_LADDER)
    assert all(e["winner"] in ("rtao", "screen space", "") for e in ladder)


def test_rtao_rays_option_is_checked_and_none_skips_it(tmp_path):
    scenes = tmp_path / "scenes"
    from compare_support import SCENES, link_scene
    link_scene(SCENES / "room", scenes / "room", mesh=True)
    assert run_compare(scenes, tmp_path / "out", "--methods", "crytek_ssao", "--sweep",
                       "quick", "--rtao-rays", "none") == 0
    rows = json.loads((tmp_path / "out" / "results.json").read_text())["rows"]
    assert not [r for r in rows if r["kind"] == "rtao"]
    for bad in ("0", "1,x", "70000", ""):
        assert run_compare(scenes, tmp_path / "o2", "--rtao-rays", bad) == 2


def test_baseline_scores_no_occlusion(study):
    g = aolab.load_gbuffer(ROOT / "reference_scenes" / "grille" / "reference.exr")
    crop = crop_of(CROP).fit(g.width, g.height)
    ref = crop.apply(g.reference).astype(np.float64)
    valid = crop.apply(g.valid_mask()) & np.isfinite(ref)
    base = next(r for r in study["rows"] if r["scene"] == "grille" and r["kind"] == "baseline")
    assert float(base["all_mae"]) == pytest.approx(np.mean(1 - ref[valid]), rel=1e-9)
    assert float(base["all_bias"]) == pytest.approx(np.mean(1 - ref[valid]), rel=1e-9)
    occ = valid & (ref < 0.9)
    assert float(base["occluded_mae"]) == pytest.approx(np.mean(1 - ref[occ]), rel=1e-9)
    assert base["total_ms"] == ""


def test_weak_flag_follows_the_stated_rule(study):
    rows = study["rows"]
    for r in rows:
        if r["kind"] != "method" or not r["occluded_mae"]:
            continue
        base = next(b for b in rows if b["scene"] == r["scene"] and b["kind"] == "baseline")
        ratio = float(r["occluded_mae"]) / float(base["occluded_mae"])
        assert float(r["occluded_mae_vs_baseline"]) == pytest.approx(ratio)
        assert (r["flag"] == "weak") == (ratio > compare.WEAK_FRACTION)


def test_settings_and_timings_are_recorded(study):
    meta = study["json"]["meta"]
    assert meta["machine"]["threads"] == 2 and meta["machine"]["cpu"]
    assert meta["repeat"] == 2 and meta["warmup"] == 0
    for r in study["json"]["rows"]:
        if r["kind"] == "method" and r["scene"] != "ALL":
            assert r["runs"] == 2 and r["method_ms_min"] <= r["method_ms"] <= r["method_ms_max"]
            s = r["settings"]
            assert "blur" in s
            if s["blur"]:
                assert r["blur_ms"] > 0
                assert r["total_ms"] == pytest.approx(r["method_ms"] + r["blur_ms"])
            if r["method"] == "pyramid_hbao":   # the builtin Gaussian is replaced by the timed one
                assert s["gaussian_filter"] is False
                # the paper's configurations keep it; a tuned one may go without
                assert s["blur"] is True or r["label"].startswith(presets.TUNED_PREFIX)
    agg = [r for r in study["json"]["rows"] if r["scene"] == "ALL" and r["kind"] == "method"]
    assert all(r["n_scenes"] == 2 for r in agg)


def test_aggregate_rows_are_means_over_scenes(study):
    rows = study["rows"]
    for r in rows:
        if r["scene"] != "ALL" or r["kind"] != "method":
            continue
        per = [x for x in rows if x["scene"] in ("room", "grille") and x["method"] == r["method"]
               and x["label"] == r["label"]]
        assert len(per) == 2
        for col in ("all_mae", "occluded_ssim", "total_ms"):
            assert float(r[col]) == pytest.approx(np.mean([float(x[col]) for x in per]))


def test_results_doc_is_regenerated_keeping_the_prose(study, tmp_path):
    path = results_doc.write(study["out"] / "results.json", tmp_path)
    text = path.read_text()
    assert results_doc.GENERATED_BEGIN in text and "## What the results show" in text
    for column, _, _ in charts.PLOTS:
        svg = tmp_path / "images" / f"results_{column}.svg"
        assert f"images/results_{column}.svg" in text and "<style>" in svg.read_text()
    for method in studied_methods():
        assert f"| {method} | medium |" in text
    # results.md opens with the prose and the means over the scenes; each scene's table is on
    # a page of its own, linked from it
    assert text.index("## What the results show") < text.index(results_doc.GENERATED_BEGIN)
    assert "[results_scenes.md](results_scenes.md)" in text and "\n## room\n" not in text
    scenes_page = (tmp_path / results_doc.SCENES_PAGE).read_text()
    assert "\n## room\n" in scenes_page and "| baseline_one |" in scenes_page
    path.write_text(text.replace("_To be written", "Our paragraph. _To be written"))
    results_doc.write(study["out"] / "results.json", tmp_path)
    again = path.read_text()
    assert "Our paragraph." in again and again.count(results_doc.GENERATED_BEGIN) == 1


def test_the_results_page_names_no_folder_of_the_machine_it_was_made_on(tmp_path):
    root = tmp_path / "checkout"
    note = (f"no mesh {root}/reference_scenes/a/reference.mesh: export one with "
            f"`aolab mesh SCENE --out {root}/reference_scenes/a`; run in {root}")
    assert results_doc.portable(note, root) == (
        "no mesh reference_scenes/a/reference.mesh: export one with "
        "`aolab mesh SCENE --out reference_scenes/a`; run in .")


# ---------------------------------------------------------------------------------------
# Scoring pieces


@pytest.fixture(scope="module")
def room():
    return scenes.load_scene(ROOT / "reference_scenes" / "room", crop_of("240x135"))


def test_whole_frame_scores_equal_aolab_metrics(room):
    ao = aolab.compute("hbao", room.g, radius=room.radius, directions=4, steps=4)
    s = runner.score(ao, room)["regions"]["all"]
    m = aolab.metrics(ao, room.reference, room.regions["all"])
    for k in ("mae", "rmse", "psnr", "bias", "ssim"):
        # SSIM: the same map, averaged in another order (float32 map, double sums)
        assert s[k] == pytest.approx(m[k], rel=1e-6 if k == "ssim" else 1e-9, abs=1e-12), k
    assert s["count"] == m["count"]


def test_calibration_removes_an_affine_distortion_and_never_raises_the_mae(room):
    valid = room.regions["all"]
    distorted = (0.5 * room.reference + 0.4).astype(np.float32)
    out = runner.score(distorted, room)
    assert out["calib_a"] == pytest.approx(2.0, rel=1e-3)
    assert out["calib_b"] == pytest.approx(-0.8, abs=1e-3)
    assert out["regions"]["all"]["mae_cal"] < 1e-4 < out["regions"]["all"]["mae"]
    ao = aolab.compute("lsao", room.g, radius=room.radius)
    s = runner.score(ao, room)["regions"]
    assert s["all"]["mae_cal"] <= s["all"]["mae"]
    a, b = runner.calibration(np.full_like(ao, 0.7), room.reference, valid)
    assert a == 0 and b == pytest.approx(np.median(room.reference[valid]))


def test_regions_on_analytic_scenes():
    w, h = 160, 90
    plane = aolab.analytic_scene("plane", w, h)
    m = regions.region_masks(plane, np.ones((h, w), np.float32), 1.0)
    assert not m["occluded"].any() and not m["creases"].any() and not m["depth_edges"].any()
    assert m["border"].sum() == w * h - (w - 2 * 8) * (h - 2 * 5)
    steep = aolab.analytic_scene("plane", w, h, tilt=85)
    assert regions.region_masks(steep, np.ones((h, w), np.float32), 1.0)["grazing"][h // 2].all()
    crease = aolab.analytic_scene("crease", w, h, radius=1.0)
    ref = np.nan_to_num(crease.reference, nan=1.0).astype(np.float32)
    m = regions.region_masks(crease, ref, 1.0)
    assert m["creases"].any() and not m["depth_edges"][m["creases"]].all()
    assert (m["occluded"] == (m["all"] & (ref < 0.9))).all()
    step = aolab.analytic_scene("step", w, h, step_height=10)   # depth 50 -> 40: 25 %
    edges = regions.region_masks(step, np.ones((h, w), np.float32), 1.0)["depth_edges"]
    cols = np.flatnonzero(edges.any(axis=0))
    assert edges[:, cols].all() and len(cols) == 2 * regions.EDGE_DILATION + 2   # 2 edge columns
    low = aolab.analytic_scene("step", w, h, step_height=1)    # 2 %: below the 5 % threshold
    assert not regions.region_masks(low, np.ones((h, w), np.float32), 1.0)["depth_edges"].any()


def test_dilate_is_a_square():
    m = np.zeros((9, 9), bool)
    m[4, 4] = True
    assert regions.dilate(m, 2).sum() == 25 and regions.dilate(m, 2)[2:7, 2:7].all()


# ---------------------------------------------------------------------------------------
# Presets


def test_every_method_has_settings_and_every_preset_is_accepted():
    g = aolab.analytic_scene("blocks", 32, 18)
    for method in aolab.methods():
        for sweep in ("quick", "presets", "full"):
            configs = presets.settings_for(method, sweep)
            assert configs and len({c.label for c in configs}) == len(configs)
        for c in presets.settings_for(method, "presets"):
            aolab.compute(method, g, radius=0.5, **c.compute_settings())


def test_full_sweep_points_are_accepted_by_the_methods():
    g = aolab.analytic_scene("blocks", 16, 9)
    for method in aolab.methods():
        for c in presets.settings_for(method, "full"):
            aolab.compute(method, g, radius=0.5, **c.compute_settings())


def test_full_sweep_runs_each_computation_once(monkeypatch, tmp_path):
    """Grid points never repeat each other or a named configuration; the named ones (the
    defaults, the presets, the tuned presets) keep their names even when two compute the same
    (lsao's defaults are its medium preset), and the study runs the method once for both."""
    monkeypatch.setenv("AOLAB_TUNED_PRESETS", str(tmp_path / "none.json"))
    for method in aolab.methods():
        configs = presets.settings_for(method, "full")
        named = {presets.identity(method, c.settings, c.blur) for c in configs if c.preset}
        grid = [presets.identity(method, c.settings, c.blur) for c in configs if not c.preset]
        assert len(set(grid)) == len(grid) and not set(grid) & named, method
        assert configs[0].label == "default" and configs[0].settings == {}
        runs = compare._method_runs(method, "full")
        assert sum(len(group) for _, group in runs) == len(configs)
        assert len(runs) == len({presets.identity(method, c.compute_settings(), False)
                                 for c in configs})
    full = {c.label for c in presets.settings_for("hbao", "full")}
    assert {"default", "low", "medium", "high", "ultra"} <= full
    medium = "directions=8,steps=8,incremental_attenuation=0,attenuation=linear,"
    assert medium + "integral=uniform,blur=1" not in full      # = medium, run under its name
    assert medium + "integral=cosine,blur=1" in full           # the reference's integral
    # 4 x 4 counts x (eq. 3 or eq. 2 attenuation, or none) x 2 integrals, blurred; the
    # presets replace 4 of those points; "default" (no blur) is not a grid point
    assert len(full) == 4 * 4 * 3 * 2 + 1
    assert not [c for c in full if "attenuation=none" in c and "incremental_attenuation=1" in c]
    lsao = {c.label: c for c in presets.settings_for("lsao", "quick")}
    assert presets.identity("lsao", lsao["default"].settings, False) == \
        presets.identity("lsao", lsao["medium"].settings, False)
    (run,) = [group for _, group in compare._method_runs("lsao", "quick")
              if "default" in [c.label for c in group]]
    assert [c.label for c in run] == ["default", "medium"]      # one run for both


def test_tuned_presets_join_every_sweep(monkeypatch, tmp_path):
    path = tmp_path / "tuned.json"
    path.write_text(json.dumps({"methods": {"vao": {"presets": {
        "tuned-50ms": {"samples": 6, "blur": True}, "tuned-200ms": {"samples": 20,
                                                                    "blur": False}}}}}))
    monkeypatch.setenv("AOLAB_TUNED_PRESETS", str(path))
    for sweep in ("quick", "presets", "full"):
        got = {c.label: c for c in presets.settings_for("vao", sweep)}
        assert got["tuned-50ms"].settings == {"samples": 6} and got["tuned-50ms"].blur
        assert got["tuned-200ms"].settings == {"samples": 20} and not got["tuned-200ms"].blur
    assert "tuned-50ms" not in {c.label for c in presets.settings_for("lsao", "quick")}


def test_a_method_without_presets_runs_its_defaults_and_registering_is_checked():
    (only,) = presets.settings_for("some_future_method", "full")
    assert only.label == "default" and only.settings == {} and not only.blur
    with pytest.raises(ValueError, match="presets of x must be named"):
        MethodEntry("x", presets={"best": {}}, sweep={})
    with pytest.raises(ValueError, match="sweep"):
        presets.settings_for("hbao", "everything")


def test_rgb_outputs_and_errors_are_recorded_not_scored(room, monkeypatch):
    study = compare.Study(compare.Options(repeat=1, warmup=0))
    images = compare._Images(1e9, room, 480)
    rgb = np.ones((room.g.height, room.g.width, 3), np.float32)
    monkeypatch.setattr(aolab, "compute", lambda *a, **k: rgb)
    cfg = presets.Setting("vao_pp", "default", {}, False, "default")
    study._run_config(room, "vao_pp", {}, [cfg], 1, images)
    (row,) = study.rows
    assert "metrics" not in row and "RGB" in row["note"] and row["total_ms"] >= 0

    def bad(*a, **k):
        raise ValueError("directions must be in [1, 64], got 0")
    monkeypatch.setattr(aolab, "compute", bad)
    study._run_config(room, "hbao", {"directions": 0}, [cfg], 1, images)
    assert study.rows[-1]["note"].startswith("error: directions")
    flat = results_mod.flat(study.rows[-1])
    assert flat["all_mae"] is None and list(flat) == results_mod.columns()


# ---------------------------------------------------------------------------------------
# Interruption and the command


def test_interrupt_keeps_partial_results(tmp_path, monkeypatch, capsys):
    """An interrupted study leaves its partial results in the staging folder <out>.partial/
    beside the output folder, says so, and writes nothing into the output folder."""
    scenes = make_scenes(tmp_path)
    calls = {"n": 0}
    real = compare.Study._run_config

    def interrupting(self, scene, *a, **k):
        if scene.name == "room":   # grille (sorted first) completes, room is interrupted
            calls["n"] += 1
            if calls["n"] == 3:
                raise KeyboardInterrupt
        return real(self, scene, *a, **k)

    monkeypatch.setattr(compare.Study, "_run_config", interrupting)
    out = tmp_path / "out"
    staging = tmp_path / "out.partial"
    assert run_compare(scenes, out, "--methods", "lsao", "hbao") == 130
    err = capsys.readouterr().err
    assert "interrupted" in err and "Partial results" in err and f"{staging}/" in err
    assert f"nothing was written to {out}/" in err
    assert not out.exists() or not list(out.iterdir())
    rows = read_csv(staging / "results.csv")
    assert {r["scene"] for r in rows if r["kind"] == "method"} == {"grille", "room", "ALL"}
    first_two = sum(len(group) for _, group in compare._method_runs("lsao", "quick")[:2])
    assert len([r for r in rows if r["scene"] == "room" and r["kind"] == "method"]) == first_two
    data = json.loads((staging / "results.json").read_text())
    assert data["meta"]["partial"] is True and data["meta"]["complete_scenes"] == ["grille"]
    html = (staging / "report.html").read_text(encoding="utf-8")
    assert "PARTIAL results" in html
    assert sorted(p.name for p in staging.iterdir()) == ["report.html", "report_files",
                                                         "results.csv", "results.json"]


def test_command_line_errors_are_clear(tmp_path):
    def run(*args):
        return subprocess.run([sys.executable, "-m", "aolab", "compare", *args],
                              capture_output=True, text=True)
    res = run("nonexistent_scene", "--scenes-dir", str(tmp_path))
    assert res.returncode == 2 and "nonexistent_scene" in res.stderr
    res = run("--crop", "big", "--scenes-dir", str(tmp_path))
    assert res.returncode == 2 and "--crop must be WxH" in res.stderr
    res = run("--methods", "nope", "--scenes-dir", str(ROOT / "reference_scenes"))
    assert res.returncode == 2 and "nope" in res.stderr
    assert "--sweep" in run("--help").stdout


@pytest.mark.slow
def test_default_run_on_the_committed_references(tmp_path):
    """The README's run command at full cost (a few minutes on 2 cores)."""
    res = subprocess.run([sys.executable, "-m", "aolab", "compare", "--out", str(tmp_path)],
                         cwd=ROOT, capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    rows = read_csv(tmp_path / "results.csv")
    scenes = sorted(p.name for p in (ROOT / "reference_scenes").iterdir()
                    if (p / "reference.exr").exists() and aolab.scenes.in_default_study(p))
    assert len(scenes) >= 9   # the six, and the corpus's organic, clutter and terrain
    assert sorted({r["scene"] for r in rows} - {"ALL"}) == scenes
    report = parse_report(tmp_path / "report.html")
    keys = {r["key"] for r in rows}
    assert report.points and all(p["data-key"] in keys for p in report.points)


def test_choice_settings_are_named_in_presets_sweeps_and_results():
    """A choice setting (chebyshev kernel_mode, vao_pp culling, ...) is given by name in every
    preset and sweep point, and recorded by name in results.csv."""
    named = 0
    for method in aolab.methods():
        choices = {s["name"]: s["choices"] for s in aolab.method_info(method)["settings"]
                   if s["type"] == "choice"}
        for s in presets.settings_for(method, "full"):
            for name, value in s.recorded_settings().items():
                if name in choices:
                    assert value in choices[name], (method, s.label, name, value)
                    named += 1
            row = {"settings": s.recorded_settings()}
            assert json.loads(results_mod.flat(row)["settings"]) == s.recorded_settings()
    assert named > 0


# ---------------------------------------------------------------------------------------
# Hostile scenes: refused with a ValueError naming the scene, before any work


def small_scene(folder: Path, reference=None, sidecar=None) -> Path:
    """A scene folder with a 64x36 analytic G-buffer as reference.exr (R 0.25 unless the
    sidecar says otherwise)."""
    folder.mkdir(parents=True)
    g = aolab.analytic_scene("blocks", 64, 36, radius=0.25)
    if reference is None:   # the closed form where the scene has one, else 1
        reference = np.nan_to_num(np.asarray(g.reference, np.float32), nan=1.0)
    aolab.save_gbuffer(folder / "reference.exr", g, reference=reference,
                       sidecar={"ao_distance": 0.25} if sidecar is None else sidecar)
    return folder


def compare_cli(scenes: Path, out: Path, *extra) -> int:
    return cli.main(["compare", *extra, "--scenes-dir", str(scenes), "--out", str(out),
                     "--methods", "lsao", "--repeat", "1", "--warmup", "0", "--threads", "2",
                     "--no-progress"])


def test_a_sidecar_without_ao_distance_is_refused_naming_the_scene_and_key(tmp_path, capsys):
    small_scene(tmp_path / "scenes" / "a_good")
    small_scene(tmp_path / "scenes" / "no_radius", sidecar={"title": "no R"})
    with pytest.raises(ValueError, match=r"scene 'no_radius'.*'ao_distance'"):
        scenes.load_cropped(tmp_path / "scenes" / "no_radius")
    out = tmp_path / "out"
    assert compare_cli(tmp_path / "scenes", out) == 2
    err = capsys.readouterr().err
    assert err.startswith("aolab: scene 'no_radius'") and "ao_distance" in err
    # refused before any work: the good scene (sorted first) was not run either
    assert not out.exists() and not (tmp_path / "out.partial").exists()


@pytest.mark.parametrize("value", [0, -1, "far", None])
def test_an_invalid_ao_distance_is_refused(tmp_path, value):
    folder = small_scene(tmp_path / "bad_r")
    side = json.loads((folder / "reference.json").read_text())
    (folder / "reference.json").write_text(json.dumps(dict(side, ao_distance=value)))
    with pytest.raises(ValueError, match=r"bad_r.*ao_distance|ao_distance.*bad_r"):
        scenes.load_cropped(folder)


def test_an_all_nan_reference_is_refused_naming_the_scene(tmp_path, capsys):
    small_scene(tmp_path / "scenes" / "nan_ref", reference=np.full((36, 64), np.nan, np.float32))
    with pytest.raises(ValueError, match=r"scene 'nan_ref'.*no finite value on any geometry"):
        scenes.load_cropped(tmp_path / "scenes" / "nan_ref")
    assert compare_cli(tmp_path / "scenes", tmp_path / "out", "nan_ref") == 2
    err = capsys.readouterr().err
    assert "scene 'nan_ref'" in err and "NaN" in err
    # a reference that is NaN in part is scored on its finite pixels
    part = np.asarray(aolab.analytic_scene("blocks", 64, 36, radius=0.25).reference)
    part = np.nan_to_num(part, nan=1.0).astype(np.float32)
    part[:, :32] = np.nan
    small_scene(tmp_path / "half_nan", reference=part)
    g, ref, radius, _ = scenes.load_cropped(tmp_path / "half_nan")
    assert radius == 0.25 and np.isnan(ref).any()


def test_a_slow_first_run_is_the_only_timed_run():
    calls = []

    def slow():
        calls.append(1)
        time.sleep(0.02)
        return len(calls)

    out, times = runner.timed(slow, warmup=1, repeat=3, max_ms=5.0)
    assert (out, len(calls), len(times)) == (1, 1, 1) and times[0] >= 20.0
    calls.clear()
    out, times = runner.timed(slow, warmup=1, repeat=3)   # no cap: warm-up + 3 timed
    assert (out, len(calls), len(times)) == (1, 4, 3)


def test_all_rows_carry_intervals_and_the_report_says_which_differences_are_real(study):
    """Every ALL row has 95 % bootstrap intervals over the two scenes that hold its mean; the
    report and results.md rank the best configurations with paired comparisons; the plots
    draw the intervals as bars; the defaults worse than AO = 1 are named."""
    results = study["json"]
    agg = [r for r in results["rows"] if r["scene"] == "ALL" and r["kind"] == "method"]
    assert agg
    for r in agg:
        lo, hi = r["intervals"]["occluded_mae"]
        assert lo <= r["metrics"]["occluded"]["mae"] + 1e-12 and hi >= lo
    html = study["html"]
    assert 'id="paired"' in html and 'class="ci"' in html and 'id="worse-than-nothing"' in html
    entries = findings.paired_comparisons(results, results["meta"]["budget_ms"])
    assert entries[0]["vs_above"] is None and all(e["vs_first"] for e in entries[1:])
    assert [e["mae"] for e in entries] == sorted(e["mae"] for e in entries)
    stills = runner.still_scenes(results["scenes"])
    base = {r["scene"]: r["metrics"]["all"]["mae"] for r in results["rows"]
            if r["kind"] == "baseline" and r["scene"] in stills}
    for e in entries:   # each passes the whole-frame guard against AO = 1 on every scene
        mine = {r["scene"]: r["metrics"]["all"]["mae"] for r in results["rows"]
                if r["scene"] in stills and r["kind"] == "method"
                and (r["method"], r["label"]) == (e["method"], e["label"])}
        assert runner.whole_frame_ok(mine, base)
    for e in entries[1:]:   # two scenes: the smallest exact p-value is 0.5, never "real"
        assert e["vs_above"]["n"] == 2 and not e["vs_above"]["real"]
    worse = findings.worse_than_nothing(results)
    base = {r["scene"]: r["metrics"]["all"]["mae"] for r in results["rows"]
            if r["kind"] == "baseline"}
    for w in worse:
        for s in w["scenes"]:
            assert s["mae"] > base[s["scene"]] == s["ao_one"]
    text = "\n".join(results_doc.study_sections(findings.study_findings(results, agg), "images"))
    assert "## Which differences are real" in text and "## Defaults worse than no occlusion" in text


def test_tests_over_scenes_count_stills_not_a_sequence_s_frames():
    """A sequence's frames are one camera path: the paired tests and the defaults worse than
    AO = 1 count the still scenes that the ALL rows average, as the ALL rows do."""
    def row(scene, kind, method, label, all_mae, occ):
        return {"scene": scene, "kind": kind, "method": method, "label": label,
                "metrics": {"all": {"mae": all_mae}, "occluded": {"mae": occ}}}
    scenes = {"a": {}, "b": {}, "seq@0001": {}, "seq@0002": {},
              "seq": {"sequence": True, "frame_scenes": ["seq@0001", "seq@0002"]}}
    rows = []
    for s in ("a", "b", "seq@0001", "seq@0002"):
        rows += [row(s, "baseline", "baseline_one", "AO=1", 0.05, 0.3),
                 row(s, "method", "hbao", "default", 0.06, 0.2)]
    results = {"scenes": scenes, "rows": rows}
    assert runner.still_scenes(results["scenes"]) == ["a", "b"]
    assert set(findings.per_scene(results, rows[1])) == {"a", "b"}
    assert [s["scene"] for s in findings.worse_than_nothing(results)[0]["scenes"]] == ["a", "b"]
