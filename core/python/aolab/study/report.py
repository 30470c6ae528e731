"""report.html of ``aolab compare``, with its files in report_files/ beside it
(report_files.py: images as WebP, plotly.js, report.js; nothing from the network, so the folder
works copied anywhere and from a file:// URL).

The accuracy-against-time plots are plotly.js figures, each held as JSON in the page (a
<script type="application/json" class="figure" data-plot="ID"> beside its <div class="plot"
id="ID">) and drawn by report.js: one trace per method and per peer series, hover naming the
configuration, a legend that hides and shows methods, a click that opens the point's AO image
and error map. Every plotted point's customdata is the key of its row in results.csv, its x
total_ms and its y the value of the column in layout.meta.column, so a test can match every
point to its row. Without plotly.js (not installed) the same plots are static SVG (svg_plot,
also docs/results.md's), whose points are elements of class ``point`` with ``data-key``,
``data-metric``, ``data-x`` and ``data-y``.

On load, the page checks that every image decoded and every plot has points and writes the
outcome into document.title: "AO Lab report: ok ..." or "AO Lab report: error ...".
"""

from __future__ import annotations

import html
import json
import math
from pathlib import Path

import numpy as np

import aolab

from .. import catalog
from ..regions import REGIONS
from ..scoring import DARKER_RGB, ERROR_SCALE, LIGHTER_RGB
from ..util import files
from . import budget, report_files, stats
from .runner import still_scenes, whole_frame_ok

#: A configuration is flagged "weak" when its MAE on the occluded region exceeds this fraction
#: of the "AO = 1" baseline's there (it removes less than a quarter of the baseline's error).
WEAK_FRACTION = 0.75

# The signed error maps' colours and scale are aolab.scoring's (the add-on's too).

#: (results.csv column, axis label, lower is better)
PLOTS = (
    ("all_mae", "MAE, all scored pixels", True),
    ("occluded_mae", "MAE, occluded region (reference < 0.9)", True),
    ("all_ssim", "SSIM, all scored pixels", False),
)
#: Kinds whose time is comparable with the methods' and that may lie on the Pareto front.
FRONT_KINDS = ("method", "cycles", "rtao")
#: One colour per method (eleven methods, the screen-space limit drawn apart), distinct on
#: white and from the peers' colours below.
PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf",
           "#bcbd22", "#d62728", "#7f7f7f", "#000080", "#00a087", "#800000", "#ff1493")
CYCLES_COLOUR = "#444444"
EEVEE_COLOUR = "#b8860b"
RTAO_COLOUR = "#7b1fa2"
LIMIT_COLOUR = "#2e7d32"
#: The configurations of each method in the error-split chart: the paper's defaults, the tuned
#: preset of the budget the study checks against EEVEE, and the largest budget's.
SPLIT_LABELS = ("default", "tuned-100ms", "tuned-500ms")
#: The budget of the check against EEVEE (docs/results.md): the best tuned configuration within
#: 100 ms a frame, scored on a scene it was not chosen on; and the largest tuned budget, shown
#: beside it to tell what time alone would buy.
EEVEE_CHECK_BUDGET_MS = 100
LARGEST_TUNED_BUDGET_MS = 500


# ----------------------------------------------------------------------------------------
# SVG plots


def _fmt(v) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return ""
    return repr(float(v))


def number(v):
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def metric(row: dict, column: str):
    """A row's value of a results.csv metric column such as ``occluded_mae``."""
    for region in REGIONS:
        if column.startswith(region + "_"):
            return number(row.get("metrics", {}).get(region, {}).get(column[len(region) + 1:]))
    return number(row.get(column))


def pareto_front(points: list[tuple[float, float, str]], lower_is_better: bool) -> list[str]:
    """Keys of the points no other point beats in both time and value (ties kept), fastest
    first."""
    sign = 1 if lower_is_better else -1
    best = math.inf
    front = []
    for x, y, key in sorted(points, key=lambda p: (p[0], sign * p[1])):
        if sign * y < best:
            best = sign * y
            front.append(key)
    return front


def _nice_ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    span = hi - lo
    if span <= 0:
        return [lo]
    raw = span / n
    mag = 10 ** math.floor(math.log10(raw))
    step = min((m * mag for m in (1, 2, 2.5, 5, 10)), key=lambda s: abs(s - raw))
    first = math.ceil(lo / step - 1e-9) * step
    ticks, t = [], first
    while t <= hi + 1e-9 * step:
        ticks.append(round(t, 10))
        t += step
    return ticks


def _tick_label(v: float) -> str:
    return f"{v:g}"


def series_for(rows: list[dict]) -> list[dict]:
    """Plot series from rows of one scene: one per method, the Cycles ladder, EEVEE."""
    methods = sorted({r["method"] for r in rows if r["kind"] == "method"})
    out = []
    for i, m in enumerate(methods):
        mine = [r for r in rows if r["kind"] == "method" and r["method"] == m]
        out.append({"name": m, "colour": PALETTE[i % len(PALETTE)], "marker": "circle",
                    "line": False, "rows": mine})
    cycles = sorted((r for r in rows if r["kind"] == "cycles"),
                    key=lambda r: (r.get("settings", {}).get("samples") or 0, r["method"]))
    if cycles:
        out.append({"name": "Cycles (fewer spp)", "colour": CYCLES_COLOUR, "marker": "square",
                    "line": True, "rows": cycles})
    rtao = sorted((r for r in rows if r["kind"] == "rtao"),
                  key=lambda r: (r.get("settings", {}).get("rays") or 0))
    if rtao:
        out.append({"name": "rtao (Embree, CPU)", "colour": RTAO_COLOUR, "marker": "triangle",
                    "line": True, "rows": rtao})
    eevee = [r for r in rows if r["kind"] == "eevee"]
    if eevee:
        out.append({"name": "EEVEE GTAO (time not comparable)", "colour": EEVEE_COLOUR,
                    "marker": "diamond", "line": False, "rows": eevee})
    return out


def _marker(shape: str, x: float, y: float, r: float, attrs: str) -> str:
    if shape == "square":
        return (f'<rect x="{x - r:.2f}" y="{y - r:.2f}" width="{2 * r:.2f}" '
                f'height="{2 * r:.2f}" {attrs}/>')
    if shape == "triangle":
        d = r * 1.3
        pts = f"{x:.2f},{y - d:.2f} {x + d:.2f},{y + d * 0.8:.2f} {x - d:.2f},{y + d * 0.8:.2f}"
        return f'<polygon points="{pts}" {attrs}/>'
    if shape == "diamond":
        d = r * 1.4
        pts = f"{x:.2f},{y - d:.2f} {x + d:.2f},{y:.2f} {x:.2f},{y + d:.2f} {x - d:.2f},{y:.2f}"
        return f'<polygon points="{pts}" {attrs}/>'
    return f'<circle cx="{x:.2f}" cy="{y:.2f}" r="{r:.2f}" {attrs}/>'


def _axes(out: list[str], ticks: list[float], py, box: tuple, x_label: str,
          y_label: str) -> None:
    """A plot's horizontal grid lines at ``ticks`` (``py`` maps a value to its y) with their
    labels, and the two axis titles; ``box`` = (left, top, width, height of the plot area,
    height of the image)."""
    ml, mt, pw, ph, height = box
    for v in ticks:
        Y = py(v)
        out.append(f'<line x1="{ml}" y1="{Y:.2f}" x2="{ml + pw}" y2="{Y:.2f}" class="grid"/>')
        out.append(f'<text x="{ml - 6}" y="{Y + 4:.2f}" class="tick" text-anchor="end">'
                   f'{_tick_label(v)}</text>')
    out.append(f'<text x="{ml + pw / 2:.1f}" y="{height - 8}" class="axis" text-anchor="middle">'
               f'{html.escape(x_label)}</text>')
    out.append(f'<text transform="translate(14,{mt + ph / 2:.1f}) rotate(-90)" class="axis" '
               f'text-anchor="middle">{html.escape(y_label)}</text>')


def plot_points(rows: list[dict], column: str) -> tuple[list[dict], list[tuple]]:
    """The series of ``rows`` (series_for) and their timed points with a value of
    ``column``: (series, row, time, value)."""
    series = series_for(rows)
    pts = []
    for s in series:
        for r in s["rows"]:
            x, y = number(r.get("total_ms")), metric(r, column)
            if x is not None and x > 0 and y is not None:
                pts.append((s, r, x, y))
    return series, pts


def plot_ranges(pts: list[tuple], lines: list[dict], lower_is_better: bool) -> tuple:
    """(x0, x1, y0, y1): the log10 decades of the time axis and the value axis's range, for
    the points of plot_points and the horizontal lines."""
    xs = [p[2] for p in pts]
    ys = [p[3] for p in pts] + [h["value"] for h in lines]
    x0, x1 = math.floor(math.log10(min(xs))), math.ceil(math.log10(max(xs)))
    if x1 == x0:
        x1 += 1
    if lower_is_better:
        y0, y1 = 0.0, max(ys) * 1.08 or 1.0
    else:
        lo = min(ys)
        y0, y1 = max(0.0, lo - 0.05 * (1 - lo) - 0.01), 1.0
    if y1 <= y0:
        y1 = y0 + 1
    return x0, x1, y0, y1


def plot_front(pts: list[tuple], lower_is_better: bool) -> list[str]:
    """The keys of the Pareto front among plot_points' points of the comparable kinds
    (FRONT_KINDS), fastest first."""
    return pareto_front([(x, y, r["key"]) for s, r, x, y in pts if r["kind"] in FRONT_KINDS],
                        lower_is_better)


def svg_plot(plot_id: str, rows: list[dict], column: str, label: str, lower_is_better: bool,
             hlines: list[dict], standalone: bool = False) -> str:
    """An accuracy-against-time scatter plot (log time axis) with the Pareto front of the
    comparable kinds highlighted and horizontal reference lines (baseline, noise floor): the
    static plots of docs/results.md, and the report's when plotly.js is missing.
    ``standalone`` embeds the style, for an .svg file of its own."""
    width, height = 672, 360
    ml, mr, mt, mb = 62, 232, 16, 44
    pw, ph = width - ml - mr, height - mt - mb
    series, pts = plot_points(rows, column)
    lines = [h for h in hlines if number(h.get("value")) is not None]
    if not pts:
        return f'<p class="missing">No timed point has a value of {html.escape(label)}.</p>'
    x0, x1, y0, y1 = plot_ranges(pts, lines, lower_is_better)

    def px(x):
        return ml + (math.log10(x) - x0) / (x1 - x0) * pw

    def py(y):
        return mt + (1 - (y - y0) / (y1 - y0)) * ph

    out = [f'<svg class="plot" id="{html.escape(plot_id)}" xmlns="http://www.w3.org/2000/svg" '
           f'width="{width}" height="{height}" viewBox="0 0 {width} {height}" '
           f'data-metric="{column}" role="img" aria-label="{html.escape(label)} against time">',
           f'<rect x="{ml}" y="{mt}" width="{pw}" height="{ph}" class="frame"/>']
    if standalone:
        out.insert(1, f"<style>{SVG_CSS}</style>")
    for e in range(x0, x1 + 1):
        for m in (1, 2, 5):
            v = m * 10 ** e
            if v > 10 ** x1:
                break
            X = px(v)
            cls = "grid" if m == 1 else "grid minor"
            out.append(f'<line x1="{X:.2f}" y1="{mt}" x2="{X:.2f}" y2="{mt + ph}" class="{cls}"/>')
            if m == 1 or (x1 - x0) <= 2:
                out.append(f'<text x="{X:.2f}" y="{mt + ph + 16}" class="tick" '
                           f'text-anchor="middle">{_tick_label(v)}</text>')
    _axes(out, _nice_ticks(y0, y1), py, (ml, mt, pw, ph, height),
          "time per frame, ms (log scale; method + blur)", label)
    # Horizontal lines: AO = 1 baseline, noise floor.
    for h in lines:
        Y = py(h["value"])
        out.append(f'<line x1="{ml}" y1="{Y:.2f}" x2="{ml + pw}" y2="{Y:.2f}" '
                   f'class="hline {h["cls"]}" data-key="{html.escape(h["key"])}" '
                   f'data-metric="{column}" data-y="{_fmt(h["value"])}">'
                   f'<title>{html.escape(h["title"])}: {h["value"]:.4g}</title></line>')
        if h.get("inline", True):
            out.append(f'<text x="{ml + pw - 4}" y="{Y - 4:.2f}" class="hlabel {h["cls"]}" '
                       f'text-anchor="end">{html.escape(h["label"])}</text>')
    # Pareto front of the comparable kinds.
    front = plot_front(pts, lower_is_better)
    front_set = set(front)
    if len(front) > 1:
        where = {r["key"]: (x, y) for s, r, x, y in pts}
        path = []
        for i, k in enumerate(front):
            x, y = where[k]
            if i:
                path.append(f"{px(x):.2f},{py(where[front[i - 1]][1]):.2f}")
            path.append(f"{px(x):.2f},{py(y):.2f}")
        out.append(f'<polyline points="{" ".join(path)}" class="front-line"/>')
    # Series.
    for s in series:
        mine = [(r, x, y) for t, r, x, y in pts if t is s]
        if s["line"] and len(mine) > 1:
            poly = " ".join(f"{px(x):.2f},{py(y):.2f}" for r, x, y in mine)
            out.append(f'<polyline points="{poly}" fill="none" stroke="{s["colour"]}" '
                       'stroke-width="1.2" stroke-dasharray="4 3"/>')
        for r, x, y in mine:
            out += error_bars(r, column, px, py)
        for r, x, y in mine:
            on = r["key"] in front_set
            cls = "point front" if on else "point"
            attrs = (f'class="{cls}" fill="{s["colour"]}" data-key="{html.escape(r["key"])}" '
                     f'data-metric="{column}" data-x="{_fmt(x)}" data-y="{_fmt(y)}"')
            tip = (f'{r["method"]} {r["label"]}: {x:.4g} ms, {label} {y:.4g}'
                   + (" (Pareto front)" if on else ""))
            el = _marker(s["marker"], px(x), py(y), 5.5 if on else 4.0, attrs)
            out.append(el[:-2] + f"><title>{html.escape(tip)}</title></{el.split()[0][1:]}>")
    # Legend.
    lx, ly = ml + pw + 14, mt + 8
    entries = [(s["name"], s["colour"], s["marker"]) for s in series]
    for i, (name, colour, shape) in enumerate(entries):
        Y = ly + i * 18
        out.append(_marker(shape, lx + 5, Y, 4.5, f'fill="{colour}" class="legend-marker"'))
        out.append(f'<text x="{lx + 16}" y="{Y + 4}" class="legend">{html.escape(name)}</text>')
    Y = ly + len(entries) * 18
    out.append(f'<line x1="{lx}" y1="{Y}" x2="{lx + 10}" y2="{Y}" class="front-line"/>'
               f'<text x="{lx + 16}" y="{Y + 4}" class="legend">Pareto front</text>')
    for j, h in enumerate(lines):
        Y = ly + (len(entries) + 1 + j) * 18
        out.append(f'<line x1="{lx}" y1="{Y}" x2="{lx + 10}" y2="{Y}" class="hline {h["cls"]}"/>'
                   f'<text x="{lx + 16}" y="{Y + 4}" class="legend">'
                   f'{html.escape(h["label"])}</text>')
    out.append("</svg>")
    return "\n".join(out)


def error_bars(row: dict, column: str, px, py) -> list[str]:
    """A mean over scenes' 95 % intervals (stats.bootstrap_interval) as thin bars through its
    point: vertical for the plotted metric, horizontal for the time."""
    iv = row.get("intervals") or {}
    x, y = number(row.get("total_ms")), metric(row, column)
    out = []
    if iv.get(column) and x:
        lo, hi = iv[column]
        out.append(f'<line x1="{px(x):.2f}" y1="{py(lo):.2f}" x2="{px(x):.2f}" '
                   f'y2="{py(hi):.2f}" class="ci" data-key="{html.escape(row["key"])}" '
                   f'data-lo="{_fmt(lo)}" data-hi="{_fmt(hi)}"/>')
    if iv.get("total_ms") and y is not None and iv["total_ms"][0] > 0:
        lo, hi = iv["total_ms"]
        out.append(f'<line x1="{px(lo):.2f}" y1="{py(y):.2f}" x2="{px(hi):.2f}" '
                   f'y2="{py(y):.2f}" class="ci"/>')
    return out


def _ci(value, interval, fmt: str = ".4f") -> str:
    """A mean and, when it has one, its 95 % interval over the scenes."""
    if not interval:
        return _cell(value, fmt)
    lo, hi = interval
    return f'{_cell(value, fmt)} <small class="ci">[{lo:{fmt}}, {hi:{fmt}}]</small>'


def best_limit(rows: list[dict]) -> dict | None:
    """The screen-space limit row (kind "limit") with the lowest occluded MAE, or None."""
    limits = [r for r in rows if r["kind"] == "limit" and metric(r, "occluded_mae") is not None]
    return min(limits, key=lambda r: metric(r, "occluded_mae")) if limits else None


def hlines_for(rows: list[dict], column: str, floor: dict | None) -> list[dict]:
    out = []
    limit = best_limit(rows)
    if limit is not None and metric(limit, column) is not None:
        out.append({"key": limit["key"], "value": metric(limit, column), "cls": "limit",
                    "label": f"screen-space limit ({limit['label']})",
                    "title": "the screen-space limit at its best thickness (an oracle)"})
    for r in rows:
        if r["kind"] == "baseline":
            out.append({"key": r["key"], "value": metric(r, column), "cls": "baseline",
                        "label": "AO ≡ 1 (no occlusion)", "title": "baseline AO ≡ 1"})
            base = metric(r, column)
            if column == "occluded_mae" and base is not None:
                out.append({"key": r["key"], "value": WEAK_FRACTION * base, "cls": "weak",
                            "label": f"weak above ({WEAK_FRACTION:g} × AO ≡ 1)",
                            "title": "flag threshold", "inline": False})
    if floor:
        value = floor.get(column)
        if value is not None:
            out.append({"key": floor["key"], "value": value, "cls": "floor",
                        "label": "noise floor" + (" (est.)" if floor.get("estimated") else ""),
                        "title": floor["source"]})
    return out


# ----------------------------------------------------------------------------------------
# Interactive plots (plotly.js)

#: plotly.js marker symbols of series_for's markers.
SYMBOLS = {"circle": "circle", "square": "square", "triangle": "triangle-up",
           "diamond": "diamond"}
#: Horizontal lines (hlines_for's cls): colour and dash, as the static plots' CSS draws them.
HLINE_STYLES = {"baseline": ("#c0392b", "7px,4px"), "floor": ("#27ae60", "2px,3px"),
                "weak": ("#e67e22", "3px,5px"), "limit": ("#2e7d32", "10px,3px,2px,3px")}


def _value(v) -> str:
    if isinstance(v, bool):
        return "on" if v else "off"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def changed_settings(row: dict, defaults: dict) -> list[str]:
    """"name value" for each of a method row's settings that differs from the method's
    default (``defaults``: aolab.method_info's, by name), and "+ blur" when the shared blur is
    on (the builtin blur switch it turns off is not named); empty for the defaults, and for
    peers (their label says what they are)."""
    if row["kind"] != "method":
        return []
    settings = dict(row.get("settings") or {})
    blur = settings.pop("blur", False)
    entry = catalog.entry(row["method"])
    builtin = entry.builtin_blur if entry is not None else None
    out = []
    for name, v in settings.items():
        if name not in defaults or (blur and name == builtin):
            continue
        d = defaults[name]
        same = (math.isclose(v, d, rel_tol=1e-9, abs_tol=1e-12)
                if isinstance(v, float) and isinstance(d, (int, float)) else v == d)
        if not same:
            out.append(f"{name} {_value(v)}")
    if blur:
        out.append("+ blur")
    return out


def interval(row: dict, column: str) -> tuple[float, float] | None:
    """A row's 95 % interval over the scenes of ``column`` (results.json's "intervals": the
    ALL rows have them for the whole-frame and occluded MAE and the time), when finite."""
    iv = (row.get("intervals") or {}).get(column)
    if not iv or number(iv[0]) is None or number(iv[1]) is None:
        return None
    return float(iv[0]), float(iv[1])


def _with_interval(value: float, iv: tuple | None, fmt: str) -> str:
    return format(value, fmt) + (f" [{iv[0]:{fmt}}, {iv[1]:{fmt}}]" if iv else "")


def hover_text(row: dict, defaults: dict, image: str) -> str:
    """What hovering a point shows (plotly.js's subset of HTML): the method, the preset, the
    settings that differ from the method's defaults, the time, the MAE on all scored pixels
    and on the occluded region (with their 95 % intervals over the scenes where the row has
    them), SSIM, and ``image``: what clicking it opens."""
    def esc(text: str) -> str:    # plotly.js's text: <, > and & escaped, quotes as they are
        return html.escape(text, quote=False)

    lines = [f'<b>{esc(row["method"])}</b> {esc(row["label"])}'
             + (f' (preset {esc(row["preset"])})' if row.get("preset")
                and row["preset"] != row["label"] else "")]
    changed = changed_settings(row, defaults)
    if row["kind"] == "method":
        changed = changed or ["the method's defaults"]
    for i in range(0, len(changed), 3):
        lines.append(esc(", ".join(changed[i:i + 3])))
    t = number(row.get("total_ms"))
    if t is not None:
        lines.append(_with_interval(t, interval(row, "total_ms"), ".1f") + " ms")
    for column, name in (("all_mae", "MAE"), ("occluded_mae", "MAE occluded")):
        v = metric(row, column)
        if v is not None:
            lines.append(f"{name} {_with_interval(v, interval(row, column), '.4f')}")
    ssim = metric(row, "all_ssim")
    if ssim is not None:
        lines.append(f"SSIM {ssim:.4f}")
    if row.get("n_scenes"):
        lines.append(f'mean over {row["n_scenes"]} scene(s)')
    lines.append(f"<i>{esc(image)}</i>")
    return "<br>".join(lines)


def _error_bar(values: list, intervals: list) -> dict | None:
    """plotly.js error bars from 95 % intervals ((lo, hi) or None per point)."""
    if not any(intervals):
        return None
    plus, minus = [], []
    for v, iv in zip(values, intervals):
        lo, hi = iv or (v, v)
        plus.append(hi - v)
        minus.append(v - lo)
    return {"type": "data", "symmetric": False, "array": plus, "arrayminus": minus,
            "thickness": 1, "width": 0, "color": "rgba(0,0,0,0.22)"}


def plotly_figure(rows: list[dict], column: str, label: str, lower_is_better: bool,
                  hlines: list[dict], hovers: dict) -> dict | None:
    """The plotly.js figure ({"data", "layout"}) of svg_plot's plot: one trace per series
    (one per method, the Cycles ladder, rtao, EEVEE), one for the Pareto front (its step line
    and a ring around each of its points), and one per horizontal line. ``hovers``: row key
    -> hover_text. A point's customdata is its row's key (a limit line's ends: the limit's);
    a trace's meta says what it is ({"role": "series", "kind"}, {"role": "hline", "key",
    "cls"} or {"role": "front"}), layout.meta the plotted column. None when no point has a
    value."""
    series, pts = plot_points(rows, column)
    lines = [h for h in hlines if number(h.get("value")) is not None]
    if not pts:
        return None
    x0, x1, y0, y1 = plot_ranges(pts, lines, lower_is_better)
    front = plot_front(pts, lower_is_better)
    on_front = set(front)
    data = []
    for h in lines:
        colour, dash = HLINE_STYLES[h["cls"]]
        line = {"type": "scatter", "mode": "lines", "name": h["label"],
                "x": [10.0 ** x0, 10.0 ** x1], "y": [h["value"], h["value"]],
                "line": {"color": colour, "dash": dash, "width": 1.3},
                "hovertemplate": f'{html.escape(h["title"])}: %{{y:.4g}}<extra></extra>',
                "meta": {"role": "hline", "key": h["key"], "cls": h["cls"]}}
        if h["cls"] == "limit":    # a click on its ends opens the limit's images
            line["customdata"] = [h["key"], h["key"]]
        data.append(line)
    where = {r["key"]: (x, y) for s, r, x, y in pts}
    if front:   # its step line and a ring around each of its points
        data.append({"type": "scatter", "mode": "lines+markers", "name": "Pareto front",
                     "x": [where[k][0] for k in front], "y": [where[k][1] for k in front],
                     "line": {"color": "rgba(0,0,0,0.55)", "width": 1.4, "shape": "hv"},
                     "marker": {"symbol": "circle-open", "size": 14, "color": "#000",
                                "line": {"width": 1.6}},
                     "hoverinfo": "skip", "meta": {"role": "front"}})
    for s in series:
        mine = [(r, x, y) for t, r, x, y in pts if t is s]
        if not mine:
            continue
        xs, ys = [x for _, x, _ in mine], [y for _, _, y in mine]
        front_here = [r["key"] in on_front for r, _, _ in mine]
        trace = {"type": "scatter", "mode": "lines+markers" if s["line"] else "markers",
                 "name": s["name"], "x": xs, "y": ys,
                 "customdata": [r["key"] for r, _, _ in mine],
                 "text": [hovers[r["key"]] + ("<br><b>on the Pareto front</b>" if f else "")
                          for (r, _, _), f in zip(mine, front_here)],
                 "hovertemplate": "%{text}<extra></extra>",
                 "marker": {"color": s["colour"], "symbol": SYMBOLS[s["marker"]], "size": 8,
                            "opacity": 0.9, "line": {"color": "#fff", "width": 0.8}},
                 "meta": {"role": "series", "kind": s["rows"][0]["kind"]}}
        if s["line"]:
            trace["line"] = {"color": s["colour"], "width": 1.2, "dash": "4px,3px"}
        ey = _error_bar(ys, [interval(r, column) for r, _, _ in mine])
        # (a time interval reaching 0 has no place on the log axis)
        ex = _error_bar(xs, [iv if iv and iv[0] > 0 else None
                             for iv in (interval(r, "total_ms") for r, _, _ in mine)])
        if ey:
            trace["error_y"] = ey
        if ex:
            trace["error_x"] = ex
        data.append(trace)
    layout = plotly_layout(440, {"type": "log", "range": [x0, x1]},
                           "time per frame, ms (log scale; method + blur)",
                           {"range": [y0, y1]}, label, column)
    return {"data": data, "layout": layout}


def plotly_layout(height: int, xaxis: dict, x_title: str, yaxis: dict, y_title: str,
                  column: str) -> dict:
    """A plotly.js layout of the report's plots: 720 px wide, framed axes with grid lines
    (``xaxis``, ``yaxis``: their ranges and types), the axis titles, the legend and hover
    style, and layout.meta.column, the results.csv column the y values are."""
    axis = {"gridcolor": "#e4e4e4", "zeroline": False, "linecolor": "#888", "mirror": True,
            "showline": True, "ticks": "outside", "tickfont": {"size": 11}}
    return {"width": 720, "height": height, "margin": {"l": 56, "r": 8, "t": 12, "b": 44},
            "xaxis": {**axis, **xaxis, "title": {"text": html.escape(x_title),
                                                 "font": {"size": 12}}},
            "yaxis": {**axis, **yaxis, "title": {"text": html.escape(y_title),
                                                 "font": {"size": 12}}},
            "legend": {"font": {"size": 11}, "tracegroupgap": 2},
            "hovermode": "closest", "hoverlabel": {"align": "left", "font": {"size": 11}},
            "plot_bgcolor": "#fff", "paper_bgcolor": "#fff",
            "font": {"family": "system-ui, sans-serif"}, "meta": {"column": column}}


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


# ----------------------------------------------------------------------------------------
# Tables


def _cell(v, fmt: str = ".4f") -> str:
    v = number(v)
    if v is None:
        return "—"
    return format(v, fmt)


_KIND_ORDER = {"baseline": 0, "method": 1, "cycles": 2, "rtao": 3, "noise_floor": 4,
               "eevee": 5, "limit": 6}


def row_order(r: dict):
    """Baseline, then methods by name and time, then peers by time (the Cycles ladder by spp)."""
    t = number(r.get("total_ms")) or 0.0
    if r["kind"] == "method":
        return (_KIND_ORDER["method"], r["method"], t, r["label"])
    return (_KIND_ORDER.get(r["kind"], 9), "", t, r["method"])


def table(rows: list[dict], floor: dict | None) -> str:
    front = set(pareto_front([(r["total_ms"], metric(r, "all_mae"), r["key"]) for r in rows
                              if r["kind"] in FRONT_KINDS and number(r.get("total_ms"))
                              and metric(r, "all_mae") is not None], True))
    head = ("<tr><th>method</th><th>setting</th><th>method ms<br><small>median (min–max)</small>"
            "</th><th>blur ms</th><th>total ms</th><th>MAE</th><th>SSIM</th><th>RMSE</th>"
            "<th>PSNR dB</th><th>bias</th><th>MAE calibrated<br><small>a·AO + b</small></th>"
            + "".join(f"<th>MAE {r.replace('_', ' ')}</th>" for r in REGIONS[1:])
            + "<th>occl. MAE / AO≡1</th><th>occl. MAE vs limit</th><th>flag</th></tr>")
    body = []
    ordered = sorted(rows, key=row_order)
    for r in ordered:
        t = number(r.get("method_ms"))
        if r["kind"] in ("method",) and t is not None:
            tms = f'{t:.1f} <small>({r["method_ms_min"]:.1f}–{r["method_ms_max"]:.1f})</small>'
        elif t is not None:
            tms = f"{t:.0f} <small>(render)</small>"
        else:
            tms = "—"
        b = number(r.get("blur_ms"))
        bms = f'{b:.1f}' if b is not None else "—"
        star = " ★" if r["key"] in front else ""
        flag = r.get("flag") or ""
        flag_html = '<span class="weak">weak on occluded</span>' if flag == "weak" else ""
        note = f' title="{html.escape(r["note"])}"' if r.get("note") else ""
        m = r.get("metrics")
        iv = r.get("intervals") or {}
        if m:
            cal = (f'{_cell(m["all"]["mae_cal"])} <small>(a {_cell(r.get("calib_a"), ".2f")}, '
                   f'b {_cell(r.get("calib_b"), ".2f")})</small>')
            cells = (f'<td>{_ci(m["all"]["mae"], iv.get("all_mae"))}</td>'
                     f'<td>{_cell(m["all"]["ssim"])}</td>'
                     f'<td>{_cell(m["all"]["rmse"])}</td><td>{_cell(m["all"]["psnr"], ".2f")}</td>'
                     f'<td>{_cell(m["all"]["bias"], "+.4f")}</td><td>{cal}</td>'
                     + "".join(f'<td>{_ci(m[reg]["mae"], iv.get(reg + "_mae"))}</td>'
                               for reg in REGIONS[1:])
                     + f'<td>{_cell(r.get("occluded_mae_vs_baseline"), ".2f")}</td>'
                     + f'<td>{_cell(r.get("occluded_mae_vs_limit"))}</td>')
        else:
            cells = f'<td colspan="{7 + len(REGIONS)}">{html.escape(r.get("note", ""))}</td>'
        body.append(f'<tr class="{r["kind"]}" data-key="{html.escape(r["key"])}"{note}>'
                    f'<td>{html.escape(r["method"])}</td><td>{html.escape(r["label"])}{star}</td>'
                    f'<td>{tms}</td><td>{bms}</td>'
                    f'<td>{_ci(r.get("total_ms"), iv.get("total_ms"), ".1f")}</td>'
                    f'{cells}<td>{flag_html}</td></tr>')
    if floor:
        body.append(f'<tr class="floor"><td colspan="5">reference noise floor '
                    f'({html.escape(floor["source"])})</td><td>{_cell(floor.get("all_mae"))}</td>'
                    f'<td>{_cell(floor.get("all_ssim"))}</td><td colspan="4"></td>'
                    + "".join(f'<td>{_cell(floor.get(reg + "_mae"))}</td>' for reg in REGIONS[1:])
                    + "<td></td><td></td><td></td></tr>")
    return f'<table class="results">{head}{"".join(body)}</table>'


# ----------------------------------------------------------------------------------------
# Temporal stability: sequences (docs/comparison.md, "Temporal stability")

#: Settings that draw a per-pixel random pattern fixed to the screen (aolab.method_info:
#: "randomly per pixel", a blue-noise or tiled rotation, random directions or start steps):
#: under a moving camera the pattern stays while the geometry slides beneath it. A setting
#: counts as on when its value is true, a non-zero number or a name other than "none".
NOISE_SETTINGS = ("random_rotation", "jitter", "noise", "rotation", "random_directions",
                  "random_start")


def per_pixel_noise(method: str, settings: dict) -> list[str]:
    """The NOISE_SETTINGS that are on for ``method`` with a row's recorded ``settings`` (which
    name only what differs from the method's defaults: aolab.method_info gives the rest)."""
    try:
        values = {s["name"]: s["default"] for s in aolab.method_info(method)["settings"]}
    except ValueError:      # a peer, the baseline or rtao: no method settings
        values = {}
    values.update(settings or {})
    on = []
    for name in NOISE_SETTINGS:
        v = values.get(name)
        off = isinstance(v, str) and v.lower() in ("none", "off", "false", "0")
        if v is None or v is False or v == 0 or off:
            continue
        on.append(name if v is True or isinstance(v, (int, float)) else f"{name} {v}")
    return on


def sequence_best(rows: list[dict], budget_ms: float) -> list[dict]:
    """Per method, among a sequence's rows (means over its frames), the configuration with the
    lowest MAE on all scored pixels within ``budget_ms`` (else its fastest), as the images
    choose; by method name."""
    out = []
    for m in sorted({r["method"] for r in rows if r["kind"] == "method"}):
        mine = [r for r in rows if r["kind"] == "method" and r["method"] == m
                and number(r.get("total_ms")) is not None and metric(r, "all_mae") is not None]
        fits = [r for r in mine if r["total_ms"] <= budget_ms]
        if fits:
            out.append(min(fits, key=lambda r: metric(r, "all_mae")))
        elif mine:
            out.append(min(mine, key=lambda r: r["total_ms"]))
    return out


#: The label of a configuration's accumulated rows (compare.py): its own label and this.
ACCUMULATED_SUFFIX = " + accumulation"
#: The preset each method is drawn at in a sequence's error-against-frame plot when the
#: sequence is accumulated (its defaults where it has no such preset).
FRAMES_PRESET = "medium"


def is_accumulated(row: dict) -> bool:
    return row.get("accumulated") is True


def config_label(row: dict) -> str:
    """A row's configuration label without ACCUMULATED_SUFFIX."""
    label = row["label"]
    return label[:-len(ACCUMULATED_SUFFIX)] if is_accumulated(row) and \
        label.endswith(ACCUMULATED_SUFFIX) else label


def frame_lines(name: str, rows: list[dict], budget_ms: float) -> list[dict]:
    """The lines of a sequence's error-against-frame plot, from ``rows`` (the study's): each
    {"name", "label", "colour", "dash", "rows"} with its frame rows in frame order. A sequence
    with accumulated rows: per method, FRAMES_PRESET (else "default", else its first
    configuration) in one frame (dashed) and accumulated (solid), in the method's colour;
    else each method's best configuration within ``budget_ms`` (sequence_best)."""
    frame_rows = [r for r in rows if r.get("sequence") == name and r.get("frame") is not None
                  and r["kind"] == "method" and metric(r, "all_mae") is not None]
    means = [r for r in rows if r["scene"] == name]
    methods = sorted({r["method"] for r in means if r["kind"] == "method"})
    colour = {m: PALETTE[i % len(PALETTE)] for i, m in enumerate(methods)}
    chosen = []   # (method, label, accumulated, dash)
    if any(is_accumulated(r) for r in means):
        for m in methods:
            labels = [r["label"] for r in means if r["kind"] == "method" and r["method"] == m
                      and r.get("accumulated") is False]
            pick = (FRAMES_PRESET if FRAMES_PRESET in labels else "default" if "default" in
                    labels else labels[0] if labels else None)
            if pick is not None:
                chosen += [(m, pick, False, "4px,3px"),
                           (m, pick + ACCUMULATED_SUFFIX, True, "solid")]
    else:
        chosen = [(b["method"], b["label"], False, "solid")
                  for b in sequence_best(means, budget_ms)]
    out = []
    for m, label, accumulated, dash in chosen:
        mine = sorted((r for r in frame_rows if r["method"] == m and r["label"] == label),
                      key=lambda r: r["frame"])
        if mine:
            out.append({"name": m + (ACCUMULATED_SUFFIX if accumulated else ""),
                        "label": label, "method": m, "colour": colour[m], "dash": dash,
                        "rows": mine})
    return out


def _frame_ranges(lines: list[dict]) -> tuple[list[int], float]:
    frames = sorted({r["frame"] for line in lines for r in line["rows"]})
    top = max(metric(r, "all_mae") for line in lines for r in line["rows"]) * 1.08 or 1.0
    return frames, top


def frames_plot(plot_id: str, lines: list[dict], standalone: bool = False) -> str:
    """MAE on all scored pixels against the frame (frame_lines' lines; the static plot).
    Every point is of class ``point`` with data-key (the frame's row), data-metric
    "all_mae", data-x (the frame) and data-y; the plot says data-x-column="frame"."""
    width, height = 672, 300
    ml, mr, mt, mb = 62, 232, 16, 44
    pw, ph = width - ml - mr, height - mt - mb
    if not lines:
        return "<p class='missing'>No frame has a scored configuration.</p>"
    frames, top = _frame_ranges(lines)
    x0, x1 = frames[0], frames[-1] if frames[-1] > frames[0] else frames[0] + 1

    def px(f):
        return ml + (f - x0) / (x1 - x0) * pw

    def py(y):
        return mt + (1 - y / top) * ph

    out = [f'<svg class="plot frames" id="{html.escape(plot_id)}" '
           'xmlns="http://www.w3.org/2000/svg" '
           f'width="{width}" height="{height}" viewBox="0 0 {width} {height}" '
           'data-metric="all_mae" data-x-column="frame" role="img" '
           'aria-label="MAE against the frame">',
           f'<rect x="{ml}" y="{mt}" width="{pw}" height="{ph}" class="frame"/>']
    if standalone:
        out.insert(1, f"<style>{SVG_CSS}</style>")
    for f in frames:
        X = px(f)
        out.append(f'<line x1="{X:.2f}" y1="{mt}" x2="{X:.2f}" y2="{mt + ph}" class="grid"/>'
                   f'<text x="{X:.2f}" y="{mt + ph + 16}" class="tick" text-anchor="middle">'
                   f'{f}</text>')
    _axes(out, _nice_ticks(0.0, top), py, (ml, mt, pw, ph, height), "frame",
          "MAE, all scored pixels")
    for i, line in enumerate(lines):
        colour = line["colour"]
        path = " ".join(f"{px(r['frame']):.2f},{py(metric(r, 'all_mae')):.2f}"
                        for r in line["rows"])
        dash = ("" if line["dash"] == "solid" else
                f' stroke-dasharray="{line["dash"].replace("px", "").replace(",", " ")}"')
        out.append(f'<polyline points="{path}" fill="none" stroke="{colour}" '
                   f'stroke-width="1.4"{dash}/>')
        for r in line["rows"]:
            f, y = r["frame"], metric(r, "all_mae")
            out.append(f'<circle cx="{px(f):.2f}" cy="{py(y):.2f}" r="3.2" class="point" '
                       f'fill="{colour}" data-key="{html.escape(r["key"])}" '
                       f'data-metric="all_mae" data-x="{f}" data-y="{_fmt(y)}"><title>'
                       f'{html.escape(r["key"])}: MAE {y:.4f}</title></circle>')
        ly = mt + 10 + 16 * i
        out.append(f'<line x1="{ml + pw + 10}" y1="{ly - 3}" x2="{ml + pw + 24}" y2="{ly - 3}" '
                   f'stroke="{colour}" stroke-width="2"{dash}/><text x="{ml + pw + 28}" '
                   f'y="{ly + 1}" class="legend">'
                   f'{html.escape(line["method"] + " " + line["label"])}</text>')
    out.append("</svg>")
    return "\n".join(out)


def frames_figure(lines: list[dict]) -> dict | None:
    """The plotly.js figure of frames_plot: one trace per line (its name the method, with
    ACCUMULATED_SUFFIX for an accumulated line, so that a legend click acts on the method in
    every plot of the section), customdata the frame rows' keys, x the frame, y the MAE;
    meta as plotly_figure's ({"role": "series", "kind": "method", "accumulated"}),
    layout.meta.column "all_mae". None without a line."""
    if not lines:
        return None
    frames, top = _frame_ranges(lines)
    data = []
    for line in lines:
        xs = [r["frame"] for r in line["rows"]]
        ys = [metric(r, "all_mae") for r in line["rows"]]
        data.append({
            "type": "scatter", "mode": "lines+markers", "name": line["name"],
            "legendgroup": line["method"], "x": xs, "y": ys,
            "customdata": [r["key"] for r in line["rows"]],
            "text": [html.escape(f'{line["method"]} {line["label"]}, frame {r["frame"]}: '
                                 f'MAE {y:.4f}', quote=False)
                     for r, y in zip(line["rows"], ys)],
            "hovertemplate": "%{text}<extra></extra>",
            "line": {"color": line["colour"], "width": 1.6, "dash": line["dash"]},
            "marker": {"color": line["colour"], "size": 6},
            "meta": {"role": "series", "kind": "method",
                     "accumulated": line["name"].endswith(ACCUMULATED_SUFFIX)}})
    layout = plotly_layout(380, {"tickvals": frames, "range": [frames[0] - 0.3, frames[-1] + 0.3]},
                           "frame", {"range": [0, top]}, "MAE, all scored pixels", "all_mae")
    return {"data": data, "layout": layout}


def flicker_entries(rows: list[dict]) -> list[dict]:
    """A sequence's rows (means over its frames) that have a flicker, least first: the
    configuration, its flicker, MAE, time and the per-pixel noise settings it has on."""
    out = [{"key": r["key"], "kind": r["kind"], "method": r["method"], "label": r["label"],
            "flicker": number(r.get("flicker")), "mae": metric(r, "all_mae"),
            "ms": number(r.get("total_ms")),
            # rtao draws its rays from a per-pixel hash: a random pattern too, not a setting
            "noise": (["random rays per pixel"] if r["kind"] == "rtao" else
                      per_pixel_noise(r["method"], r.get("settings") or {}))}
           for r in rows if number(r.get("flicker")) is not None]
    return sorted(out, key=lambda e: (e["flicker"], e["method"], e["label"]))


def flicker_table(entries: list[dict], floor: dict | None) -> str:
    head = ("<tr><th>method</th><th>setting</th><th>flicker</th><th>MAE (mean over frames)"
            "</th><th>ms</th><th>per-pixel random pattern</th></tr>")
    body = []
    if floor:
        body.append(f'<tr class="floor"><td colspan="2">reference flicker floor (est.)</td>'
                    f'<td>{_cell(floor.get("value"))}</td><td colspan="3">'
                    f'{html.escape(floor.get("source", ""))}</td></tr>')
    for e in entries:
        noise = ", ".join(e["noise"]) if e["noise"] else "none"
        body.append(f'<tr class="{e["kind"]}" data-key="{html.escape(e["key"])}" '
                    f'data-flicker="{_fmt(e["flicker"])}"><td>{html.escape(e["method"])}</td>'
                    f'<td>{html.escape(e["label"])}</td><td>{_cell(e["flicker"])}</td>'
                    f'<td>{_cell(e["mae"])}</td><td>{_cell(e["ms"], ".1f")}</td>'
                    f'<td>{html.escape(noise)}</td></tr>')
    return f'<table class="check flicker">{head}{"".join(body)}</table>'


def accumulation_entries(rows: list[dict], name: str) -> list[dict]:
    """Per configuration of sequence ``name`` that has accumulated rows: its single-frame and
    accumulated rows (means over the frames) side by side — times, converged error,
    disoccluded error, flicker; by method, then single-frame time."""
    means = [r for r in rows if r["scene"] == name and r["kind"] == "method"]
    acc = {(r["method"], config_label(r)): r for r in means if is_accumulated(r)}
    out = []
    for r in means:
        a = acc.get((r["method"], r["label"]))
        if r.get("accumulated") is not False or a is None:
            continue
        out.append({"method": r["method"], "label": r["label"], "single_key": r["key"],
                    "acc_key": a["key"], "single_ms": number(r.get("total_ms")),
                    "acc_ms": number(a.get("total_ms")), "step_ms": number(a.get("accumulate_ms")),
                    "single_converged": number(r.get("converged_mae")),
                    "acc_converged": number(a.get("converged_mae")),
                    "single_disoccluded": number(r.get("disoccluded_mae")),
                    "acc_disoccluded": number(a.get("disoccluded_mae")),
                    "single_flicker": number(r.get("flicker")),
                    "acc_flicker": number(a.get("flicker"))})
    big = math.inf
    return sorted(out, key=lambda e: (e["method"], e["single_ms"] or big, e["label"]))


#: The kinds of the peers' rows (reference_scenes/<name>/peers/peers.json).
PEER_KINDS = ("cycles", "eevee")


def peer_sequence_entries(rows: list[dict], name: str) -> list[dict]:
    """The peers of sequence ``name`` (EEVEE, rendered per frame: its own samples accumulated
    within each frame, nothing carried between frames) over its frames, for the accumulation
    tables: render time, converged error (the same frames as the configurations'),
    disoccluded error, flicker."""
    out = [{"name": r["method"], "label": r["label"], "key": r["key"],
            "ms": number(r.get("total_ms")), "converged": number(r.get("converged_mae")),
            "disoccluded": number(r.get("disoccluded_mae")), "flicker": number(r.get("flicker"))}
           for r in rows if r["scene"] == name and r["kind"] in PEER_KINDS]
    return sorted(out, key=lambda e: e["name"])


#: What the peers' row of the accumulation tables says of their times.
PEER_TIME_NOTE = ("EEVEE renders each frame with its own samples (Blender's render settings) "
                  "and carries nothing between frames; its time is Blender's render of the "
                  "frame on this machine (software OpenGL here), not comparable with the "
                  "methods' times.")


#: accumulation_pairs' rule, as the report and docs/results.md state it.
PAIRING_RULE = ("Per method, the cheapest configuration X (by its time per frame with the "
                "step) whose accumulated converged error beats the single-frame error, over the "
                "same frames, of a configuration Y dearer in one frame than X accumulated, "
                "which X in one frame does not beat; beside it the most accurate such Y.")


def accumulation_pairs(entries: list[dict]) -> list[dict]:
    """Per method (accumulation_entries' entries): the cheapest configuration X, by its time
    per frame with the accumulation step, whose accumulated converged error is below the
    single-frame error (over the same frames) of some configuration Y that is dearer in one
    frame than X accumulated and that X in one frame does not beat (so that the accumulation
    is what beats it); Y is the most accurate of those (the dearer on a tie). {"method",
    "x", "y"}: the two entries, both None when no configuration of the method has such a
    Y."""
    out = []
    for m in sorted({e["method"] for e in entries}):
        mine = [e for e in entries if e["method"] == m]
        xs = sorted((e for e in mine if e["acc_ms"] is not None
                     and e["acc_converged"] is not None),
                    key=lambda e: (e["acc_ms"], e["acc_converged"], e["label"]))
        pair = {"method": m, "x": None, "y": None}
        for x in xs:
            beaten = [y for y in mine if y["single_ms"] is not None
                      and y["single_converged"] is not None and y["single_ms"] > x["acc_ms"]
                      and x["acc_converged"] < y["single_converged"]
                      and x["single_converged"] is not None
                      and x["single_converged"] >= y["single_converged"]]
            if beaten:
                y = min(beaten, key=lambda e: (e["single_converged"], -e["single_ms"],
                                               e["label"]))
                pair = {"method": m, "x": x, "y": y}
                break
        out.append(pair)
    return out


def history_text(accumulation: dict) -> str:
    """How many frames the converged error's frames have accumulated: "8 frames" or
    "9–24 frames" (results.json's scenes.<sequence>.accumulation)."""
    n = accumulation.get("converged_history") or []
    if not n:
        return "— frames"
    return f"{n[0]} frames" if n[0] == n[-1] else f"{n[0]}–{n[-1]} frames"


def accumulation_rules(accumulation: dict) -> str:
    """The rules of a sequence's accumulation scores in words (plain text)."""
    a = accumulation
    frames = ", ".join(str(f) for f in a.get("converged_frames", []))
    if a.get("at_rest"):
        why = "nothing moves in it, so the last frame, the most accumulated"
    elif len(a.get("converged_frames", [])) == 1:
        why = (f"it has no frame of index {a.get('converged_from_index')} or later, so its "
               "last frame")
    else:
        why = f"the frames of index {a.get('converged_from_index')} on (0 first)"
    settings = ", ".join(f"{k} {v}" for k, v in (a.get("settings") or {}).items())
    return (f"Every configuration runs at frame=k (the frame's index, 0 first: a per-frame "
            f"seed) and is also accumulated with aolab.accumulate at the step's defaults "
            f"({settings}), one history per configuration, empty at the first frame. "
            f"Converged error: the mean whole-frame MAE over frame(s) {frames} ({why}), "
            f"{history_text(a)} accumulated. Disoccluded region: the scored pixels whose "
            f"history after the step holds fewer than {a.get('disoccluded_below')} frames "
            f"(rejected in this frame or the {a.get('disoccluded_below', 1) - 1} before); its "
            f"error pools every region pixel of the frames of index "
            f"{a.get('disoccluded_from_index')} on. Times: method + blur, and + the step "
            "for the accumulated rows.")


def _pair_cells(e: dict | None, accumulated: bool) -> str:
    if e is None:
        return "<td>—</td><td>—</td><td>—</td>"
    if accumulated:
        return (f'<td>{html.escape(e["label"])}{html.escape(ACCUMULATED_SUFFIX)}</td>'
                f'<td>{_cell(e["acc_ms"], ".1f")} <small>(step {_cell(e["step_ms"], ".1f")})'
                f'</small></td><td>{_cell(e["acc_converged"])}</td>')
    return (f'<td>{html.escape(e["label"])}</td><td>{_cell(e["single_ms"], ".1f")}</td>'
            f'<td>{_cell(e["single_converged"])}</td>')


def accumulation_html(name: str, rows: list[dict], info: dict) -> str:
    """A sequence's accumulation: the rules, the pairing (accumulation_pairs) and every
    configuration single-frame beside accumulated (accumulation_entries)."""
    entries = accumulation_entries(rows, name)
    if not entries:
        return ""
    acc = info.get("accumulation") or {}
    n = history_text(acc)
    head = (f"<tr><th>method</th><th>accumulated over {html.escape(n)}</th><th>ms per frame"
            "</th><th>converged MAE</th><th>beats in one frame</th><th>ms per frame</th>"
            "<th>MAE, same frames</th></tr>")
    body = []
    for p in accumulation_pairs(entries):
        x, y = p["x"], p["y"]
        attrs = (f' data-x="{html.escape(x["acc_key"])}" data-y="{html.escape(y["single_key"])}"'
                 if x else "")
        body.append(f'<tr data-method="{html.escape(p["method"])}"{attrs}>'
                    f'<td>{html.escape(p["method"])}</td>' + _pair_cells(x, True)
                    + (_pair_cells(y, False) if y else
                       '<td colspan="3">no configuration accumulated beats a dearer one in '
                       'one frame</td>') + "</tr>")
    pairs = f'<table class="check pairs">{head}{"".join(body)}</table>'
    head = ("<tr><th>method</th><th>setting</th><th>ms, one frame</th><th>ms, accumulated"
            "</th><th>converged MAE, one frame</th><th>accumulated</th><th>disoccluded MAE, "
            "one frame</th><th>accumulated</th><th>flicker, one frame</th><th>accumulated</th>"
            "</tr>")
    body = [f'<tr data-key="{html.escape(e["single_key"])}"><td>{html.escape(e["method"])}</td>'
            f'<td>{html.escape(e["label"])}</td><td>{_cell(e["single_ms"], ".1f")}</td>'
            f'<td>{_cell(e["acc_ms"], ".1f")}</td><td>{_cell(e["single_converged"])}</td>'
            f'<td>{_cell(e["acc_converged"])}</td><td>{_cell(e["single_disoccluded"])}</td>'
            f'<td>{_cell(e["acc_disoccluded"])}</td><td>{_cell(e["single_flicker"])}</td>'
            f'<td>{_cell(e["acc_flicker"])}</td></tr>' for e in entries]
    table_ = f'<table class="check accumulation">{head}{"".join(body)}</table>'
    peers = peer_sequence_entries(rows, name)
    peer_html = []
    if peers:
        head = ("<tr><th>peer</th><th>render ms per frame</th><th>converged MAE</th>"
                "<th>disoccluded MAE</th><th>flicker</th></tr>")
        body = [f'<tr data-key="{html.escape(e["key"])}"><td>{html.escape(e["label"])}</td>'
                f'<td>{_cell(e["ms"], ".0f")}</td><td>{_cell(e["converged"])}</td>'
                f'<td>{_cell(e["disoccluded"])}</td><td>{_cell(e["flicker"])}</td></tr>'
                for e in peers]
        peer_html = [f'<p class="note">The peers on the same frames. '
                     f'{html.escape(PEER_TIME_NOTE)}</p>',
                     f'<div class="scroll"><table class="check peers">{head}{"".join(body)}'
                     '</table></div>']
    return "\n".join([
        f'<h3 id="accumulation-{html.escape(name)}">Temporal accumulation</h3>',
        f'<p class="note">{html.escape(accumulation_rules(acc))} {PAIRING_RULE}</p>',
        f'<div class="scroll">{pairs}</div>',
        '<p class="note">Every configuration in one frame beside accumulated (times per '
        'frame; the errors and the flicker as above; the rows are in the table of the '
        'sequence and in results.csv):</p>', f'<div class="scroll">{table_}</div>',
        *peer_html])


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


# ----------------------------------------------------------------------------------------
# The error split, the tuned presets and the check against EEVEE

#: The parts of the error split: (key, label, colour).
SPLIT_PARTS = (
    ("total", "error: MAE against the reference", "#555555"),
    ("screen_space", "screen-space loss: the limit against the reference", LIMIT_COLOUR),
    ("definition", "definition: what an affine map a·AO + b removes", "#e67e22"),
    ("approximation", "approximation: MAE against the limit", "#1f77b4"),
)


def limit_mae(rows: list[dict], scenes: dict, column: str = "occluded_mae"):
    """The screen-space limit's score for ``rows`` of one scene or of ALL: the scene's chosen
    limit; over ALL, the mean of each scene's (a scene picks its own best thickness)."""
    scene = rows[0]["scene"] if rows else None
    if scene != "ALL":
        r = best_limit(rows)
        return metric(r, column) if r is not None else None
    got = [number((info.get("limit") or {}).get(column)) for info in scenes.values()]
    got = [v for v in got if v is not None]
    return float(np.mean(got)) if got else None


def error_split(rows: list[dict], scenes: dict) -> list[dict]:
    """Per shown configuration (each method's SPLIT_LABELS, and EEVEE) its occluded-region
    error and the three parts of docs/comparison.md, "The error split". The parts overlap:
    they need not add up to the error (the error is at most the screen-space loss plus the
    approximation, by the triangle inequality)."""
    loss = limit_mae(rows, scenes)
    out = []
    shown = [r for r in rows
             if (r["kind"] == "method" and r["label"] in SPLIT_LABELS) or r["kind"] == "eevee"]
    for r in sorted(shown, key=lambda r: (r["kind"] != "method", r["method"],
                                          SPLIT_LABELS.index(r["label"])
                                          if r["label"] in SPLIT_LABELS else 0)):
        total = number(r.get("metrics", {}).get("occluded", {}).get("mae"))
        if total is None:
            continue
        definition = number(r.get("occluded_mae_definition"))
        out.append({"key": r["key"], "name": f'{r["method"]} {r["label"]}'
                    if r["kind"] == "method" else r["method"],
                    "total": total, "screen_space": loss,
                    "definition": definition,
                    "approximation": number(r.get("occluded_mae_vs_limit"))})
    return out


def split_chart(plot_id: str, parts: list[dict]) -> str:
    """Horizontal grouped bars, one group per configuration of :func:`error_split`. Every bar
    is an element of class ``bar`` with data-key (its row), data-part and data-value."""
    if not parts:
        return "<p class='missing'>No configuration to split.</p>"
    values = [p[k] for p in parts for k, _, _ in SPLIT_PARTS if p.get(k) is not None]
    top = max(values) * 1.1 if values else 1.0
    bar, gap, ml, mt = 7, 10, 210, 46
    group = bar * len(SPLIT_PARTS) + gap
    width, pw = 760, 760 - 210 - 24
    height = mt + group * len(parts) + 40

    def px(v):
        return ml + v / top * pw

    out = [f'<svg class="split" id="{html.escape(plot_id)}" xmlns="http://www.w3.org/2000/svg" '
           f'width="{width}" height="{height}" viewBox="0 0 {width} {height}" role="img" '
           'aria-label="error split on the occluded region">']
    for t in _nice_ticks(0.0, top):
        X = px(t)
        out.append(f'<line x1="{X:.1f}" y1="{mt - 4}" x2="{X:.1f}" y2="{height - 36}" '
                   f'stroke="#e4e4e4"/><text x="{X:.1f}" y="{height - 22}" font-size="11" '
                   f'fill="#555" text-anchor="middle">{_tick_label(t)}</text>')
    out.append(f'<text x="{ml + pw / 2:.0f}" y="{height - 6}" font-size="12" fill="#333" '
               'text-anchor="middle">MAE on the occluded region (reference &lt; 0.9)</text>')
    for i, (key, label, colour) in enumerate(SPLIT_PARTS):   # the legend: two by two
        x, y = 8 + (i % 2) * 370, 6 + (i // 2) * 16
        out.append(f'<rect x="{x}" y="{y}" width="10" height="10" fill="{colour}"/>'
                   f'<text x="{x + 14}" y="{y + 9}" font-size="11" fill="#333">'
                   f'{html.escape(label)}</text>')
    for g, p in enumerate(parts):
        y0 = mt + g * group
        out.append(f'<text x="{ml - 6}" y="{y0 + bar * 2.6:.1f}" font-size="11" fill="#333" '
                   f'text-anchor="end">{html.escape(p["name"])}</text>')
        for i, (key, label, colour) in enumerate(SPLIT_PARTS):
            v = p.get(key)
            if v is None:
                continue
            out.append(f'<rect class="bar" x="{ml}" y="{y0 + i * bar}" width="{px(v) - ml:.2f}" '
                       f'height="{bar - 1}" fill="{colour}" data-key="{html.escape(p["key"])}" '
                       f'data-part="{key}" data-value="{_fmt(v)}"><title>'
                       f'{html.escape(p["name"])}: {html.escape(label)} {v:.4f}</title></rect>')
    out.append("</svg>")
    return "\n".join(out)


#: The paired comparisons cover this many of the best configurations.
PAIRED_TOP = 8
#: AO = 1's rows, the whole-frame guard's bound.
BASELINE_ROW = {"kind": "baseline", "method": "baseline_one", "label": "AO=1"}


def per_scene(results: dict, row: dict, column: str = "occluded_mae") -> dict:
    """Scene -> the value of ``column`` of ``row``'s configuration on each still scene."""
    stills = set(still_scenes(results.get("scenes", {})))
    return {r["scene"]: metric(r, column) for r in results["rows"]
            if r["scene"] in stills
            and (r["kind"], r["method"], r["label"]) == (row["kind"], row["method"], row["label"])}


def paired_comparisons(results: dict, budget_ms: float) -> list[dict]:
    """Each method's best admissible configuration within ``budget_ms`` (lowest mean occluded
    MAE over the still scenes, the ALL rows, among those no worse than AO = 1 on the whole
    frame of any scene), ranked, the first PAIRED_TOP of them; each compared with the one
    ranked just above it and with the first, paired by scene (stats.paired): which
    differences are real and which are noise."""
    best: dict = {}
    for r in results["rows"]:
        t, e = number(r.get("total_ms")), metric(r, "occluded_mae")
        if r["scene"] != "ALL" or r["kind"] != "method" or t is None or e is None or t > budget_ms:
            continue
        # the whole-frame guard against AO = 1 on every still scene the row has
        base = per_scene(results, BASELINE_ROW, "all_mae")
        mine = per_scene(results, r, "all_mae")
        if not whole_frame_ok(mine, {s: math.nan if base.get(s) is None else base[s]
                                     for s in mine}):
            continue
        if r["method"] not in best or e < metric(best[r["method"]], "occluded_mae"):
            best[r["method"]] = r
    ranked = sorted(best.values(), key=lambda r: metric(r, "occluded_mae"))[:PAIRED_TOP]
    out = []
    for i, r in enumerate(ranked):
        entry = {"rank": i + 1, "method": r["method"], "label": r["label"],
                 "ms": number(r.get("total_ms")), "mae": metric(r, "occluded_mae"),
                 "interval": (r.get("intervals") or {}).get("occluded_mae"),
                 "vs_above": None, "vs_first": None}
        if i:
            mine = per_scene(results, r)
            for key, other in (("vs_above", ranked[i - 1]), ("vs_first", ranked[0])):
                c = stats.paired(per_scene(results, other), mine)
                entry[key] = {**c, "verdict": stats.verdict(c)}
        out.append(entry)
    return out


def worse_than_nothing(results: dict, label: str = "default") -> list[dict]:
    """Per method, the still scenes where its ``label`` configuration (the paper's defaults)
    has a higher whole-frame MAE than AO = 1, the output that draws no occlusion: where the
    paper's own settings do worse than doing nothing. Methods with no such scene are left
    out."""
    stills = set(still_scenes(results.get("scenes", {})))
    base = {r["scene"]: metric(r, "all_mae") for r in results["rows"] if r["kind"] == "baseline"}
    out: dict = {}
    for r in results["rows"]:
        if r["kind"] != "method" or r["label"] != label or r["scene"] not in stills:
            continue
        mine, none = metric(r, "all_mae"), base.get(r["scene"])
        if mine is not None and none is not None and mine > none:
            out.setdefault(r["method"], []).append({"scene": r["scene"], "mae": mine,
                                                    "ao_one": none})
    return [{"method": m, "scenes": v} for m, v in sorted(out.items())]


def worse_than_nothing_html(entries: list[dict], n_scenes: int) -> str:
    if not entries:
        return ("<p class='note'>On every scene each method's defaults beat AO ≡ 1 on the "
                "whole frame.</p>")
    items = "".join(
        f'<li><b>{html.escape(e["method"])}</b> on {len(e["scenes"])} of {n_scenes} scenes: '
        + ", ".join(f'{html.escape(s["scene"])} ({s["mae"]:.4f} against {s["ao_one"]:.4f})'
                    for s in e["scenes"]) + "</li>" for e in entries)
    return f'<ul class="worse">{items}</ul>'


def paired_table(entries: list[dict], budget_ms: float) -> str:
    if not entries:
        return "<p class='missing'>No method within the budget.</p>"
    head = ("<tr><th>rank</th><th>configuration</th><th>ms</th><th>occluded MAE [95 % CI]</th>"
            "<th>the one above wins on</th><th>difference to the one above</th>"
            "<th>the first wins on</th><th>difference to the first</th></tr>")
    body = []
    for e in entries:
        cells = []
        for key in ("vs_above", "vs_first"):
            c = e[key]
            if c is None:
                cells.append("<td>—</td><td>—</td>")
                continue
            cls = "real" if c["real"] else "noise"
            cells.append(f'<td>{c["wins"]} of {c["n"]} scenes</td>'
                         f'<td class="{cls}">{html.escape(c["verdict"])}</td>')
        body.append(f'<tr data-rank="{e["rank"]}"><td>{e["rank"]}</td>'
                    f'<td>{html.escape(e["method"])} {html.escape(e["label"])}</td>'
                    f'<td>{_cell(e["ms"], ".1f")}</td><td>{_ci(e["mae"], e["interval"])}</td>'
                    + "".join(cells) + "</tr>")
    return (f'<table class="check paired">{head}{"".join(body)}</table>')


def eevee_check(results: dict, budget_ms: float = EEVEE_CHECK_BUDGET_MS) -> list[dict]:
    """Per scene: the screen-space limit's, EEVEE's and the best tuned configuration's (within
    ``budget_ms``, held out across methods: budget.best_across_methods) occluded MAE, and the
    verdict — "pass" where the limit is below EEVEE and the tuned configuration is too,
    "fail" where it is not, "limit" where even the limit is not below EEVEE (no screen-space
    method can be expected to beat it there), "unknown" where a number is missing."""
    tuned = results.get("tuned") or {}
    best = budget.best_across_methods(tuned.get("methods", {}), budget_ms) if tuned else {}
    larger = (budget.best_across_methods(tuned.get("methods", {}), LARGEST_TUNED_BUDGET_MS)
              if tuned else {})
    out = []
    for name in results["meta"].get("scenes", []):
        if (results.get("scenes", {}).get(name) or {}).get("sequence"):
            continue    # a sequence has no peers: tuning and EEVEE are about the stills
        rows = [r for r in results["rows"] if r["scene"] == name]
        eevee = [metric(r, "occluded_mae") for r in rows if r["kind"] == "eevee"]
        eevee = eevee[0] if eevee else None
        limit = best_limit(rows)
        lim = metric(limit, "occluded_mae") if limit is not None else None
        pick = best.get(name)
        mine = number(pick["mae"]) if pick else None
        if eevee is None or lim is None or mine is None:
            verdict = "unknown"
        elif lim >= eevee:
            verdict = "limit"
        else:
            verdict = "pass" if mine < eevee else "fail"
        out.append({"scene": name, "eevee": eevee, "limit": lim,
                    "limit_label": limit["label"] if limit else None, "tuned": mine,
                    "method": pick["method"] if pick else None,
                    "trial": pick["trial"] if pick else None,
                    "ms": number(pick["ms"]) if pick else None,
                    "within_budget": pick["within_budget"] if pick else None,
                    "larger": number(larger[name]["mae"]) if larger.get(name) else None,
                    "larger_method": larger[name]["method"] if larger.get(name) else None,
                    "verdict": verdict})
    return out


def eevee_releases(results: dict) -> list[dict]:
    """Per scene, each EEVEE peer's scores (GTAO from Blender 3.4, EEVEE Next from 4.2+,
    where committed): MAE, bias and occluded MAE against the same Cycles reference, and its
    settings and Blender release: what the newer EEVEE changed."""
    out = []
    for name in results["meta"].get("scenes", []):
        for r in results["rows"]:
            if r["scene"] == name and r["kind"] == "eevee":
                m = r["metrics"]["all"]
                out.append({"scene": name, "peer": r["method"], "mae": number(m.get("mae")),
                            "bias": number(m.get("bias")),
                            "occluded_mae": number(metric(r, "occluded_mae")),
                            "blender": (r.get("settings") or {}).get("blender_version")})
    return out


def eevee_table(checks: list[dict], budget_ms: float = EEVEE_CHECK_BUDGET_MS) -> str:
    head = ("<tr><th>scene</th><th>screen-space limit</th><th>EEVEE GTAO</th>"
            f"<th>best tuned ≤ {budget_ms:g} ms, held out</th><th>its method, trial, ms</th>"
            f"<th>verdict</th><th>best tuned ≤ {LARGEST_TUNED_BUDGET_MS} ms, held out</th></tr>")
    words = {"pass": "below EEVEE", "fail": "not below EEVEE",
             "limit": "the limit itself is not below EEVEE", "unknown": "a number is missing"}
    body = []
    for c in checks:
        who = (f'{html.escape(c["method"])} trial {c["trial"]}, {c["ms"]:.1f} ms'
               + ("" if c["within_budget"] else " (over budget on this scene)")
               if c["method"] else "—")
        cls = "pass" if c["verdict"] == "pass" else ("fail" if c["verdict"] == "fail" else "")
        body.append(f'<tr data-scene="{html.escape(c["scene"])}" data-verdict="{c["verdict"]}">'
                    f'<td>{html.escape(c["scene"])}</td>'
                    f'<td>{_cell(c["limit"])} <small>{html.escape(c["limit_label"] or "")}'
                    f'</small></td><td>{_cell(c["eevee"])}</td><td>{_cell(c["tuned"])}</td>'
                    f'<td>{who}</td><td class="{cls}">{words[c["verdict"]]}</td>'
                    f'<td>{_cell(c["larger"])} <small>{html.escape(c["larger_method"] or "")}'
                    '</small></td></tr>')
    return f'<table class="check">{head}{"".join(body)}</table>'


def tuned_rows(tuned: dict) -> list[dict]:
    """One row per method and budget of the tuned presets: what ships (the tuned choice or the
    default), its time and errors on all scenes, its leave-one-family-out error, the
    generalisation gap and the default's held-out error; a budget with nothing shipped has
    its reason."""
    out = []
    for method, entry in tuned.get("methods", {}).items():
        for name, sel in entry.get("selection", {}).items():
            out.append({"method": method, "preset": name, "trial": sel.get("trial"),
                        "ships": sel.get("ships", "tuned"), "ms": sel.get("mean_ms"),
                        "mae": sel.get("mean_mae"), "all_mae": sel.get("mean_all_mae"),
                        "held_out": sel.get("held_out_mean_mae"), "gap": sel.get("gap"),
                        "default_held_out": sel.get("default_held_out_mean_mae"),
                        "folds": sel.get("held_out_folds")})
        for name, why in entry.get("unshipped", {}).items():
            out.append({"method": method, "preset": name, "unshipped": why})
    return out


def tuned_table(tuned: dict) -> str:
    """The tuned presets (tuned_rows): the error on all scenes (how each was chosen) and the
    leave-one-family-out error (the honest one)."""
    head = ("<tr><th>method</th><th>preset</th><th>ships</th><th>trial</th><th>ms</th>"
            "<th>occluded MAE, chosen on all scenes</th><th>whole-frame MAE</th>"
            "<th>held out (leave one family out)</th><th>gap</th><th>default, held out</th>"
            "<th>folds</th></tr>")
    body = []
    for r in tuned_rows(tuned):
        if "unshipped" in r:
            body.append(f'<tr><td>{html.escape(r["method"])}</td><td>{html.escape(r["preset"])}'
                        f'</td><td colspan="9">not shipped: {html.escape(r["unshipped"])}</td>'
                        '</tr>')
            continue
        body.append(f'<tr><td>{html.escape(r["method"])}</td><td>{html.escape(r["preset"])}</td>'
                    f'<td>{html.escape(r["ships"])}</td><td>{r["trial"]}</td>'
                    f'<td>{_cell(r["ms"], ".1f")}</td><td>{_cell(r["mae"])}</td>'
                    f'<td>{_cell(r["all_mae"])}</td><td>{_cell(r["held_out"])}</td>'
                    f'<td>{_cell(r["gap"], "+.4f")}</td><td>{_cell(r["default_held_out"])}</td>'
                    f'<td>{r["folds"]}</td></tr>')
    if not body:
        return "<p class='missing'>No tuned presets (run aolab tune: docs/tuning.md).</p>"
    return f'<table class="check">{head}{"".join(body)}</table>'


# ----------------------------------------------------------------------------------------
# Images


def _rgb(colour) -> str:
    return "rgb(" + ",".join(str(int(c * 255)) for c in colour) + ")"


def _colour_bar() -> str:
    return (f'<svg class="colourbar" xmlns="http://www.w3.org/2000/svg" width="300" height="40">'
            '<defs><linearGradient id="errgrad" x1="0" x2="1" y1="0" y2="0">'
            f'<stop offset="0" stop-color="{_rgb(DARKER_RGB)}"/>'
            '<stop offset="0.5" stop-color="#ffffff"/>'
            f'<stop offset="1" stop-color="{_rgb(LIGHTER_RGB)}"/>'
            '</linearGradient></defs>'
            '<rect x="10" y="4" width="280" height="14" fill="url(#errgrad)" '
            'stroke="#888"/>'
            f'<text x="10" y="34" class="tick">−{ERROR_SCALE:g} darker</text>'
            '<text x="150" y="34" class="tick" text-anchor="middle">0</text>'
            f'<text x="290" y="34" class="tick" text-anchor="end">+{ERROR_SCALE:g} lighter</text>'
            '</svg>')


def image_files(scene: str, imgs: dict, out: report_files.Files) -> dict:
    """A scene's encoded images (compare.scene_images) added to ``out``: {"reference": its
    name, "configs": {"method/label": [AO's name, signed error's name]}, "size": [w, h]}."""
    return {"reference": out.add(f"{scene}_reference", ".webp", imgs["reference"]),
            "configs": {c: [out.add(f"{scene}_{c}_ao", ".webp", d["ao"]),
                            out.add(f"{scene}_{c}_error", ".webp", d["error"])]
                        for c, d in imgs["configs"].items()},
            "size": list(imgs["size"])}


def _img(src: str, alt: str, size: list, cls: str = "") -> str:
    return (f'<img class="{cls}" alt="{html.escape(alt)}" width="{size[0]}" height="{size[1]}" '
            f'src="{html.escape(src)}">')


def image_grid(scene: str, imgs: dict | None, names: dict | None, budget_ms: float) -> str:
    """The reference, then each entry of compare.scene_images with its AO and signed error;
    ``names``: image_files' names of the scene's images."""
    if not imgs or not names:
        return "<p class='missing'>No images (the scene did not finish).</p>"
    size = names["size"]
    cards = [f'<figure class="card"><figcaption><b>Cycles 1024 spp reference</b></figcaption>'
             f'{_img(names["reference"], f"{scene} reference", size)}</figure>']
    for e in imgs["entries"]:
        if e["kind"] == "method":
            caption = (f'<b>{html.escape(e["method"])}</b> {html.escape(e["label"])}, '
                       f'{e["total_ms"]:.1f} ms, MAE {e["mae"]:.4f}'
                       + ("" if e["within_budget"] else f" — <i>fastest setting; none within "
                          f"{budget_ms:g} ms</i>"))
        else:
            what = "oracle" if e["kind"] == "limit" else "render"
            t = f'{e["total_ms"] / 1000:.1f} s {what}' if e.get("total_ms") else "no time"
            caption = f'<b>{html.escape(e["method"])}</b> ({t}), MAE {e["mae"]:.4f}'
        ao, err = names["configs"].get(e["config"]) or (None, None)
        shots = (f'{_img(ao, e["key"] + " AO", size)}'
                 f'{_img(err, e["key"] + " signed error", size, "err")}' if ao else
                 "<p class='missing'>no image</p>")
        cards.append(f'<figure class="card" data-key="{html.escape(e["key"])}"><figcaption>'
                     f'{caption}</figcaption>{shots}</figure>')
    return (f'<div class="grid">{"".join(cards)}</div><div class="legendbar">Signed error '
            f'(method − reference), saturating at ±{ERROR_SCALE:g}: {_colour_bar()}</div>')


# ----------------------------------------------------------------------------------------
# The page

SVG_CSS = """
svg.plot{background:#fff;border:1px solid #ddd;font-family:system-ui,sans-serif}
svg .frame{fill:none;stroke:#888} svg .grid{stroke:#e4e4e4} svg .grid.minor{stroke:#f2f2f2}
svg .tick{font-size:11px;fill:#555} svg .axis{font-size:12px;fill:#333}
svg .legend{font-size:11px;fill:#333}
svg .point{stroke:#fff;stroke-width:0.8;opacity:0.9} svg .point.front{stroke:#000;stroke-width:1.6}
svg .front-line{fill:none;stroke:#000;stroke-width:1.4;opacity:0.55}
svg .ci{stroke:#555;stroke-width:1;opacity:0.55}
td.real{color:#1a7f37;font-weight:600} td.noise{color:#777}
svg .hline{stroke-width:1.3} svg .hline.baseline{stroke:#c0392b;stroke-dasharray:7 4}
svg .hline.floor{stroke:#27ae60;stroke-dasharray:2 3}
svg .hline.weak{stroke:#e67e22;stroke-dasharray:3 5} svg .hlabel.weak{fill:#e67e22}
svg .hlabel{font-size:10px} svg .hlabel.baseline{fill:#c0392b} svg .hlabel.floor{fill:#27ae60}
svg .hline.limit{stroke:#2e7d32;stroke-dasharray:10 3 2 3} svg .hlabel.limit{fill:#2e7d32}
svg.split{background:#fff;border:1px solid #ddd;font-family:system-ui,sans-serif}
"""

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


#: The scene name of the means over the scenes (compare.AGGREGATE_SCENE).
AGGREGATE = "ALL"


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


def rtao_ladder(rows: list[dict]) -> list[dict]:
    """Per rung of rtao's ladder in ``rows`` (one scene, or the ALL means): its time and MAE
    over all scored pixels, and the most accurate screen-space configuration (kind "method")
    whose time is within the rung's, with its time and MAE; ``winner`` says which is more
    accurate at that budget ("screen space", "rtao", or "" when no method fits)."""
    methods = [r for r in rows if r["kind"] == "method" and number(r.get("total_ms"))
               and metric(r, "all_mae") is not None]
    out = []
    # In order of rays, not of time: at a few rays the packet sizes make the times close, and
    # a noisy run must not reorder the ladder.
    rungs = sorted((r for r in rows if r["kind"] == "rtao" and number(r.get("total_ms"))
                    and metric(r, "all_mae") is not None),
                   key=lambda r: ((r.get("settings") or {}).get("rays") or 0, r["total_ms"]))
    for r in rungs:
        fits = [m for m in methods if m["total_ms"] <= r["total_ms"]]
        best = min(fits, key=lambda m: metric(m, "all_mae")) if fits else None
        winner = ""
        if best is not None:
            winner = "screen space" if metric(best, "all_mae") < metric(r, "all_mae") else "rtao"
        out.append({"label": r["label"], "rays": (r.get("settings") or {}).get("rays"),
                    "ms": r["total_ms"], "mae": metric(r, "all_mae"),
                    "method": f'{best["method"]} {best["label"]}' if best else None,
                    "method_ms": best["total_ms"] if best else None,
                    "method_mae": metric(best, "all_mae") if best else None, "winner": winner})
    return out


def rtao_crossover(ladder: list[dict]) -> float | None:
    """The time of the cheapest rtao rung more accurate than every screen-space configuration
    as fast as it: below it screen space wins; None if no rung wins."""
    wins = [e["ms"] for e in ladder if e["winner"] == "rtao"]
    return min(wins) if wins else None


def rtao_not_run(results: dict) -> str:
    """Why rtao has no rows on some scenes: "scene, scene: reason" for each reason (the mesh
    is missing, of another scene, or refused), or "" when it ran wherever the study asked for
    it."""
    scenes = results.get("scenes") or {}
    by_reason: dict[str, list[str]] = {}   # scenes with the same reason said once
    for name, info in scenes.items():
        if (info or {}).get("rtao_not_run"):
            by_reason.setdefault(info["rtao_not_run"], []).append(name)
    for why, names in by_reason.items():   # a sequence's frames said as one name
        for seq, info in scenes.items():
            frames = (info or {}).get("frame_scenes") or []
            if frames and set(frames) <= set(names):
                at = names.index(frames[0])
                names[:] = [n for n in names if n not in frames]
                names.insert(at, f"{seq} (its {len(frames)} frames)")
    return "; ".join(f"{', '.join(names)}: {why}" for why, names in by_reason.items())


def rtao_table(ladder: list[dict], not_run: str = "") -> str:
    """The ladder against screen space; ``not_run`` (rtao_not_run) says where rtao did not
    run and why."""
    why = f"<p class='missing'>rtao not run on {html.escape(not_run)}</p>" if not_run else ""
    if not ladder:
        return why or ("<p class='missing'>No rtao rows: no scene has a mesh beside its "
                       "reference (aolab mesh), or the study ran with --rtao-rays none.</p>")
    head = ("<tr><th>rtao</th><th>ms</th><th>MAE</th><th>best screen-space within that time"
            "</th><th>ms</th><th>MAE</th><th>more accurate</th></tr>")
    body = [f'<tr><td>{html.escape(e["label"])}</td><td>{_cell(e["ms"], ".1f")}</td>'
            f'<td>{_cell(e["mae"])}</td><td>{html.escape(e["method"] or "—")}</td>'
            f'<td>{_cell(e["method_ms"], ".1f")}</td><td>{_cell(e["method_mae"])}</td>'
            f'<td>{html.escape(e["winner"] or "—")}</td></tr>' for e in ladder]
    return f'<table class="check">{head}{"".join(body)}</table>{why}'


def study_sections(results: dict, agg: list[dict]) -> str:
    """The error split over all scenes, the tuned presets and the check against EEVEE."""
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
    if any(r["kind"] == "limit" for r in results["rows"]):
        parts.append(split_chart("split-ALL", error_split(agg, results.get("scenes", {}))))
    else:
        parts.append("<p class='missing'>No committed screen-space limits (reference_scenes/"
                     "&lt;scene&gt;/limits/: aolab limits): no split.</p>")
    budget = results["meta"].get("budget_ms", 0)
    parts.append(f'<h2 id="paired">Which differences are real</h2><p class="note">Each '
                 f'method\'s most accurate configuration within {budget:g} ms per 1280×720 '
                 'frame that is no worse than AO ≡ 1 on the whole frame of any scene, ranked '
                 'by mean occluded MAE with its 95 % bootstrap interval over the '
                 'scenes, and compared scene by scene with the one ranked above it and with the '
                 'first: on how many scenes the better one wins, and the two-sided Wilcoxon '
                 f'signed-rank test; a difference with p ≥ {stats.ALPHA:g} is not told apart '
                 'from the scatter between scenes (docs/comparison.md).</p>')
    parts.append(paired_table(paired_comparisons(results, budget), budget))
    stills = still_scenes(results.get("scenes", {}))
    parts.append('<h2 id="worse-than-nothing">Defaults worse than no occlusion</h2><p class='
                 '"note">Where a method at its paper\'s defaults has a higher whole-frame MAE '
                 'than AO ≡ 1 — drawing no occlusion at all would be closer to the reference '
                 '(whole-frame MAE, the method\'s against AO ≡ 1\'s). No tuned preset ships '
                 'worse than AO ≡ 1 on any scene (docs/tuning.md).</p>')
    parts.append(worse_than_nothing_html(worse_than_nothing(results), len(stills)))
    tuned = results.get("tuned")
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
    parts.append(tuned_table(tuned or {}))
    parts.append(f'<h2 id="eevee">Against EEVEE</h2><p class="note">Per scene: where the '
                 'screen-space limit is below EEVEE\'s occluded MAE, does the best tuned '
                 f'configuration within {EEVEE_CHECK_BUDGET_MS} ms, chosen on the other scenes '
                 'among every method\'s trials, beat EEVEE too?</p>')
    parts.append(eevee_table(eevee_check(results)))
    ladder = rtao_ladder(agg)
    cross = rtao_crossover(ladder)
    parts.append('<h2 id="rtao">Against a CPU ray tracer</h2><p class="note">rtao (Embree on '
                 'the same cores, the BVH build apart) at each rung of rays per pixel, against '
                 'the most accurate screen-space configuration as fast as it, means over the '
                 'scenes: ' + (f'from {cross:.0f} ms on, the ray tracer is more accurate.'
                               if cross is not None else
                               'screen space is more accurate at every rung.') + '</p>')
    parts.append(rtao_table(ladder, rtao_not_run(results)))
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
        body.append(study_sections(results, agg))
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
