"""report.html of ``aolab compare``, with its files in report_files/ beside it
(report_files.py: images as WebP, plotly.js, report.js; nothing from the network, so the folder
works copied anywhere and from a file:// URL). The page is one view of findings.py's findings
(docs/results.md, by results_doc.py, is the other); its plots are charts.py's and its tables
report_tables.py's.

The accuracy-against-time plots are plotly.js figures, each held as JSON in the page (a
<script type="application/json" class="figure" data-plot="ID"> beside its <div class="plot"
id="ID">) and drawn by report.js: one trace per method and per peer series, hover naming the
configuration, a legend that hides and shows methods, a click that opens the point's AO image
and error map. Every plotted point's customdata is the key of its row in results.csv, its x
total_ms and its y the value of the column in layout.meta.column, so a test can match every
point to its row. Without plotly.js (not installed) the same plots are static SVG
(charts.svg_plot, also docs/results.md's), whose points are elements of class ``point`` with
``data-key``, ``data-metric``, ``data-x`` and ``data-y``.

On load, the page checks that every image decoded and every plot has points and writes the
outcome into document.title: "AO Lab report: ok ..." or "AO Lab report: error ...".
"""

from __future__ import annotations

import html
import json
from pathlib import Path

import aolab

from ..util import files
from . import report_files, stats
from .charts import PLOTS, frame_lines, frames_figure, frames_plot, hlines_for, hover_text
from .charts import plotly_figure, split_chart, svg_plot, SVG_CSS
from .findings import (AGGREGATE, EEVEE_CHECK_BUDGET_MS, FRAMES_PRESET, LARGEST_TUNED_BUDGET_MS,
                       StudyFindings, flicker_entries, is_accumulated, study_findings)
from .report_tables import (accumulation_html, eevee_table, flicker_table, image_files,
                            image_grid, paired_table, rtao_table, table, tuned_table,
                            worse_than_nothing_html)

#: What json_for_html writes as JSON escapes: "<" and ">" (so that no "</script", "<!--" or
#: "<script" of a user's string ends or changes the script element around it), "&", and the
#: two line separators JavaScript source once refused.
_JSON_IN_HTML = str.maketrans({"<": "\\u003c", ">": "\\u003e", "&": "\\u0026",
                               "\u2028": "\\u2028", "\u2029": "\\u2029"})


def json_for_html(value) -> str:
    """``value`` as JSON that is inert inside an HTML element: the one encoder of every JSON
    the page holds (the same value to JSON.parse, nothing an HTML parser acts on)."""
    return json.dumps(value, separators=(",", ":"), allow_nan=False).translate(_JSON_IN_HTML)


def _json_script(value, cls: str, **attrs) -> str:
    """``value`` as JSON in an inert <script type="application/json"> (json_for_html)."""
    extra = "".join(f' {k.replace("_", "-")}="{html.escape(v)}"' for k, v in attrs.items())
    return f'<script type="application/json" class="{cls}"{extra}>{json_for_html(value)}</script>'


CSS = SVG_CSS + """
body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;margin:24px auto;max-width:1500px;
 padding:0 16px;color:#222;line-height:1.4}
h1{margin-bottom:4px} h2{border-bottom:2px solid #ddd;padding-bottom:4px;margin-top:40px}
.banner{background:#fde2e1;border:2px solid #c0392b;padding:10px 14px;font-weight:bold;
 margin:12px 0}
.meta td{padding:1px 12px 1px 0;vertical-align:top} .meta td:first-child{color:#666}
.plots{display:flex;flex-wrap:wrap;gap:12px}
table.results{border-collapse:collapse;font-size:12px;margin:8px 0}
table.results th,table.results td{border:1px solid #ddd;padding:2px 6px;text-align:right}
table.results td:first-child,table.results td:nth-child(2){text-align:left}
table.results th{background:#f4f4f4;position:sticky;top:0}
tr.baseline{background:#fbeaea} tr.cycles,tr.noise_floor{background:#f3f3f3}
tr.eevee{background:#fbf5e6} tr.limit{background:#edf6ee} tr.rtao{background:#f5eef8}
table.check{border-collapse:collapse;font-size:13px} .check td,.check th{border:1px solid #ddd;
 padding:2px 8px;text-align:right} .check td:first-child{text-align:left}
.pass{color:#2e7d32;font-weight:bold} .fail{color:#c0392b;font-weight:bold}
tr.floor{background:#eaf7ee;font-style:italic}
.weak{color:#c0392b;font-weight:bold}
.grid{display:flex;flex-wrap:wrap;gap:10px}
.card{margin:0;border:1px solid #ddd;padding:6px;background:#fafafa}
.card img{display:inline-block;margin:4px 4px 0 0;vertical-align:top} figcaption{font-size:12px}
.legendbar{font-size:12px;margin:6px 0;display:flex;align-items:center;gap:8px}
.missing{color:#a05a00} .note{color:#555;font-size:13px} .scroll{overflow-x:auto}
div.plot{border:1px solid #ddd;background:#fff;width:720px;height:440px}
tr.has-image{cursor:pointer} tr.has-image:hover{background:#eef4fb}
#viewer{position:fixed;inset:0;background:rgba(0,0,0,0.55);z-index:10;overflow:auto}
#viewer[hidden]{display:none}
.viewer-box{background:#fff;margin:3vh auto;max-width:1500px;padding:12px 16px;
 position:relative;border-radius:4px}
.viewer-box button{position:absolute;right:10px;top:8px;font-size:20px;border:0;
 background:none;cursor:pointer}
.viewer-caption{font-size:13px;margin:0 30px 8px 0}
.viewer-row{display:flex;flex-wrap:wrap;gap:8px;align-items:flex-start;margin:6px 0}
.viewer-scene{width:100%;font-weight:bold;font-size:13px}
figure.shot{margin:0} figure.shot img{display:block;max-width:100%;height:auto;
 border:1px solid #ddd} figure.shot figcaption{font-size:12px;color:#555;max-width:480px}
"""


CHECK_SCRIPT = """
window.addEventListener('load', function () {
  var ready = (window.aolabReport && window.aolabReport.ready) || Promise.resolve();
  ready.then(function () {
    var problems = [];
    var imgs = document.images;
    for (var i = 0; i < imgs.length; i++) {
      if (!imgs[i].complete || imgs[i].naturalWidth === 0)
        problems.push('image "' + imgs[i].alt + '" did not decode');
    }
    var plots = document.querySelectorAll('svg.plot, div.plot');
    if (plots.length === 0) problems.push('no plot');
    if (document.querySelector('div.plot') && !window.Plotly) {
      problems.push('plotly.js did not load');
      var line = document.createElement('p');
      line.className = 'missing';
      line.textContent = 'The plots did not load: their scripts are missing from ' +
          'report_files/ (copy the whole folder, not report.html alone).';
      document.body.insertBefore(line, document.body.firstChild);
    }
    var points = 0;
    for (var j = 0; j < plots.length; j++) {
      var n = 0, p = plots[j];
      if (p.tagName.toLowerCase() === 'svg') n = p.querySelectorAll('.point').length;
      else (p._fullData || []).forEach(function (t) {
        if (t.meta && t.meta.role === 'series') n += t.x.length;
      });
      points += n;
      if (n === 0) problems.push('plot ' + p.id + ' has no points');
    }
    var outcome = problems.length ? 'error ' + problems.join('; ')
        : 'ok (' + imgs.length + ' images, ' + plots.length + ' plots, ' + points + ' points)';
    document.title = 'AO Lab report: ' + outcome;
    document.body.setAttribute('data-check', outcome);
  });
});
"""


def _meta_table(results: dict) -> str:
    meta = results["meta"]
    m = meta.get("machine", {})

    def load(v):
        return ", ".join(f"{x:.2f}" for x in v) if v else "—"

    items = [
        ("machine", f'{m.get("cpu")}, {m.get("logical_cores")} logical cores '
                    f'({m.get("usable_cores")} usable), {m.get("memory_gib")} GiB, '
                    f'{m.get("platform")}'),
        ("threads", f'{m.get("threads")} (requested {m.get("threads_requested")}; 0 = all cores)'),
        ("timing", f'{meta.get("warmup")} warm-up run(s), then the median of {meta.get("repeat")} '
                   "timed runs (min–max shown); the method and the shared blur timed apart; "
                   "wall-clock of the call, G-buffer already in memory"),
        ("load average", f'start {load(m.get("load_average_start"))}; end '
                         f'{load(meta.get("load_average_end"))} (1, 5, 15 min)'),
        ("sweep", f'{meta.get("sweep")}; methods {", ".join(meta.get("methods", []))}'),
        ("scenes", ", ".join(meta.get("scenes", []))
         + (f' (cropped to {meta["crop"]})' if meta.get("crop") else "")),
        ("time budget for the images", f'{meta.get("budget_ms"):g} ms'),
        ("run", f'started {meta.get("started")}, finished {meta.get("finished")}, '
                f'{meta.get("elapsed_s", 0):.0f} s; aolab commit {meta.get("aolab_commit")}'),
    ]
    rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{html.escape(str(v))}</td></tr>"
                   for k, v in items)
    return f"<table class='meta'>{rows}</table>"


def _how_to_read(results: dict) -> str:
    meta = results["meta"]
    regions = "".join(f"<li><b>{html.escape(k.replace('_', ' '))}</b>: {html.escape(v)}</li>"
                      for k, v in results["regions"].items())
    sources = "".join(f"<li><b>{html.escape(k)}</b>: {html.escape(v)}</li>"
                      for k, v in meta.get("presets_source", {}).items())
    return f"""
<details open><summary><b>How to read this report</b></summary>
<ul class="note">
<li>Every score is against the Cycles 1024-spp AO reference, on geometry pixels (background
excluded). Time is per frame: the method's median plus its blur's median, log axis; lower-left
is better for MAE, upper-left for SSIM. Black-ringed points joined by the black step line are
the <b>Pareto front</b>: no other method or Cycles setting is both faster and more accurate.</li>
<li>Most pixels of a frame are nearly white, so whole-frame scores flatter every method. The
red dashed line <b>AO ≡ 1</b> scores "no occlusion at all"; a configuration is flagged
<span class="weak">weak on occluded</span> when its MAE on the occluded region (reference &lt; 0.9)
exceeds {meta.get("weak_fraction", 0.75):g} × that of AO ≡ 1, i.e. it removes less than a quarter
of the error of drawing nothing there.</li>
<li>The green dotted <b>noise floor</b> is the reference's own noise: the MAE between it and an
independent 1024-spp render (or, marked "est.", the 256-spp render's MAE × √(2/5)). Differences
below it are not resolved by the reference.</li>
<li><b>bias</b> = mean(method − reference): positive = lighter than the reference
(under-occlusion), negative = darker (over-occlusion).</li>
<li><b>MAE calibrated</b>: the MAE after the best affine fit a·AO + b to the reference (least
absolute deviations, fitted on all scored pixels), shown beside (never instead of) the MAE:
it separates a different falloff (a bias the fit removes) from structural error (what it
cannot).</li>
<li><b>Cycles (fewer spp)</b>: Cycles AO at 1 … 256 samples scored against 1024; its time is
Blender's render time on this CPU. <b>EEVEE GTAO</b> renders on a software rasteriser (Mesa
llvmpipe) under xvfb: its time is <b>not comparable</b> with ours; read its accuracy only.</li>
<li>Images: each method at its best setting (lowest MAE) within the time budget, its signed
error (blue lighter / red darker than the reference).</li>
<li>Regions: <ul>{regions}</ul></li>
<li>Preset sources: <ul>{sources}</ul></li>
</ul></details>"""


class Page:
    """What rendering one report.html collects and shares between its sections: the files it
    names (``out``), whether the plots are interactive (plotly.js is in ``out``), the image
    files of each scene (image_files) and the methods' default settings."""

    def __init__(self, out: report_files.Files, interactive: bool):
        self.out = out
        self.interactive = interactive
        self.images: dict[str, dict] = {}
        self._defaults: dict[str, dict] = {}

    def add_images(self, scene: str, imgs: dict | None, sequence: bool = False) -> None:
        """Adds a scene's images (compare.scene_images); a sequence's are its first frame's,
        and its scenes are not among those of the means over the scenes (ALL)."""
        if imgs:
            self.images[scene] = {**image_files(scene, imgs, self.out),
                                  "note": "first frame" if sequence else "",
                                  "in_all": not sequence}

    def defaults(self, method: str) -> dict:
        if method not in self._defaults:
            try:
                info = aolab.method_info(method)["settings"]
            except ValueError:      # a peer, the baseline or rtao: no method settings
                info = []
            self._defaults[method] = {s["name"]: s["default"] for s in info}
        return self._defaults[method]

    def image_note(self, scene: str, row: dict) -> str:
        """What clicking a point of ``row`` in ``scene``'s plots opens, for its hover."""
        config = f'{row["method"]}/{row["label"]}'
        names = ([n for n, i in self.images.items() if i["in_all"]] if scene == AGGREGATE
                 else [scene])
        have = [n for n in names if config in (self.images.get(n) or {}).get("configs", {})]
        if not have:
            return "no image"
        if scene == AGGREGATE:
            return f"click: its image and error map on each of {len(have)} scene(s)"
        return "click: image and error map" + (f' ({self.images[scene]["note"]})'
                                               if self.images[scene]["note"] else "")

    def index(self) -> str:
        """Every scene's image files, for report.js."""
        return _json_script({"order": list(self.images), "scenes": self.images}, "images")


def plots_html(page: Page, name: str, rows: list[dict], floor: dict | None,
               plot_prefix: str) -> str:
    """The three plots of a section (PLOTS): plotly.js figures, or static SVG when plotly.js
    is not installed."""
    plots = []
    hovers = ({r["key"]: hover_text(r, page.defaults(r["method"]), page.image_note(name, r))
               for r in rows} if page.interactive else {})
    for column, label, lower in PLOTS:
        plot_id = f"{plot_prefix}-{column}"
        lines = hlines_for(rows, column, floor)
        if not page.interactive:
            plots.append(svg_plot(plot_id, rows, column, label, lower, lines))
            continue
        fig = plotly_figure(rows, column, label, lower, lines, hovers)
        if fig is None:
            plots.append(f'<p class="missing">No timed point has a value of '
                         f'{html.escape(label)}.</p>')
            continue
        plots.append(f'<div class="plot" id="{html.escape(plot_id)}" data-metric="{column}" '
                     f'data-section="{html.escape(name)}"></div>'
                     + _json_script(fig, "figure", data_plot=plot_id))
    return f'<div class="plots">{"".join(plots)}</div>'


def scene_section(page: Page, name: str, rows: list[dict], info: dict | None,
                  imgs: dict | None, budget_ms: float, plot_prefix: str) -> str:
    parts = []
    floor = info.get("noise_floor") if info else None
    parts.append(plots_html(page, name, rows, floor, plot_prefix))
    if info is not None:
        peers = info.get("peers") or []
        if not peers:
            parts.append("<p class='missing'>This scene has no peers (no "
                         "reference_scenes/&lt;scene&gt;/peers/peers.json): the Cycles spp ladder, "
                         "the EEVEE row and the measured noise floor are missing here.</p>")
        elif not any(r["kind"] == "eevee" for r in rows):
            parts.append("<p class='missing'>No EEVEE render among this scene's peers.</p>")
        if floor is None:
            parts.append("<p class='missing'>Reference noise floor unknown (no independent "
                         "1024-spp or 256-spp render).</p>")
        parts.append(image_grid(name, imgs, page.images.get(name), budget_ms))
    parts.append(f'<div class="scroll">{table(rows, floor)}</div>')
    return "\n".join(parts)


def sequence_section(page, name: str, rows: list[dict], info: dict, budget_ms: float) -> str:
    """A sequence's temporal stability: the MAE against the frame (frame_lines: with
    accumulation, each method at FRAMES_PRESET in one frame and accumulated; else each
    method's best configuration within the budget), the flicker of every configuration,
    least first, and the accumulation tables (accumulation_html)."""
    means = [r for r in rows if r["scene"] == name]
    floor = info.get("flicker_floor")
    lines = frame_lines(name, rows, budget_ms)
    plot_id = f"plot-{name}-frames"
    fig = frames_figure(lines) if page.interactive else None
    if fig is not None:
        plot = (f'<div class="plot frames" id="{html.escape(plot_id)}" data-metric="all_mae" '
                f'data-section="{html.escape(name)}"></div>'
                + _json_script(fig, "figure", data_plot=plot_id))
    else:
        plot = frames_plot(plot_id, lines)
    accumulated = any(is_accumulated(r) for r in means)
    what = (f'each method at {FRAMES_PRESET} (its defaults where it has no {FRAMES_PRESET}) in '
            'one frame, dashed, and accumulated, solid' if accumulated else
            "each method's best configuration within the time budget")
    return "\n".join([
        f'<h3 id="temporal-{html.escape(name)}">Temporal stability</h3>',
        f'<p class="note">Frames {", ".join(str(f) for f in info.get("frames", []))}, each '
        'scored as a scene of its own (rows ' + html.escape(name) + '@NNNN in results.csv; the '
        'plots and table above are their means). The plot: the MAE of every frame, '
        + html.escape(what) + '. <b>Flicker</b>: the mean over pixels scored '
        'in both frames of |(AO<sub>t</sub> − AO<sub>t−1</sub>) − (Ref<sub>t</sub> − '
        'Ref<sub>t−1</sub>)|, averaged over consecutive frames: how much a configuration’s '
        'image changes where the reference’s does not. The reference’s own flicker floor '
        '(its noise alone) is ' + (f'{floor["value"]:.4f}, {html.escape(floor["source"])}'
                                   if floor else 'unknown') + '. The last column names the '
        'per-pixel random patterns a configuration has on (random rotation, jitter ...): '
        + ('redrawn every frame here (a per-frame seed), they boil in one frame and average '
           'out accumulated.' if accumulated else 'fixed to the screen, they stay while the '
           'geometry moves, so per-pixel random rotation and jitter show what they cost in '
           'motion.') + '</p>',
        plot,
        f'<div class="scroll">{flicker_table(flicker_entries(means), floor)}</div>',
        accumulation_html(name, rows, info)])


def study_sections(f: StudyFindings) -> str:
    """The findings over all scenes (findings.study_findings): the error split, the paired
    comparisons, the defaults worse than AO = 1, the tuned presets, the check against EEVEE and
    rtao's ladder."""
    parts = ['<h2 id="split">Where the error comes from</h2><p class="note">Per method, at '
             'its paper defaults and its tuned presets within '
             f'{EEVEE_CHECK_BUDGET_MS} and {LARGEST_TUNED_BUDGET_MS} ms, and EEVEE: the MAE on '
             'the occluded region and three '
             'parts of it, as means over the scenes. <b>Screen-space loss</b>: what the best '
             'any screen-space method could do costs (the screen-space limit, each scene at its '
             'best thickness, against the reference). <b>Definition</b>: what the best affine '
             'map a·AO + b removes (the method computes another quantity than the '
             'reference). <b>Approximation</b>: the method against the limit (its sampling '
             'and its assumptions). The parts overlap and need not add up.</p>']
    if f.has_limits:
        parts.append(split_chart("split-ALL", f.split))
    else:
        parts.append("<p class='missing'>No committed screen-space limits (reference_scenes/"
                     "&lt;scene&gt;/limits/: aolab limits): no split.</p>")
    budget = f.budget_ms
    parts.append(f'<h2 id="paired">Which differences are real</h2><p class="note">Each '
                 f'method\'s most accurate configuration within {budget:g} ms per 1280×720 '
                 'frame that is no worse than AO ≡ 1 on the whole frame of any scene, ranked '
                 'by mean occluded MAE with its 95 % bootstrap interval over the '
                 'scenes, and compared scene by scene with the one ranked above it and with the '
                 'first: on how many scenes the better one wins, and the two-sided Wilcoxon '
                 f'signed-rank test; a difference with p ≥ {stats.ALPHA:g} is not told apart '
                 'from the scatter between scenes (docs/comparison.md).</p>')
    parts.append(paired_table(f.paired, budget))
    parts.append('<h2 id="worse-than-nothing">Defaults worse than no occlusion</h2><p class='
                 '"note">Where a method at its paper\'s defaults has a higher whole-frame MAE '
                 'than AO ≡ 1 — drawing no occlusion at all would be closer to the reference '
                 '(whole-frame MAE, the method\'s against AO ≡ 1\'s). No tuned preset ships '
                 'worse than AO ≡ 1 on any scene (docs/tuning.md).</p>')
    parts.append(worse_than_nothing_html(f.worse, f.n_stills))
    tuned = f.tuned
    parts.append('<h2 id="tuned">Tuned presets</h2>')
    if tuned:
        parts.append('<p class="note">From the committed tuned presets (' +
                     html.escape(tuned.get("source", "")) + '): the rows "tuned-…" above are '
                     'these configurations run by this study, on the scenes they were chosen '
                     'on; the held-out column is the honest score, each family of scenes scored '
                     'with the configuration chosen on the other families, and the gap is how '
                     'much worse that is than on the families it was chosen on. Where the '
                     'tuned choice lost to the method\'s default on held-out families, the '
                     'default ships under the tuned name (docs/tuning.md).</p>')
    parts.append(tuned_table(f.tuned_rows))
    parts.append(f'<h2 id="eevee">Against EEVEE</h2><p class="note">Per scene: where the '
                 'screen-space limit is below EEVEE\'s occluded MAE, does the best tuned '
                 f'configuration within {EEVEE_CHECK_BUDGET_MS} ms, chosen on the other scenes '
                 'among every method\'s trials, beat EEVEE too?</p>')
    parts.append(eevee_table(f.eevee))
    cross = f.rtao_crossover
    parts.append('<h2 id="rtao">Against a CPU ray tracer</h2><p class="note">rtao (Embree on '
                 'the same cores, the BVH build apart) at each rung of rays per pixel, against '
                 'the most accurate screen-space configuration as fast as it, means over the '
                 'scenes: ' + (f'from {cross:.0f} ms on, the ray tracer is more accurate.'
                               if cross is not None else
                               'screen space is more accurate at every rung.') + '</p>')
    parts.append(rtao_table(f.rtao_ladder, f.rtao_not_run))
    return "\n".join(parts)


VIEWER = ('<div id="viewer" hidden><div class="viewer-box" role="dialog" aria-label="images">'
          '<button type="button" aria-label="close">×</button><div class="viewer-body"></div>'
          '</div></div>')


def render_html(results: dict, images: dict, out: report_files.Files | None = None,
                plotly: str | None = None, script: str | None = None) -> str:
    """The page. ``images``: compare.scene_images per scene, whose files are added to
    ``out``; ``plotly`` and ``script``: the names in ``out`` of plotly.js and report.js,
    loaded at the page's end. Without plotly.js the plots are static SVG and the page says so
    in one line."""
    meta = results["meta"]
    rows = results["rows"]
    scenes = meta.get("scenes", [])
    interactive = plotly is not None
    page = Page(out if out is not None else report_files.Files(), interactive)
    for name in scenes:
        info = results["scenes"].get(name) or {}
        page.add_images(name, images.get(name), bool(info.get("sequence")))
    body = ["<h1>AO Lab: what accuracy costs in time</h1>"]
    if not interactive:
        body.append("<p class='missing'>Static plots: plotly.js is not installed "
                    "(scripts/install-deps.sh installs it), so the plots cannot show a point's "
                    "configuration on hover.</p>")
    else:
        body.append("<noscript><p class='missing'>The plots need JavaScript; the tables "
                    "below hold every number.</p></noscript>")
    if meta.get("partial"):
        complete = ", ".join(meta.get("complete_scenes", [])) or "none"
        body.append('<div class="banner">PARTIAL results: the study was interrupted or is still '
                    f'running. Complete scenes: {html.escape(complete)}.</div>')
    body.append(_meta_table(results))
    body.append(_how_to_read(results))
    agg = [r for r in rows if r["scene"] == AGGREGATE]
    if agg:
        body.append('<h2 id="all">All scenes</h2><p class="note">Each point is the mean over the '
                    'complete scenes where the configuration ran (times and scores averaged; '
                    'peers only over the scenes that have them: see each row\'s note). The '
                    'noise floor is per scene: see the scenes below.</p>')
        body.append(scene_section(page, AGGREGATE, agg, None, None, meta.get("budget_ms", 0),
                                  "plot-ALL"))
        body.append(study_sections(study_findings(results, agg)))
    for name in scenes:
        mine = [r for r in rows if r["scene"] == name]
        info = results["scenes"].get(name)
        body.append(f'<h2 id="scene-{html.escape(name)}">{html.escape(name)}</h2>')
        if not mine:
            body.append("<p class='missing'>Not run (interrupted before this scene).</p>")
            continue
        if info:
            body.append(f'<p class="note">{html.escape(info.get("title", ""))}: '
                        f'{info["width"]}×{info["height"]}, R = {info["radius"]:g}; '
                        'region pixels: ' + ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in
                                                      info.get("region_pixels", {}).items())
                        + "</p>")
        body.append(scene_section(page, name, mine, info, images.get(name),
                                  meta.get("budget_ms", 0), f"plot-{name}"))
        if info and info.get("sequence"):
            body.append(sequence_section(page, name, rows, info, meta.get("budget_ms", 0)))
    if results.get("notes"):
        notes = "".join(f"<li>{html.escape(n)}</li>" for n in results["notes"])
        body.append(f"<h2>Notes</h2><ul>{notes}</ul>")
    body += [VIEWER, page.index()]
    body += [f'<script src="{html.escape(s)}"></script>' for s in (plotly, script) if s]
    return ("<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            "<title>AO Lab report</title>"
            f"<style>{CSS}</style><script>{CHECK_SCRIPT}</script></head><body>"
            + "\n".join(body) + "</body></html>\n")


def write_report(path: Path, results: dict, images: dict) -> None:
    """Writes report.html and the files it names into report_files/ beside it (plotly.js
    when installed, report.js, the images: report_files.Files), each atomically, the files
    before the page; then removes the files of report_files/ that the page no longer names."""
    path = Path(path)
    out = report_files.Files()
    found = report_files.plotly_js()
    plotly = out.add("plotly-basic", ".min.js", found.read_bytes()) if found else None
    script = out.add("report", ".js", report_files.SCRIPT.read_bytes())
    page = render_html(results, images, out, plotly, script)
    out.write(path.parent)
    files.write_text(path, page)
    report_files.prune(path)
