"""Choosing a configuration within a time budget from trials scored per scene, and judging
that choice on scene families it was not made on (leave one family out): what aolab tune
selects its presets with and what the report shows of them (docs/tuning.md).

A trial is a dict with "number", "settings", optionally "preset" (the named preset it
started as) and "scenes": scene -> {"ms", "mae", "all_mae"}: the time (at 1280x720), the
MAE on the occluded region and the MAE on the whole frame. A :class:`Guard` holds what a
choice must not be worse than on the whole frame: AO = 1 on every scene, and the method's
own default on the mean. Budgets and times are per 1280x720 frame (runner.hd_scale).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..named_presets import TUNED_PREFIX
from .runner import whole_frame_ok

#: The named preset a tuned preset must beat on held-out families.
DEFAULT_PRESET = "default"


@dataclass
class Guard:
    """The whole-frame bounds of a choice. ``ao_one``: scene -> the whole-frame MAE of
    AO = 1 (the output that draws no occlusion); a trial worse than it on any scene it is
    chosen on is out. ``default``: the method's default trial, whose mean whole-frame MAE a
    choice must not exceed (None: no such bound)."""
    ao_one: dict = field(default_factory=dict)
    default: dict | None = None


def mean(trial: dict, scenes: list[str], key: str) -> float:
    return float(np.mean([trial["scenes"][s][key] for s in scenes]))


def admits(guard: Guard, trial: dict, scenes: list[str]) -> bool:
    """Whether ``trial`` passes ``guard`` on ``scenes`` (runner.whole_frame_ok): no worse than
    AO = 1 on the whole frame of any of them, and no worse than the method's default on their
    mean whole-frame MAE."""
    d = guard.default
    bounded = d is not None and d is not trial and all(s in d["scenes"] for s in scenes)
    return whole_frame_ok({s: trial["scenes"][s].get("all_mae") for s in scenes}, guard.ao_one,
                          mean(d, scenes, "all_mae") if bounded else None)


def choose(table: list[dict], scenes: list[str], budget_ms: float,
           guard: Guard | None = None) -> dict | None:
    """The trial of ``table`` with the lowest mean occluded MAE over ``scenes`` among those
    whose mean time over them is within ``budget_ms`` and that pass ``guard`` on them: the
    Pareto-optimal admissible configuration at that budget (ties: the faster, then the
    earlier trial). None when no trial qualifies."""
    guard = guard or Guard()
    best, best_key = None, None
    for t in table:
        if not all(s in t["scenes"] for s in scenes):
            continue
        ms, mae = mean(t, scenes, "ms"), mean(t, scenes, "mae")
        if ms > budget_ms or not math.isfinite(mae) or not admits(guard, t, scenes):
            continue
        key = (mae, ms, t["number"])
        if best_key is None or key < best_key:
            best, best_key = t, key
    return best


def _scores(trial: dict, scenes: list[str]) -> dict:
    return {s: {k: trial["scenes"][s].get(k) for k in ("mae", "all_mae", "ms")} for s in scenes}


def leave_one_family_out(table: list[dict], families: dict, budget_ms: float,
                         guard: Guard | None = None) -> dict:
    """For each family (``families``: scene -> family): the trial chosen on the other
    families' scenes only (:func:`choose`, guarded on them) and its scores on the held-out
    family's scenes — {"trial", "mae", "all_mae", "ms" (means over the family), "scenes"
    (per scene), "within_budget", "train_mae", "default_mae" (the default's mean occluded
    MAE on the family)}; None when nothing qualifies on the other families."""
    guard = guard or Guard()
    out = {}
    for fam in sorted(set(families.values())):
        held = [s for s, f in families.items() if f == fam]
        train = [s for s, f in families.items() if f != fam]
        pick = choose(table, train, budget_ms, guard) if train else None
        if pick is None:
            out[fam] = None
            continue
        d = guard.default
        out[fam] = {"trial": pick["number"], "mae": mean(pick, held, "mae"),
                    "all_mae": mean(pick, held, "all_mae"), "ms": mean(pick, held, "ms"),
                    "scenes": _scores(pick, held),
                    "within_budget": mean(pick, held, "ms") <= budget_ms,
                    "train_mae": mean(pick, train, "mae"),
                    "default_mae": (mean(d, held, "mae") if d is not None and
                                    all(s in d["scenes"] for s in held) else None)}
    return out


def held_out_summary(folds: dict) -> dict:
    """Means over the folds that found a trial: the held-out occluded MAE, the training one,
    their difference (the generalisation gap) and the default's on the same families."""
    got = [f for f in folds.values() if f is not None]
    if not got:
        return {"held_out_mean_mae": None, "train_mean_mae": None, "gap": None,
                "default_held_out_mean_mae": None, "held_out_folds": 0}
    held = float(np.mean([f["mae"] for f in got]))
    train = float(np.mean([f["train_mae"] for f in got]))
    defaults = [f["default_mae"] for f in got if f["default_mae"] is not None]
    return {"held_out_mean_mae": held, "train_mean_mae": train, "gap": held - train,
            "default_held_out_mean_mae": (float(np.mean(defaults))
                                          if len(defaults) == len(got) else None),
            "held_out_folds": len(got)}


def decide(pick: dict, summary: dict, guard: Guard, scenes: list[str],
           budget_ms: float) -> tuple[dict | None, str]:
    """What ships for a budget, and why: the tuned pick when its held-out error beats the
    default's on the same families; else the default, when it fits the budget and passes
    the AO = 1 bound on every scene; else nothing."""
    held, default_held = summary["held_out_mean_mae"], summary["default_held_out_mean_mae"]
    d = guard.default
    if held is None:
        return None, "no leave-one-family-out fold found a configuration"
    if d is pick:
        return d, "default: the best admissible configuration within the budget"
    if default_held is None or held < default_held or d is None:
        return pick, "tuned"
    if (mean(d, scenes, "ms") <= budget_ms
            and admits(Guard(ao_one=guard.ao_one), d, scenes)):
        return d, "default: the tuned choice lost to it on held-out families"
    return None, ("the tuned choice lost to the default on held-out families, and the "
                  "default does not fit the budget or is worse than AO = 1 on a scene")


def select(table: list[dict], families: dict, budgets,
           guard: Guard | None = None) -> tuple[dict, dict]:
    """Per budget the preset that ships: name -> {"settings" (with "blur"), "trial",
    "ships" ("tuned", or why the default ships), "tuned_trial", "mean_ms", "mean_mae",
    "mean_all_mae" (over every scene, how it was chosen), "scenes" (its scores per scene),
    "held_out" (per family, leave one family out) and the :func:`held_out_summary`}; and
    name -> why, for each budget with nothing to ship."""
    guard = guard or Guard()
    scenes = list(families)
    out, unshipped = {}, {}
    for b in budgets:
        name = f"{TUNED_PREFIX}{b:g}ms"
        pick = choose(table, scenes, b, guard)
        if pick is None:
            unshipped[name] = "no configuration fits the budget and the whole-frame bounds"
            continue
        folds = leave_one_family_out(table, families, b, guard)
        summary = held_out_summary(folds)
        ship, why = decide(pick, summary, guard, scenes, b)
        if ship is None:
            unshipped[name] = why
            continue
        out[name] = {"settings": dict(ship["settings"]), "trial": ship["number"], "ships": why,
                     "tuned_trial": pick["number"], "mean_ms": mean(ship, scenes, "ms"),
                     "mean_mae": mean(ship, scenes, "mae"),
                     "mean_all_mae": mean(ship, scenes, "all_mae"),
                     "scenes": _scores(ship, scenes), "held_out": folds, **summary}
    return out, unshipped


def fold_scenes(key: str, fold: dict) -> dict:
    """A fold's per-scene scores: a family fold's "scenes"; a file written before families
    (one fold per scene) is its own scene."""
    return fold.get("scenes") or {key: {k: fold.get(k) for k in ("mae", "ms")}}


def best_across_methods(methods: dict, budget_ms: float) -> dict:
    """Held out across methods, from the tuned-presets JSON's ``methods``: for each scene S,
    the configuration with the lowest mean occluded MAE on the other families among every
    method's trials within ``budget_ms`` there — the method whose fold for S's family has
    the lowest ``train_mae`` — and its score on S. Scene -> {"method", "trial", "mae", "ms",
    "within_budget", "train_mae"}, or None when no method's fold found a trial. A method
    with no preset at this budget takes no part."""
    name = f"{TUNED_PREFIX}{budget_ms:g}ms"
    out: dict = {}
    for method, entry in methods.items():
        for key, fold in entry.get("selection", {}).get(name, {}).get("held_out", {}).items():
            scenes = fold_scenes(key, fold) if fold is not None else {key: None}
            for scene, got in scenes.items():
                out.setdefault(scene, None)
                if got is None:
                    continue
                best = out[scene]
                if best is None or (fold["train_mae"], method) < (best["train_mae"],
                                                                  best["method"]):
                    out[scene] = {"method": method, "trial": fold["trial"], "mae": got["mae"],
                                  "ms": got["ms"], "within_budget": got["ms"] <= budget_ms,
                                  "train_mae": fold["train_mae"]}
    return out
