"""report.html of aolab compare: the pieces (WebP images, Pareto front, hover text, figures,
static SVG points), and the page in headless Chromium, driven through the DevTools protocol
(tests/python/support/browser.py): no console error, one trace per method in every plot,
hover naming the preset, a click opening the point's images, a legend click hiding a method in
the three plots of its section. The Chromium tests skip, saying why, only where Chromium is absent
(scripts/install-deps.sh installs it, so CI runs them)."""
from __future__ import annotations

import hashlib
import io
import json
import re
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import aolab
from aolab import cli, scoring
from aolab.study import charts, findings, report, report_files
from browser import Browser, chromium, plot_point, poll
from compare_support import CROP, make_scenes, parse_report
from browser import need_chromium


def test_webp_bytes_decode_close_to_the_image():
    grey = np.linspace(0, 1, 64 * 48, dtype=np.float32).reshape(48, 64)
    rgb = np.stack([grey, 1 - grey, np.full_like(grey, 0.5)], axis=2)
    for img in (grey, rgb):
        decoded = Image.open(io.BytesIO(report_files.webp_bytes(img)))   # (WebP has no grey)
        back = np.asarray(decoded.convert("L" if img.ndim == 2 else "RGB"), np.float64) / 255
        # lossy at IMAGE_QUALITY: a smooth ramp comes back within a few levels on average
        assert np.mean(np.abs(back - img)) < 4 / 255


def test_file_names_follow_the_content():
    out = report_files.Files()
    a = out.add("room_hbao/tuned 100ms_ao", ".webp", b"one")
    assert a.startswith("report_files/room_hbao_tuned_100ms_ao-") and a.endswith(".webp")
    assert out.add("room_hbao/tuned 100ms_ao", ".webp", b"one") == a
    assert out.add("room_hbao/tuned 100ms_ao", ".webp", b"two") != a
    assert out.add("room_hbao/medium_ao", ".webp", b"one") == a    # the same image: one file
    assert len(out.items) == 2
    assert report_files.referenced(f'<img src="{a}"><script>["{a}"]</script>') == {a}


def test_pareto_front():
    pts = [(1, 0.5, "a"), (2, 0.4, "b"), (3, 0.45, "c"), (4, 0.1, "d"), (4, 0.2, "e")]
    assert findings.pareto_front(pts, lower_is_better=True) == ["a", "b", "d"]
    assert findings.pareto_front(pts, lower_is_better=False) == ["a"]
    assert findings.pareto_front([(1, 0.9, "x"), (2, 0.95, "y")],
                                 lower_is_better=False) == ["x", "y"]


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


ROWS = [
    {"key": "s/m/a", "kind": "method", "method": "m", "label": "a", "total_ms": 10.0,
     "metrics": {"all": {"mae": 0.1}}},
    {"key": "s/m/b", "kind": "method", "method": "m", "label": "b", "total_ms": 100.0,
     "metrics": {"all": {"mae": 0.05}}},
    {"key": "s/e/x", "kind": "eevee", "method": "e", "label": "x", "total_ms": 5.0,
     "metrics": {"all": {"mae": 0.01}}},
    {"key": "s/baseline_one/AO=1", "kind": "baseline", "method": "baseline_one",
     "label": "AO=1", "metrics": {"all": {"mae": 0.2}}},
]


def test_svg_points_carry_their_row_and_values():
    svg = charts.svg_plot("p", ROWS, "all_mae", "MAE", True,
                          charts.hlines_for(ROWS, "all_mae", None))
    keys = re.findall(r'class="point[^"]*"[^>]*data-key="([^"]+)"', svg)
    assert sorted(keys) == ["s/e/x", "s/m/a", "s/m/b"]
    # EEVEE's time is not comparable: it is never on the front, though fastest and best
    assert re.findall(r'class="point front"[^>]*data-key="([^"]+)"', svg) == ["s/m/a", "s/m/b"]
    assert 'class="hline baseline" data-key="s/baseline_one/AO=1"' in svg


def test_the_figure_has_a_trace_per_series_the_front_and_the_lines():
    hovers = {r["key"]: r["key"] for r in ROWS}
    fig = charts.plotly_figure(ROWS, "all_mae", "MAE", True,
                               charts.hlines_for(ROWS, "all_mae", None), hovers)
    series = [t for t in fig["data"] if t["meta"]["role"] == "series"]
    assert [t["name"] for t in series] == ["m", "EEVEE GTAO (time not comparable)"]
    assert series[0]["customdata"] == ["s/m/a", "s/m/b"] and series[0]["x"] == [10.0, 100.0]
    # the front (EEVEE excluded) ringed and joined
    (front,) = [t for t in fig["data"] if t["meta"]["role"] == "front"]
    assert front["x"] == [10.0, 100.0] and front["line"]["shape"] == "hv"
    assert front["mode"] == "lines+markers" and front["marker"]["symbol"] == "circle-open"
    (line,) = [t for t in fig["data"] if t["meta"]["role"] == "hline"]
    assert line["meta"]["key"] == "s/baseline_one/AO=1" and line["y"] == [0.2, 0.2]
    assert fig["layout"]["xaxis"]["type"] == "log" and fig["layout"]["meta"]["column"] == "all_mae"
    assert "on the Pareto front" in series[0]["text"][0]


def test_hover_names_the_configuration_and_what_differs_from_the_defaults():
    defaults = {s["name"]: s["default"] for s in aolab.method_info("hbao")["settings"]}
    steps = defaults["steps"] + 3
    row = {"key": "ALL/hbao/tuned-100ms", "kind": "method", "method": "hbao",
           "label": "tuned-100ms", "preset": "tuned-100ms", "total_ms": 42.0, "n_scenes": 3,
           "settings": {**defaults, "steps": steps, "power": 0.6478010809295235, "blur": True,
                        "blur_sigma": 1.5, "blur_taps": 5},
           "intervals": {"total_ms": [40.0, 44.0], "all_mae": [0.02, 0.03],
                         "occluded_mae": None},
           "metrics": {"all": {"mae": 0.025, "ssim": 0.91}, "occluded": {"mae": 0.15}}}
    text = charts.hover_text(row, defaults, "click: image")
    assert text.startswith("<b>hbao</b> tuned-100ms")
    assert f"steps {steps}" in text and "power 0.6478" in text and "+ blur" in text
    assert "directions" not in text                  # as the default: not named
    assert "42.0 [40.0, 44.0] ms" in text and "MAE 0.0250 [0.0200, 0.0300]" in text
    assert "MAE occluded 0.1500<br>" in text and "SSIM 0.9100" in text
    assert "mean over 3 scene(s)" in text and text.endswith("<i>click: image</i>")
    plain = charts.hover_text({**row, "label": "default", "settings": dict(defaults)}, defaults,
                              "no image")
    assert "the method's defaults" in plain and "no image" in plain


# ---------------------------------------------------------------------------------------
# The page in Chromium

@pytest.fixture(scope="module")
def small_report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    scenes = make_scenes(tmp)
    out = tmp / "out"
    assert cli.main(["compare", "room", "--scenes-dir", str(scenes), "--out", str(out),
                     "--crop", CROP, "--repeat", "1", "--warmup", "0", "--no-progress"]) == 0
    return out / "report.html"


def dump_dom(path) -> str:
    need_chromium()
    res = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu",
                          "--disable-dev-shm-usage", "--virtual-time-budget=10000",
                          "--dump-dom", f"file://{path}"],
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
    copy = tmp_path / "copy"
    shutil.copytree(small_report.parent, copy)
    name = parse_report(small_report).images[0]["src"]     # an image of a grid
    (copy / name).write_bytes(b"not an image")
    title = re.search(r"<title>(AO Lab report[^<]*)</title>",
                      dump_dom(copy / "report.html")).group(1)
    assert title.startswith("AO Lab report: error") and "did not decode" in title


def test_report_html_alone_says_its_plots_did_not_load(small_report, tmp_path):
    shutil.copy(small_report, tmp_path / "report.html")     # without report_files/
    dom = dump_dom(tmp_path / "report.html")
    assert "The plots did not load" in dom and "plotly.js did not load" in dom
    assert "<table" in dom      # the tables are there


def test_without_plotly_js_the_report_says_so_and_draws_static_plots(
        small_report, tmp_path, monkeypatch):
    results = json.loads((small_report.parent / "results.json").read_text())
    monkeypatch.setattr(report_files, "plotly_js", lambda: None)
    page = tmp_path / "report.html"
    report.write_report(page, results, {})
    html = page.read_text(encoding="utf-8")
    assert html.count("plotly.js is not installed") == 1
    static = parse_report(page)
    assert '<svg class="plot"' in html and '<div class="plot"' not in html
    assert len(static.plots) == 6 and not static.figures and static.points
    assert "plotly" not in " ".join(report_files.referenced(html))


def test_the_report_in_chromium_hovers_clicks_and_hides(small_report):
    need_chromium()
    results = json.loads((small_report.parent / "results.json").read_text())
    with Browser() as b:
        b.open(small_report)
        title = b.evaluate("window.aolabReport.ready.then(() => document.title)")
        assert poll(b, "document.title.startsWith('AO Lab report: ok')"), b.evaluate(
            "document.title")
        assert b.errors == [], b.errors
        # one trace per method in every plot, named by the method
        plots = b.evaluate("""Array.from(document.querySelectorAll('div.plot')).map(gd => ({
            id: gd.id, section: gd.dataset.section,
            traces: gd._fullData.map(t => ({name: t.name, meta: t.meta || {},
                                            n: t.x.length}))}))""")
        assert len(plots) == 6, title
        for p in plots:
            methods = sorted({r["method"] for r in results["rows"]
                              if r["scene"] == p["section"] and r["kind"] == "method"})
            shown = sorted(t["name"] for t in p["traces"]
                           if t["meta"].get("role") == "series" and t["meta"]["kind"] == "method")
            assert shown == methods, p["id"]
        # hover a method's point of room's first plot, the one farthest from the others: the
        # hover names its method and preset (or those of a point under the cursor too)
        plot = "plot-room-all_mae"
        at = plot_point(b, plot)
        rows = {r["key"]: r for r in results["rows"]}
        b.mouse("mouseMoved", at["x"], at["y"])
        hover = poll(b, f"(document.querySelector('#{plot} .hovertext') || {{}}).textContent")
        named = [k for k in [at["key"], *at["near"]]
                 if hover and f"{rows[k]['method']} {rows[k]['label']}" in hover]
        assert named and "ms" in hover and rows[named[0]]["kind"] == "method", (hover, at)
        # a click opens its AO image and error map, which load
        b.mouse("mousePressed", at["x"], at["y"])
        b.mouse("mouseReleased", at["x"], at["y"])
        shots = poll(b, """(() => {
            const v = document.getElementById('viewer');
            const imgs = Array.from(v.querySelectorAll('img'));
            return !v.hidden && imgs.length && imgs.every(i => i.complete && i.naturalWidth)
                && imgs.map(i => i.getAttribute('src'));
        })()""")
        configs = parse_report(small_report).images_index["scenes"]["room"]["configs"]
        assert shots and any(set(configs[k.split("/", 1)[1]]) <= set(shots) for k in named), \
            (shots, named)
        b.evaluate("window.aolabReport.close()")
        # a legend click hides the method in the three plots of the section, and shows it
        legend = b.evaluate(f"""(() => {{
            const gd = document.getElementById('{plot}');
            const item = Array.from(gd.querySelectorAll('.legend .traces'))
                .find(g => g.textContent === 'hbao');
            const r = item.querySelector('.legendtoggle').getBoundingClientRect();
            return {{x: r.left + r.width / 2, y: r.top + r.height / 2}};
        }})()""")
        visible = ("Array.from(document.querySelectorAll('div.plot[data-section=room]')).map("
                   "gd => gd._fullData.find(t => t.name === 'hbao').visible)")
        for want in ("legendonly", True):
            b.mouse("mousePressed", legend["x"], legend["y"])
            b.mouse("mouseReleased", legend["x"], legend["y"])
            assert poll(b, f"({visible}).every(v => v === {json.dumps(want)})"), b.evaluate(
                visible)
            time.sleep(0.4)   # past plotly.js's double-click window
        # a double click shows it alone in the three plots; another shows every trace again
        shown = ("Array.from(document.querySelectorAll('div.plot[data-section=room]')).map("
                 "gd => gd._fullData.filter(t => t.visible === true).map(t => t.name))")
        # The double click is two press-release pairs dispatched in the page in one go: sent
        # as input events one round trip each, a loaded machine can space them further apart
        # than plotly.js's 300 ms double-click window (two single clicks then hide everything).
        double = f"""(() => {{
            const gd = document.getElementById('{plot}');
            const toggle = Array.from(gd.querySelectorAll('.legend .traces'))
                .find(g => g.textContent === 'hbao').querySelector('.legendtoggle');
            const o = {{bubbles: true, cancelable: true, view: window, button: 0,
                       clientX: {legend["x"]}, clientY: {legend["y"]}}};
            for (let k = 0; k < 2; k++) {{
                toggle.dispatchEvent(new MouseEvent('mousedown', o));
                toggle.dispatchEvent(new MouseEvent('mouseup', o));
            }}
            return true;
        }})()"""
        for alone in (True, False):
            b.evaluate(double)
            test = ("names.length === 1 && names[0] === 'hbao'" if alone else
                    "names.length > 1 && names.includes('hbao')")
            assert poll(b, f"({shown}).every(names => {test})"), b.evaluate(shown)
            time.sleep(0.4)
        assert b.errors == [], b.errors


def test_the_vendored_plotly_js_is_the_pinned_release():
    """core/web/vendor holds the file of the release core/web/package-lock.json pins (its
    header names the version), unchanged since scripts/update_plotly.sh wrote SHA256SUMS; and
    the build's copy is that file."""
    web = Path(__file__).resolve().parents[3] / "core" / "web"
    lock = json.loads((web / "package-lock.json").read_text())
    version = lock["packages"]["node_modules/plotly.js-basic-dist-min"]["version"]
    vendored = web / "vendor" / report_files.PLOTLY_FILE
    assert f"plotly.js (basic - minified) v{version}\n" in vendored.read_bytes()[:200].decode()
    sums = dict(reversed(line.split("  ", 1)) for line in
                (web / "vendor" / "SHA256SUMS").read_text().splitlines())
    for name, digest in sums.items():
        assert hashlib.sha256((web / "vendor" / name).read_bytes()).hexdigest() == digest, name
    assert set(sums) == {report_files.PLOTLY_FILE, "plotly.js-LICENSE"}
    built = report_files.plotly_js()
    assert built is not None and built.read_bytes() == vendored.read_bytes()
