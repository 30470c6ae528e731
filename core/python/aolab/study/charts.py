"""The charts of a comparison study, drawn from its rows and findings (findings.py): the
accuracy-against-time scatter plots (static SVG: svg_plot; plotly.js: plotly_figure), a
sequence's error against the frame (frames_plot, frames_figure) and the error split's bars
(split_chart). The report (report.py) and docs/results.md (results_doc.py) draw the same charts.

A static plot's points are elements of class ``point`` with ``data-key``, ``data-metric``,
``data-x`` and ``data-y``; a plotly.js point's customdata is the key of its row in results.csv,
its x total_ms and its y the value of the column in layout.meta.column, so that a test can
match every point to its row.
"""

from __future__ import annotations

import html
import math

from .. import catalog
from .findings import (FRAMES_PRESET, FRONT_KINDS, WEAK_FRACTION, ACCUMULATED_SUFFIX, best_limit,
                       interval, is_accumulated, metric, number, pareto_front, sequence_best,
                       with_interval)

#: (results.csv column, axis label, lower is better)
PLOTS = (
    ("all_mae", "MAE, all scored pixels", True),
    ("occluded_mae", "MAE, occluded region (reference < 0.9)", True),
    ("all_ssim", "SSIM, all scored pixels", False),
)


#: One colour per method (eleven methods, the screen-space limit drawn apart), distinct on
#: white and from the peers' colours below.
PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf",
           "#bcbd22", "#d62728", "#7f7f7f", "#000080", "#00a087", "#800000", "#ff1493")


CYCLES_COLOUR = "#444444"


EEVEE_COLOUR = "#b8860b"


RTAO_COLOUR = "#7b1fa2"


LIMIT_COLOUR = "#2e7d32"


def attr_number(v) -> str:
    """A number as a data- attribute holds it (repr of the float: every bit), "" when
    missing."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return ""
    return repr(float(v))


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
    box = (ml, mt, pw, ph, height)
    _time_axis(out, x0, x1, px, box)
    _axes(out, _nice_ticks(y0, y1), py, box, "time per frame, ms (log scale; method + blur)",
          label)
    _svg_hlines(out, lines, column, py, box)
    front = plot_front(pts, lower_is_better)
    _svg_front(out, front, pts, px, py)
    _svg_series(out, series, pts, set(front), column, label, (px, py))
    _svg_legend(out, series, lines, ml + pw + 14, mt + 8)
    out.append("</svg>")
    return "\n".join(out)


def _time_axis(out: list[str], x0: int, x1: int, px, box: tuple) -> None:
    """The log time axis's grid lines at 1, 2 and 5 of each decade, labelled at the decades
    (at every line when the axis spans two decades or less)."""
    ml, mt, pw, ph, height = box
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


def _svg_hlines(out: list[str], lines: list[dict], column: str, py, box: tuple) -> None:
    """The horizontal lines (hlines_for: AO = 1 baseline, noise floor, limit) with their
    inline labels."""
    ml, mt, pw, ph, height = box
    for h in lines:
        Y = py(h["value"])
        out.append(f'<line x1="{ml}" y1="{Y:.2f}" x2="{ml + pw}" y2="{Y:.2f}" '
                   f'class="hline {h["cls"]}" data-key="{html.escape(h["key"])}" '
                   f'data-metric="{column}" data-y="{attr_number(h["value"])}">'
                   f'<title>{html.escape(h["title"])}: {h["value"]:.4g}</title></line>')
        if h.get("inline", True):
            out.append(f'<text x="{ml + pw - 4}" y="{Y - 4:.2f}" class="hlabel {h["cls"]}" '
                       f'text-anchor="end">{html.escape(h["label"])}</text>')


def _svg_front(out: list[str], front: list[str], pts: list[tuple], px, py) -> None:
    """The Pareto front's step line, when it has more than one point."""
    if len(front) <= 1:
        return
    where = {r["key"]: (x, y) for s, r, x, y in pts}
    path = []
    for i, k in enumerate(front):
        x, y = where[k]
        if i:
            path.append(f"{px(x):.2f},{py(where[front[i - 1]][1]):.2f}")
        path.append(f"{px(x):.2f},{py(y):.2f}")
    out.append(f'<polyline points="{" ".join(path)}" class="front-line"/>')


def _svg_series(out: list[str], series: list[dict], pts: list[tuple], front: set, column: str,
                label: str, scale: tuple) -> None:
    """Each series's points (the front's larger), their interval bars and, for a ladder, its
    dashed line; ``scale``: (px, py)."""
    px, py = scale
    for s in series:
        mine = [(r, x, y) for t, r, x, y in pts if t is s]
        if s["line"] and len(mine) > 1:
            poly = " ".join(f"{px(x):.2f},{py(y):.2f}" for r, x, y in mine)
            out.append(f'<polyline points="{poly}" fill="none" stroke="{s["colour"]}" '
                       'stroke-width="1.2" stroke-dasharray="4 3"/>')
        for r, x, y in mine:
            out += error_bars(r, column, px, py)
        for r, x, y in mine:
            on = r["key"] in front
            cls = "point front" if on else "point"
            attrs = (f'class="{cls}" fill="{s["colour"]}" data-key="{html.escape(r["key"])}" '
                     f'data-metric="{column}" data-x="{attr_number(x)}" '
                     f'data-y="{attr_number(y)}"')
            tip = (f'{r["method"]} {r["label"]}: {x:.4g} ms, {label} {y:.4g}'
                   + (" (Pareto front)" if on else ""))
            el = _marker(s["marker"], px(x), py(y), 5.5 if on else 4.0, attrs)
            out.append(el[:-2] + f"><title>{html.escape(tip)}</title></{el.split()[0][1:]}>")


def _svg_legend(out: list[str], series: list[dict], lines: list[dict], lx: float,
                ly: float) -> None:
    """The legend at (lx, ly): the series, the Pareto front, the horizontal lines."""
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
                   f'data-lo="{attr_number(lo)}" data-hi="{attr_number(hi)}"/>')
    if iv.get("total_ms") and y is not None and iv["total_ms"][0] > 0:
        lo, hi = iv["total_ms"]
        out.append(f'<line x1="{px(lo):.2f}" y1="{py(y):.2f}" x2="{px(hi):.2f}" '
                   f'y2="{py(y):.2f}" class="ci"/>')
    return out


def hlines_for(rows: list[dict], column: str, floor: dict | None) -> list[dict]:
    out = []
    limit = best_limit(rows)
    if limit is not None and metric(limit, column) is not None:
        out.append({"key": limit["key"], "value": metric(limit, column), "cls": "limit",
                    "label": f"screen-space limit ({limit['label']})",
                    "title": "the screen-space limit at its best thickness (a bound)"})
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
        lines.append(with_interval(t, interval(row, "total_ms"), ".1f") + " ms")
    for column, name in (("all_mae", "MAE"), ("occluded_mae", "MAE occluded")):
        v = metric(row, column)
        if v is not None:
            lines.append(f"{name} {with_interval(v, interval(row, column), '.4f')}")
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
                       f'data-metric="all_mae" data-x="{f}" data-y="{attr_number(y)}"><title>'
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


#: The parts of the error split: (key, label, colour).
SPLIT_PARTS = (
    ("total", "error: MAE against the reference", "#555555"),
    ("screen_space", "screen-space loss: the limit against the reference", LIMIT_COLOUR),
    ("definition", "definition: what an affine map a·AO + b removes", "#e67e22"),
    ("approximation", "approximation: MAE against the limit", "#1f77b4"),
)


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
                       f'data-part="{key}" data-value="{attr_number(v)}"><title>'
                       f'{html.escape(p["name"])}: {html.escape(label)} {v:.4f}</title></rect>')
    out.append("</svg>")
    return "\n".join(out)


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
