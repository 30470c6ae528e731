"""The findings of a comparison study: what results.json says, as data, for the two views that
draw it (report.py's report.html and results_doc.py's docs/results.md) and for the commands
that choose by it (compare, advise).

Nothing here writes HTML or Markdown: each function reads results.json's rows (or a scene's
rows) and returns numbers, rows and verdicts. The Pareto front, the error split, the paired
comparisons, the defaults worse than AO = 1, the check against EEVEE, the tuned presets, rtao's
ladder, a sequence's flicker and accumulation; ``study_findings`` gathers those over all scenes,
once, for both views. ``cell`` and ``with_interval`` are the one text of a number and of a mean
with its interval that both views show.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import aolab

from ..regions import REGIONS
from . import budget, stats
from .runner import still_scenes, whole_frame_ok

#: A configuration is flagged "weak" when its MAE on the occluded region exceeds this fraction
#: of the "AO = 1" baseline's there (it removes less than a quarter of the baseline's error).
WEAK_FRACTION = 0.75


#: Kinds whose time is comparable with the methods' and that may lie on the Pareto front.
FRONT_KINDS = ("method", "cycles", "rtao")


#: The configurations of each method in the error-split chart: the paper's defaults, the tuned
#: preset of the budget the study checks against EEVEE, and the largest budget's.
SPLIT_LABELS = ("default", "tuned-100ms", "tuned-500ms")


#: The budget of the check against EEVEE (docs/results.md): the best tuned configuration within
#: 100 ms a frame, scored on a scene it was not chosen on; and the largest tuned budget, shown
#: beside it to tell what time alone would buy.
EEVEE_CHECK_BUDGET_MS = 100
LARGEST_TUNED_BUDGET_MS = 500


#: The scene name of the means over the scenes (compare.AGGREGATE_SCENE).
AGGREGATE = "ALL"


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


def cell(v, fmt: str = ".4f") -> str:
    """A number as both views' tables show it: formatted with ``fmt``, or "—" when it is
    missing or not finite."""
    v = number(v)
    if v is None:
        return "—"
    return format(v, fmt)


def interval_text(iv, fmt: str = ".4f") -> str:
    """A 95 % interval (lo, hi) as the views show it: "[lo, hi]"."""
    return f"[{iv[0]:{fmt}}, {iv[1]:{fmt}}]"


def with_interval(value, iv, fmt: str = ".4f") -> str:
    """A mean (cell) and, when it has one, its 95 % interval over the scenes after it."""
    return cell(value, fmt) + (" " + interval_text(iv, fmt) if iv else "")


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


_KIND_ORDER = {"baseline": 0, "method": 1, "cycles": 2, "rtao": 3, "noise_floor": 4,
               "eevee": 5, "limit": 6}


def row_order(r: dict):
    """Baseline, then methods by name and time, then peers by time (the Cycles ladder by spp)."""
    t = number(r.get("total_ms")) or 0.0
    if r["kind"] == "method":
        return (_KIND_ORDER["method"], r["method"], t, r["label"])
    return (_KIND_ORDER.get(r["kind"], 9), "", t, r["method"])


def best_limit(rows: list[dict]) -> dict | None:
    """The screen-space limit row (kind "limit") with the lowest occluded MAE, or None."""
    limits = [r for r in rows if r["kind"] == "limit" and metric(r, "occluded_mae") is not None]
    return min(limits, key=lambda r: metric(r, "occluded_mae")) if limits else None


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


def interval(row: dict, column: str) -> tuple[float, float] | None:
    """A row's 95 % interval over the scenes of ``column`` (results.json's "intervals": the
    ALL rows have them for the whole-frame and occluded MAE and the time), when finite."""
    iv = (row.get("intervals") or {}).get(column)
    if not iv or number(iv[0]) is None or number(iv[1]) is None:
        return None
    return float(iv[0]), float(iv[1])


@dataclass
class StudyFindings:
    """The findings over all scenes that report.html and docs/results.md both show, computed
    once (study_findings): the error split of the ALL rows, the paired comparisons within the
    study's budget, the defaults worse than AO = 1, the tuned presets, the check against
    EEVEE and its releases, and rtao's ladder (over all scenes and per scene)."""
    agg: list
    has_limits: bool
    split: list
    budget_ms: float
    paired: list
    worse: list
    n_stills: int
    tuned: dict | None
    tuned_rows: list
    eevee: list
    eevee_releases: list
    rtao_ladder: list
    rtao_crossover: float | None
    rtao_not_run: str
    rtao_scenes: list     # (scene, its ladder, its crossover) for each scene with rtao rows
    rtao_builds: dict     # scene -> its BVH build (results.json's scenes.<name>.rtao)


def study_findings(results: dict, agg: list[dict]) -> StudyFindings:
    """The StudyFindings of ``results`` (results.json), ``agg`` its ALL rows."""
    budget = results["meta"].get("budget_ms", 0)
    ladder = rtao_ladder(agg)
    per_scene_ladders = []
    for name in results["meta"].get("scenes", []):
        lad = rtao_ladder([r for r in results["rows"] if r["scene"] == name])
        if lad:
            per_scene_ladders.append((name, lad, rtao_crossover(lad)))
    return StudyFindings(
        agg=agg, has_limits=any(r["kind"] == "limit" for r in results["rows"]),
        split=error_split(agg, results.get("scenes", {})), budget_ms=budget,
        paired=paired_comparisons(results, budget), worse=worse_than_nothing(results),
        n_stills=len(still_scenes(results.get("scenes", {}))), tuned=results.get("tuned"),
        tuned_rows=tuned_rows(results.get("tuned") or {}), eevee=eevee_check(results),
        eevee_releases=eevee_releases(results), rtao_ladder=ladder,
        rtao_crossover=rtao_crossover(ladder), rtao_not_run=rtao_not_run(results),
        rtao_scenes=per_scene_ladders,
        rtao_builds={name: info["rtao"] for name, info in results.get("scenes", {}).items()
                     if info.get("rtao")})
