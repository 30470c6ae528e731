"""The HTML tables and image grids of report.html (report.py), each from findings.py's data:
a scene's results table, the flicker and accumulation tables of a sequence, the paired
comparisons, the defaults worse than AO = 1, the check against EEVEE, the tuned presets, rtao's
ladder and a scene's images with their signed error maps."""

from __future__ import annotations

import html

from ..regions import REGIONS
# The signed error maps' colours and scale are aolab.scoring's (the add-on's too).
from ..scoring import DARKER_RGB, ERROR_SCALE, LIGHTER_RGB
from . import report_files
from .charts import attr_number
from .findings import (ACCUMULATED_SUFFIX, FRONT_KINDS, LARGEST_TUNED_BUDGET_MS,
                       EEVEE_CHECK_BUDGET_MS, PAIRING_RULE, PEER_TIME_NOTE, accumulation_entries,
                       accumulation_pairs, accumulation_rules, cell, history_text, interval_text,
                       metric, number, pareto_front, peer_sequence_entries, row_order)


def _ci(value, iv, fmt: str = ".4f") -> str:
    """A mean and, when it has one, its 95 % interval over the scenes (smaller, after it)."""
    if not iv:
        return cell(value, fmt)
    return f'{cell(value, fmt)} <small class="ci">{interval_text(iv, fmt)}</small>'


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
            cal = (f'{cell(m["all"]["mae_cal"])} <small>(a {cell(r.get("calib_a"), ".2f")}, '
                   f'b {cell(r.get("calib_b"), ".2f")})</small>')
            cells = (f'<td>{_ci(m["all"]["mae"], iv.get("all_mae"))}</td>'
                     f'<td>{cell(m["all"]["ssim"])}</td>'
                     f'<td>{cell(m["all"]["rmse"])}</td><td>{cell(m["all"]["psnr"], ".2f")}</td>'
                     f'<td>{cell(m["all"]["bias"], "+.4f")}</td><td>{cal}</td>'
                     + "".join(f'<td>{_ci(m[reg]["mae"], iv.get(reg + "_mae"))}</td>'
                               for reg in REGIONS[1:])
                     + f'<td>{cell(r.get("occluded_mae_vs_baseline"), ".2f")}</td>'
                     + f'<td>{cell(r.get("occluded_mae_vs_limit"))}</td>')
        else:
            cells = f'<td colspan="{7 + len(REGIONS)}">{html.escape(r.get("note", ""))}</td>'
        body.append(f'<tr class="{r["kind"]}" data-key="{html.escape(r["key"])}"{note}>'
                    f'<td>{html.escape(r["method"])}</td><td>{html.escape(r["label"])}{star}</td>'
                    f'<td>{tms}</td><td>{bms}</td>'
                    f'<td>{_ci(r.get("total_ms"), iv.get("total_ms"), ".1f")}</td>'
                    f'{cells}<td>{flag_html}</td></tr>')
    if floor:
        body.append(f'<tr class="floor"><td colspan="5">reference noise floor '
                    f'({html.escape(floor["source"])})</td><td>{cell(floor.get("all_mae"))}</td>'
                    f'<td>{cell(floor.get("all_ssim"))}</td><td colspan="4"></td>'
                    + "".join(f'<td>{cell(floor.get(reg + "_mae"))}</td>' for reg in REGIONS[1:])
                    + "<td></td><td></td><td></td></tr>")
    return f'<table class="results">{head}{"".join(body)}</table>'


def flicker_table(entries: list[dict], floor: dict | None) -> str:
    head = ("<tr><th>method</th><th>setting</th><th>flicker</th><th>MAE (mean over frames)"
            "</th><th>ms</th><th>per-pixel random pattern</th></tr>")
    body = []
    if floor:
        body.append(f'<tr class="floor"><td colspan="2">reference flicker floor (est.)</td>'
                    f'<td>{cell(floor.get("value"))}</td><td colspan="3">'
                    f'{html.escape(floor.get("source", ""))}</td></tr>')
    for e in entries:
        noise = ", ".join(e["noise"]) if e["noise"] else "none"
        body.append(f'<tr class="{e["kind"]}" data-key="{html.escape(e["key"])}" '
                    f'data-flicker="{attr_number(e["flicker"])}">'
                    f'<td>{html.escape(e["method"])}</td>'
                    f'<td>{html.escape(e["label"])}</td><td>{cell(e["flicker"])}</td>'
                    f'<td>{cell(e["mae"])}</td><td>{cell(e["ms"], ".1f")}</td>'
                    f'<td>{html.escape(noise)}</td></tr>')
    return f'<table class="check flicker">{head}{"".join(body)}</table>'


def _pair_cells(e: dict | None, accumulated: bool) -> str:
    if e is None:
        return "<td>—</td><td>—</td><td>—</td>"
    if accumulated:
        return (f'<td>{html.escape(e["label"])}{html.escape(ACCUMULATED_SUFFIX)}</td>'
                f'<td>{cell(e["acc_ms"], ".1f")} <small>(step {cell(e["step_ms"], ".1f")})'
                f'</small></td><td>{cell(e["acc_converged"])}</td>')
    return (f'<td>{html.escape(e["label"])}</td><td>{cell(e["single_ms"], ".1f")}</td>'
            f'<td>{cell(e["single_converged"])}</td>')


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
            f'<td>{html.escape(e["label"])}</td><td>{cell(e["single_ms"], ".1f")}</td>'
            f'<td>{cell(e["acc_ms"], ".1f")}</td><td>{cell(e["single_converged"])}</td>'
            f'<td>{cell(e["acc_converged"])}</td><td>{cell(e["single_disoccluded"])}</td>'
            f'<td>{cell(e["acc_disoccluded"])}</td><td>{cell(e["single_flicker"])}</td>'
            f'<td>{cell(e["acc_flicker"])}</td></tr>' for e in entries]
    table_ = f'<table class="check accumulation">{head}{"".join(body)}</table>'
    peers = peer_sequence_entries(rows, name)
    peer_html = []
    if peers:
        head = ("<tr><th>peer</th><th>render ms per frame</th><th>converged MAE</th>"
                "<th>disoccluded MAE</th><th>flicker</th></tr>")
        body = [f'<tr data-key="{html.escape(e["key"])}"><td>{html.escape(e["label"])}</td>'
                f'<td>{cell(e["ms"], ".0f")}</td><td>{cell(e["converged"])}</td>'
                f'<td>{cell(e["disoccluded"])}</td><td>{cell(e["flicker"])}</td></tr>'
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
                    f'<td>{cell(e["ms"], ".1f")}</td><td>{_ci(e["mae"], e["interval"])}</td>'
                    + "".join(cells) + "</tr>")
    return (f'<table class="check paired">{head}{"".join(body)}</table>')


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
                    f'<td>{cell(c["limit"])} <small>{html.escape(c["limit_label"] or "")}'
                    f'</small></td><td>{cell(c["eevee"])}</td><td>{cell(c["tuned"])}</td>'
                    f'<td>{who}</td><td class="{cls}">{words[c["verdict"]]}</td>'
                    f'<td>{cell(c["larger"])} <small>{html.escape(c["larger_method"] or "")}'
                    '</small></td></tr>')
    return f'<table class="check">{head}{"".join(body)}</table>'


def tuned_table(rows: list[dict]) -> str:
    """The tuned presets (findings.tuned_rows): the error on all scenes (how each was chosen)
    and the leave-one-family-out error (the honest one)."""
    head = ("<tr><th>method</th><th>preset</th><th>ships</th><th>trial</th><th>ms</th>"
            "<th>occluded MAE, chosen on all scenes</th><th>whole-frame MAE</th>"
            "<th>held out (leave one family out)</th><th>gap</th><th>default, held out</th>"
            "<th>folds</th></tr>")
    body = []
    for r in rows:
        if "unshipped" in r:
            body.append(f'<tr><td>{html.escape(r["method"])}</td><td>{html.escape(r["preset"])}'
                        f'</td><td colspan="9">not shipped: {html.escape(r["unshipped"])}</td>'
                        '</tr>')
            continue
        body.append(f'<tr><td>{html.escape(r["method"])}</td><td>{html.escape(r["preset"])}</td>'
                    f'<td>{html.escape(r["ships"])}</td><td>{r["trial"]}</td>'
                    f'<td>{cell(r["ms"], ".1f")}</td><td>{cell(r["mae"])}</td>'
                    f'<td>{cell(r["all_mae"])}</td><td>{cell(r["held_out"])}</td>'
                    f'<td>{cell(r["gap"], "+.4f")}</td><td>{cell(r["default_held_out"])}</td>'
                    f'<td>{r["folds"]}</td></tr>')
    if not body:
        return "<p class='missing'>No tuned presets (run aolab tune: docs/tuning.md).</p>"
    return f'<table class="check">{head}{"".join(body)}</table>'


def rtao_table(ladder: list[dict], not_run: str = "") -> str:
    """The ladder against screen space; ``not_run`` (rtao_not_run) says where rtao did not
    run and why."""
    why = f"<p class='missing'>rtao not run on {html.escape(not_run)}</p>" if not_run else ""
    if not ladder:
        return why or ("<p class='missing'>No rtao rows: no scene has a mesh beside its "
                       "reference (aolab mesh), or the study ran with --rtao-rays none.</p>")
    head = ("<tr><th>rtao</th><th>ms</th><th>MAE</th><th>best screen-space within that time"
            "</th><th>ms</th><th>MAE</th><th>more accurate</th></tr>")
    body = [f'<tr><td>{html.escape(e["label"])}</td><td>{cell(e["ms"], ".1f")}</td>'
            f'<td>{cell(e["mae"])}</td><td>{html.escape(e["method"] or "—")}</td>'
            f'<td>{cell(e["method_ms"], ".1f")}</td><td>{cell(e["method_mae"])}</td>'
            f'<td>{html.escape(e["winner"] or "—")}</td></tr>' for e in ladder]
    return f'<table class="check">{head}{"".join(body)}</table>{why}'


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
            what = "bound" if e["kind"] == "limit" else "render"
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
