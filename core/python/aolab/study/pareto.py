"""Choosing a configuration within a time budget from trials scored per scene, and judging
that choice on scenes it was not made on (leave one scene out): what aolab tune selects its
presets with and what the report shows of them. A trial is a dict with "number",
"settings" and "scenes": scene -> {"ms", "mae"}."""

from __future__ import annotations

import math

import numpy as np

from ..named_presets import TUNED_PREFIX


def _mean(trial: dict, scenes: list[str], key: str) -> float:
    return float(np.mean([trial["scenes"][s][key] for s in scenes]))


def choose(table: list[dict], scenes: list[str], budget_ms: float) -> dict | None:
    """The trial of ``table`` (dicts with "number" and "scenes": scene -> {"ms", "mae"}) with
    the lowest mean MAE over ``scenes`` among those whose mean time over them is within
    ``budget_ms``: the Pareto-optimal configuration at that budget (ties: the faster, then
    the earlier trial). None when no trial fits."""
    best, best_key = None, None
    for t in table:
        if not all(s in t["scenes"] for s in scenes):
            continue
        ms, mae = _mean(t, scenes, "ms"), _mean(t, scenes, "mae")
        if ms > budget_ms or not math.isfinite(mae):
            continue
        key = (mae, ms, t["number"])
        if best_key is None or key < best_key:
            best, best_key = t, key
    return best


def leave_one_scene_out(table: list[dict], scenes: list[str], budget_ms: float) -> dict:
    """For each scene: the trial chosen on the other scenes only (:func:`choose`) and its
    score on the held-out scene — {"trial", "mae", "ms", "within_budget", "train_mae",
    "train_ms"}, or None when nothing fits the budget on the other scenes (or there are
    none)."""
    out = {}
    for held in scenes:
        train = [s for s in scenes if s != held]
        pick = choose(table, train, budget_ms) if train else None
        if pick is None:
            out[held] = None
            continue
        got = pick["scenes"][held]
        out[held] = {"trial": pick["number"], "mae": got["mae"], "ms": got["ms"],
                     "within_budget": got["ms"] <= budget_ms,
                     "train_mae": _mean(pick, train, "mae"),
                     "train_ms": _mean(pick, train, "ms")}
    return out


def select(table: list[dict], scenes: list[str], budgets) -> dict:
    """Per budget the tuned preset: name -> {"settings" (with "blur"), "trial", "mean_ms",
    "mean_mae" (over all scenes: how it was chosen), "held_out" (per scene, LOSO) and
    "held_out_mean_mae" (mean over the scenes whose fold found a trial)}. A budget no trial
    meets on the mean over all scenes is absent."""
    out = {}
    for b in budgets:
        pick = choose(table, scenes, b)
        if pick is None:
            continue
        held = leave_one_scene_out(table, scenes, b)
        got = [h["mae"] for h in held.values() if h is not None]
        out[f"{TUNED_PREFIX}{b:g}ms"] = {
            "settings": dict(pick["settings"]), "trial": pick["number"],
            "mean_ms": _mean(pick, scenes, "ms"), "mean_mae": _mean(pick, scenes, "mae"),
            "held_out": held,
            "held_out_mean_mae": float(np.mean(got)) if got else None,
            "held_out_folds": len(got)}
    return out


def best_across_methods(methods: dict, budget_ms: float) -> dict:
    """Leave one scene out across methods, from the tuned-presets JSON's ``methods``: for each
    held-out scene S, the configuration with the lowest mean MAE on the other scenes among
    every method's trials within ``budget_ms`` there — which is the method whose fold-S
    choice (``selection[...]["held_out"][S]``) has the lowest ``train_mae`` — and its score
    on S. Scene -> {"method", "trial", "mae", "ms", "within_budget", "train_mae"}, or None
    when no method's fold found a trial. A method with no preset at this budget (none of its
    trials fits it on all scenes) takes no part."""
    name = f"{TUNED_PREFIX}{budget_ms:g}ms"
    out: dict = {}
    for method, entry in methods.items():
        for scene, fold in entry.get("selection", {}).get(name, {}).get("held_out", {}).items():
            out.setdefault(scene, None)
            if fold is None:
                continue
            best = out[scene]
            if best is None or (fold["train_mae"], method) < (best["train_mae"], best["method"]):
                out[scene] = {"method": method, **fold}
    return out
