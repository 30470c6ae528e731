"""report.html of aolab compare: the pieces (PNG, Pareto front, SVG points) and the page in
headless Chromium (skipped, with the reason, where Chromium is absent)."""
from __future__ import annotations

import re
import shutil
import subprocess

import numpy as np
import OpenImageIO as oiio
import pytest

from aolab import cli, scoring
from aolab.study import report
from compare_support import CROP, make_scenes, parse_report


def test_png_bytes_decode_to_the_image(tmp_path):
    grey = np.linspace(0, 1, 7 * 5, dtype=np.float32).reshape(5, 7)
    rgb = np.stack([grey, 1 - grey, np.full_like(grey, 0.5)], axis=2)
    for name, img in (("g.png", grey), ("c.png", rgb)):
        path = tmp_path / name
        path.write_bytes(report.png_bytes(img))
        back = oiio.ImageBuf(str(path)).get_pixels(oiio.UINT8)
        expect = np.round(img * 255).astype(np.uint8)
        assert back.reshape(expect.shape).tolist() == expect.tolist()


def test_pareto_front():
    pts = [(1, 0.5, "a"), (2, 0.4, "b"), (3, 0.45, "c"), (4, 0.1, "d"), (4, 0.2, "e")]
    assert report.pareto_front(pts, lower_is_better=True) == ["a", "b", "d"]
    assert report.pareto_front(pts, lower_is_better=False) == ["a"]
    assert report.pareto_front([(1, 0.9, "x"), (2, 0.95, "y")], lower_is_better=False) == ["x", "y"]


def test_signed_error_colours():
    # One definition for the report's images and the add-on's error maps (aolab.scoring).
    err = np.array([[0.0, 1.0, -1.0, 0.125, 0.5]])
    rgb = scoring.signed_error_rgb(err)
    assert rgb[0, 0].tolist() == [1, 1, 1]
    assert rgb[0, 1].tolist() == list(scoring.LIGHTER_RGB)
    assert rgb[0, 2].tolist() == list(scoring.DARKER_RGB)
    assert rgb[0, 3] == pytest.approx((np.ones(3) + np.array(scoring.LIGHTER_RGB)) / 2)
    valid = np.array([[True, True, True, True, False]])
    masked = scoring.signed_error_rgb(err, valid=valid)
    assert masked[0, 4].tolist() == [scoring.BACKGROUND_GREY] * 3
    assert np.array_equal(masked[0, :4], rgb[0, :4])


def test_svg_points_carry_their_row_and_values():
    rows = [
        {"key": "s/m/a", "kind": "method", "method": "m", "label": "a", "total_ms": 10.0,
         "metrics": {"all": {"mae": 0.1}}},
        {"key": "s/m/b", "kind": "method", "method": "m", "label": "b", "total_ms": 100.0,
         "metrics": {"all": {"mae": 0.05}}},
        {"key": "s/e/x", "kind": "eevee", "method": "e", "label": "x", "total_ms": 5.0,
         "metrics": {"all": {"mae": 0.01}}},
        {"key": "s/baseline_one/AO=1", "kind": "baseline", "method": "baseline_one",
         "label": "AO=1", "metrics": {"all": {"mae": 0.2}}},
    ]
    svg = report.svg_plot("p", rows, "all_mae", "MAE", True,
                          report.hlines_for(rows, "all_mae", None))
    keys = re.findall(r'class="point[^"]*"[^>]*data-key="([^"]+)"', svg)
    assert sorted(keys) == ["s/e/x", "s/m/a", "s/m/b"]
    # EEVEE's time is not comparable: it is never on the front, though fastest and best
    assert re.findall(r'class="point front"[^>]*data-key="([^"]+)"', svg) == ["s/m/a", "s/m/b"]
    assert 'class="hline baseline" data-key="s/baseline_one/AO=1"' in svg


def chromium():
    return shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.fixture(scope="module")
def small_report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    scenes = make_scenes(tmp)
    out = tmp / "out"
    assert cli.main(["compare", "room", "--scenes-dir", str(scenes), "--out", str(out),
                     "--crop", CROP, "--repeat", "1", "--warmup", "0", "--no-progress"]) == 0
    return out / "report.html"


def dump_dom(path) -> str:
    exe = chromium()
    if exe is None:
        pytest.skip("Chromium is not installed (Debian: apt-get install chromium; "
                    "scripts/install-deps.sh installs it)")
    res = subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu",
                          "--disable-dev-shm-usage", "--dump-dom", f"file://{path}"],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr[-2000:]
    return res.stdout


def test_report_renders_in_headless_chromium(small_report):
    dom = dump_dom(small_report)
    title = re.search(r"<title>(AO Lab report[^<]*)</title>", dom).group(1)
    assert title.startswith("AO Lab report: ok"), title
    points = parse_report(small_report)
    n_plots, n_points = re.search(r"(\d+) plots, (\d+) points", title).groups()
    assert int(n_plots) == len(points.plots) == 6 and int(n_points) == len(points.points)
    assert "Cycles (fewer spp)" in dom and "EEVEE GTAO" in dom


def test_the_self_check_reports_a_broken_image(small_report, tmp_path):
    broken = tmp_path / "broken.html"
    html = small_report.read_text(encoding="utf-8")
    broken.write_text(html.replace("data:image/png;base64,", "data:image/png;base64,AAAA", 1),
                      encoding="utf-8")
    title = re.search(r"<title>(AO Lab report[^<]*)</title>", dump_dom(broken)).group(1)
    assert title.startswith("AO Lab report: error") and "did not decode" in title
