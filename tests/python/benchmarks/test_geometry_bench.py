"""aolab bench-table's geometry tables (core/python/aolab/benchmarks/geometry_bench.py): the radii
on screen it asks for, the upsampled scenes, the tables and the targets they judge; timings
themselves are never asserted."""

import json
import subprocess
import sys

import numpy as np
import pytest

import aolab
from aolab import scenes
from aolab.benchmarks import geometry_bench as gb
from aolab.benchmarks import mip_bench as mb


def test_median_projected_radius_on_a_plane():
    g = aolab.analytic_scene("plane", width=64, height=36)
    d = np.asarray(g.depth)[np.asarray(g.valid_mask(), bool)]
    assert scenes.median_projected_radius(g, 0.5) == pytest.approx(np.median(0.5 * g.fx / d))


@pytest.mark.parametrize("pixels", [16, 100.5, 256])
def test_the_radius_for_pixels_projects_to_them(pixels):
    g = aolab.analytic_scene("blocks", width=160, height=90)
    r = scenes.radius_for_pixels(g, pixels)
    assert scenes.median_projected_radius(g, r) == pytest.approx(pixels, rel=1e-9)


def test_upsampling_keeps_the_view_and_triples_the_radius_on_screen():
    g = aolab.analytic_scene("blocks", width=64, height=36)
    big = gb.upsampled(g, 3)
    assert (big.width, big.height) == (192, 108)
    # The intrinsics are float32 in the G-buffer: equal to float32 rounding.
    assert (big.fx, big.fy, big.cx, big.cy) == pytest.approx(
        (3 * g.fx, 3 * g.fy, 3 * g.cx, 3 * g.cy), rel=1e-6)
    # A source pixel's centre is the centre of its 3 x 3 block: its depth is kept there.
    assert np.allclose(np.asarray(big.depth)[1::3, 1::3], np.asarray(g.depth), rtol=1e-6)
    assert np.array_equal(np.asarray(big.normal)[2::3, ::3], np.asarray(g.normal))
    assert scenes.median_projected_radius(big, 0.25) == pytest.approx(
        3 * scenes.median_projected_radius(g, 0.25), rel=0.01)


@pytest.mark.parametrize("tilt", [0, 60])
def test_an_open_plane_stays_a_plane_upsampled(tilt):
    """Repeating pixels made stairs of a slanted plane, whose risers occlude; interpolating
    1/d keeps it a plane: the upsampled one is the analytic plane rendered at that size.
    (Where a plane is so grazing that neighbours differ by more than EDGE_JUMP, as at 80°
    near the horizon, it is taken for an edge and gets the nearest pixel's depth.)"""
    small = aolab.analytic_scene("plane", width=320, height=180, tilt=tilt)
    big = gb.upsampled(small, 3)
    exact = aolab.analytic_scene("plane", width=960, height=540, tilt=tilt)
    valid = np.asarray(exact.valid_mask(), bool) & np.asarray(big.valid_mask(), bool)
    assert np.allclose(np.asarray(big.depth)[valid], np.asarray(exact.depth)[valid], rtol=1e-4)
    ao = aolab.compute("hbao", big, radius=0.5)
    assert np.all(ao[np.asarray(big.valid_mask(), bool)] == 1.0)


def test_edges_are_not_interpolated_across():
    g = aolab.analytic_scene("blocks", width=64, height=36)
    # Away from the border (where planes are extrapolated by a third of a pixel), every
    # depth lies between the depths of its source neighbours: none bridges an edge.
    big = np.asarray(gb.upsampled(g, 3).depth)[3:-3, 3:-3]
    d = np.asarray(g.depth)
    lo, hi = np.nanmin(d), np.nanmax(d)
    assert np.all((big >= lo * (1 - 1e-6)) & (big <= hi * (1 + 1e-6)))


def _times():
    def t(scene, method, ms, target=True, px=None):
        return gb.SceneTimes(scene, method, (1280, 720) if target else (640, 360), 0.5, 40.0,
                             target, ms, px or {})
    px = {p: 10.0 + p / 10 for p in gb.PIXEL_RADII}
    slow = {p: 10.0 + p / 4 for p in gb.PIXEL_RADII}   # 74 ms at 256 px
    return [t("a", "hbao", 30.0, px=px), t("b", "hbao", 20.0, px=slow),
            t("a", "sao", 10.0, px=px), t("b", "sao", 12.0, px=px),
            t("c", "hbao", 8.0, target=False), t("c", "sao", 101.0, target=False)]


def test_targets_name_the_worst_case():
    rows = gb.targets(["hbao", "sao"], _times(),
                      [{"scene": "a", "radius_px": 64, "speedup": 15.5, "scalar_ms": 1,
                        "simd_ms": 1}, {"scene": "b", "radius_px": "own", "speedup": 20,
                                        "scalar_ms": 1, "simd_ms": 1}], None)
    by = {r["target"].split(" ")[0]: r for r in rows}
    assert not by["hbao"]["met"] and "74.0 ms (b, 256 px)" in by["hbao"]["measured"]
    assert by["sao"]["met"] and "35.6 ms (a, 256 px)" in by["sao"]["measured"]
    assert not by["HBAO"]["met"] and "15.5× (a, 64 px)" in by["HBAO"]["measured"]
    assert not by["Live"]["met"] and "101.0 ms (sao, c)" in by["Live"]["measured"]


def test_alternated_timing_takes_the_runs_in_turn():
    calls = []
    ms = gb.alternated_ms([lambda: calls.append("a"), lambda: calls.append("b"),
                           lambda: calls.append("c")], 3)
    assert calls == ["a", "b", "c"] * 4 and len(ms) == 3 and min(ms) >= 0


def test_scaling_targets_follow_the_worst_ratio():
    large = [{"scene": "a", "method": "sao", "ms": 90.0, "small_ms": 10.0, "ratio": 9.0},
             {"scene": "b", "method": "sao", "ms": 132.0, "small_ms": 12.0, "ratio": 11.0}]
    rows = gb.targets(["sao"], [], [], large)
    assert len(rows) == 1 and not rows[0]["met"] and "11.0× (b)" in rows[0]["measured"]
    assert "| sao | 11.0 | 111 | 10.0 | 11.0 (b) |" in gb.scaling_table(["sao"], large)


def test_tables_are_square():
    times = _times()
    for text in (gb.scene_table(["hbao", "sao"], times), gb.radius_table(["hbao", "sao"], times)):
        lines = text.splitlines()
        assert len({line.count("|") for line in lines}) == 1, text
    assert "| hbao | 30.0 | 20.0 | 25.0 | 30.0 | 8.0 | 8.0 (c) |" in gb.scene_table(
        ["hbao", "sao"], times)


def test_the_svg_has_a_curve_per_method_and_the_same_bits_twice(tmp_path):
    one, two = tmp_path / "1.svg", tmp_path / "2.svg"
    gb.plot_svg(["hbao", "sao"], _times(), one)
    gb.plot_svg(["hbao", "sao"], _times(), two)
    text = one.read_text()
    assert text.startswith("<?xml") and "hbao" in text and "sao" in text
    assert one.read_bytes() == two.read_bytes()


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "aolab", "bench-table", *args],
                          capture_output=True, text=True, timeout=600)


def test_cli_times_the_scenes_and_says_where_the_targets_stand(tmp_path):
    out = tmp_path / "rows.json"
    r = _cli("crytek_ssao", "--scene", "engine", "--scene", "organic_duck", "--size", "16x9",
             "--repeat", "1", "--json", str(out), "--svg", str(tmp_path / "t.svg"))
    assert r.returncode == 0, r.stderr
    text = r.stdout
    for heading in ("## Time at each scene's own R", "## Time against the radius on screen",
                    "## Scalar code against SIMD kernel", "## Where each target stands"):
        assert heading in text
    assert "| crytek_ssao | " in text and "engine (63 px)" in text
    data = json.loads(out.read_text())
    assert {t["scene"] for t in data["times"]} == {"engine", "organic_duck"}
    engine = next(t for t in data["times"] if t["scene"] == "engine")
    assert sorted(int(k) for k in engine["px_ms"]) == list(gb.PIXEL_RADII)
    assert [t["target"].split(" ")[0] for t in data["targets"]] == ["crytek_ssao", "Live"]
    assert (tmp_path / "t.svg").read_text().count("crytek_ssao") >= 1


def test_cli_refuses_an_unknown_scene_before_any_timing():
    r = _cli("crytek_ssao", "--scene", "no_such_scene", "--repeat", "1")
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.startswith("aolab: scene 'no_such_scene': no reference.exr found")
    assert len(r.stderr.strip().splitlines()) == 1


def test_mip_accuracy_table_means_pairs_and_floor():
    def errors(name, off, q4, floor):
        mae = {}
        for m in mb.METHODS:
            for q in mb.ACCURACY_Q:
                for region in mb.REGIONS:
                    mae[(m, q, region)] = off if q == 0 else q4
        change = {(m, q): 0.0 if q == 0 else 0.01 for m in mb.METHODS for q in mb.ACCURACY_Q}
        return mb.SceneErrors(name, mae, {"occluded": floor, "all": floor}, change)
    table = mb.accuracy_table([errors("a", 0.1, 0.2, 0.03), errors("b", 0.3, 0.25, 0.05)])
    lines = table.splitlines()
    assert len(lines) == 2 + len(mb.METHODS) * len(mb.ACCURACY_Q) + 1
    # q off: mean 0.2 of 0.1 and 0.3, the interval within them; no difference to itself.
    assert lines[2].startswith("| hbao | off | 0.0000 | 0.2000 [0.1000, 0.3000] | — |")
    # q = 4: +0.1 on one scene, -0.05 on the other.
    assert lines[3].startswith("| hbao | q = 4 | 0.0100 | 0.2250 [0.2000, 0.2500] | "
                               "+0.0250 (1 better, 1 worse; p = 1) |")
    assert lines[-1].startswith("| noise floor (2 scenes) |  |  | 0.0400 [0.0300, 0.0500] |")


def test_cli_mip_times_and_scores_with_the_noise_floor(tmp_path):
    out = tmp_path / "mip.json"
    r = _cli("--mip", "--scene", "engine", "--scene", "organic_duck", "--repeat", "1",
             "--json", str(out))
    assert r.returncode == 0, r.stderr
    assert "## mip_distance: time" in r.stdout and "## mip_distance: accuracy on 2" in r.stdout
    data = json.loads(out.read_text())
    # Only the 1280x720 scene is timed, at each radius on screen and each q.
    assert {(t["scene"], t["method"], t["px"]) for t in data["times"]} == {
        ("engine", m, px) for m in mb.METHODS for px in mb.TIME_RADII}
    assert all(len(t["ms"]) == len(mb.TIME_Q) for t in data["times"])
    for scene in data["accuracy"]:
        assert all(scene["change"][f"{m}/0"] == 0 for m in mb.METHODS)
        assert all(0 <= v <= 1 for v in scene["mae"].values())
        # q moves samples beyond 2q px onto other points of the same surfaces: the output
        # changes, a little (not at all where R covers less than 2q px on screen).
        assert all(0 <= scene["change"][f"{m}/{q:g}"] < 0.05
                   for m in mb.METHODS for q in mb.ACCURACY_Q)
        assert all(scene["change"][f"{m}/4"] > 0 for m in mb.METHODS)
        assert scene["floor"] is None or 0 < scene["floor"]["all"] < 0.1


def test_cli_mip_refuses_the_other_tables_options():
    r = _cli("hbao", "--mip", "--scaling")
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.strip() == ("aolab: --mip times hbao and bitmask at their medium preset "
                                "and takes no METHOD, --scaling")
