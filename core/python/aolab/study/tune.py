"""``aolab tune``: each method's settings searched for the Pareto front of occluded-region MAE
against time, with Optuna's multi-objective samplers; tuned presets per time budget, guarded
on the whole frame, chosen on the corpus and validated leaving one family out
(docs/tuning.md).

    aolab tune [--methods M ...] [--trials N] [--scenes S ...] [--out DIR] [--seed N]
               [--timeout S] [--sampler tpe|nsga2] [--crop WxH] [--presets-file PATH]
               [--workers N | --scheduler ADDRESS]

One trial = one configuration of one method (its searched settings and the shared blur), run
on every still scene at the scene's R, timed and scored by the study's runner, which runs
``aolab compare``'s configurations too (runner.evaluate: ``--warmup`` untimed run, median of
``--repeat``; the blur timed apart and added; scaled to a 1280x720 frame), by its MAE on the
occluded region (reference AO < 0.9, aolab.regions) and on the whole frame. Its two
objectives are the means over the scenes of the occluded MAE and of the time; the
whole-frame MAE is a constraint (budget.Guard). Trials are stored in SQLite (DIR/tune.db,
one Optuna study per method): Ctrl-C keeps every finished trial and the same command
resumes. With a cluster the trials' accuracy is computed on its workers and their times
here.

For each budget B of BUDGETS_MS, ``budget.select`` makes the preset ``tuned-<B>ms``: the
guarded trial with the lowest mean occluded MAE within B over all scenes, its leave-one-
family-out score and generalisation gap, and the method's default in its place where the
tuned choice loses to the default on held-out families.
"""

from __future__ import annotations

import json
import os
import shlex
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import aolab

from .. import catalog
from .. import named_presets as presets_mod
from ..catalog.kinds import SHARED_BOUNDS, Param, choice_bound, float_bound, int_bound
from ..scenes import Scene, family, find_scenes_dir, frame_numbers, resolve_scenes, scene_files
from ..settings import described
from ..util import dask_cluster, files
from ..util.files import check_paths
from ..util.provenance import git_commit, machine_info
from ..util.dask_cluster import ClusterSecurity, connect, wait_all
from . import budget
from ..util.progress import bar as progress_bar
from .runner import Timing, evaluate, load_scene, score_remotely, trial_scores

#: The time budgets of the tuned presets, ms per 1280x720 frame (method + blur: runner.hd_scale).
BUDGETS_MS = (50, 100, 200, 500)
# 60 trials per method: the TPE sampler's 10 random start-up trials, the presets, then ~45
# guided ones. The whole default run (seven methods) then fits about an hour on 2 cores
# (docs/tuning.md, "How long it takes"); --trials extends a study later without losing any.
DEFAULT_TRIALS = 60
# Twice the largest budget: a configuration whose first run is slower than that cannot be
# within any budget even if the first run was the slow one, so it is timed by that run alone.
DEFAULT_MAX_MS = 2.0 * BUDGETS_MS[-1]
#: The SQLite file of the studies in --out, and each method's study name.
DB_NAME = "tune.db"
STUDY_PREFIX = "aolab-tune-"
#: The committed tuned presets, relative to the checkout (named_presets.TUNED_FILE).
PACKAGE_PRESETS = Path("core/python/aolab") / presets_mod.TUNED_FILE


# ----------------------------------------------------------------------------------------
# The search space


#: Settings never searched, for every method, and why.
NOT_SEARCHED = {
    "radius": "the scene's R (the reference's AO distance), not a quality choice",
    "seed": "kept at its default: every trial draws the same per-pixel randomness",
}

#: A bound for a setting in no table: ints spanning at most this many values.
SMALL_INT_SPAN = 64
#: The shared blur, searched for every method: presets.BLUR_SIGMA / BLUR_TAPS, timed apart.
BLUR_PARAM = "blur"


@dataclass
class Space:
    """The search space of one method: searched params (parents first), the settings kept
    fixed (name -> value), the constraint rules of its catalog entry, and why each setting is
    searched as it is or not searched."""
    method: str
    params: list
    fixed: dict
    rules: tuple
    notes: dict
    defaults: dict
    builtin_blur: str | None = None


def _generic(s: dict) -> Param | None:
    if s["type"] == "bool":
        return choice_bound((False, True), "false or true")
    if s["type"] == "choice":
        return choice_bound(s["choices"], "every choice")
    lo, hi = s.get("min"), s.get("max")
    if s["type"] == "int" and lo is not None and hi is not None and hi - lo <= SMALL_INT_SPAN:
        return int_bound(int(lo), int(hi), "the setting's own range")
    if s["type"] == "float" and lo is not None and hi is not None and hi - lo <= 1:
        return float_bound(float(lo), float(hi), "the setting's own range")
    return None


def search_space(method: str) -> Space:
    """The search space of ``method`` from its description and its catalog entry's
    tune_bounds and tune_fixed (aolab.catalog)."""
    entry = catalog.entry(method)
    fixed_table = dict(entry.tune_fixed) if entry is not None else {}
    if entry is not None and entry.builtin_blur:
        fixed_table[entry.builtin_blur] = (False, "the method's own Gaussian is the shared "
                                           "blur, searched as `blur` and timed apart")
    bounds = {**SHARED_BOUNDS, **(entry.tune_bounds if entry is not None else {})}
    params, fixed, notes, defaults = [], {}, {}, {}
    for s in described(method, shared=True):
        name = s["name"]
        defaults[name] = s["default"]
        if name in NOT_SEARCHED:
            notes[name] = "not searched: " + NOT_SEARCHED[name]
        elif name in fixed_table:
            value, why = fixed_table[name]
            if value is not None:
                fixed[name] = value
            notes[name] = f"not searched ({'default' if value is None else value}): {why}"
        else:
            p = bounds.get(name) or _generic(s)
            if p is None:
                notes[name] = (f"not searched (default): its range [{s['min']:g}, "
                               f"{s['max']:g}] has no bound in its catalog entry (tune_bounds)")
                continue
            params.append(Param(name, p.kind, p.low, p.high, p.log, p.step, p.choices,
                                p.when, p.why))
            notes[name] = _describe(params[-1])
    params.append(Param(BLUR_PARAM, "set", choices=(False, True),
                        why=f"the shared Gaussian (sigma {presets_mod.BLUR_SIGMA}, "
                        f"{presets_mod.BLUR_TAPS} taps), timed apart and added"))
    notes[BLUR_PARAM] = _describe(params[-1])
    params.sort(key=lambda p: p.when is not None)   # parents before conditional settings
    rules = entry.constraints if entry is not None else ()
    return Space(method, params, fixed, rules, notes, defaults,
                 entry.builtin_blur if entry is not None else None)


def _describe(p: Param) -> str:
    if p.kind == "set":
        values = ", ".join(str(c) for c in p.choices)
        text = f"one of {values}"
    else:
        text = f"{p.kind} [{p.low:g}, {p.high:g}]" + (" log" if p.log else "") + \
            (f" step {p.step}" if p.step != 1 else "")
    return text + (" (conditional)" if p.when is not None else "") + f": {p.why}"


def suggest(trial, space: Space) -> tuple[dict, bool]:
    """The settings and blur switch of a trial: each active param suggested, the fixed ones
    set, the catalog entry's constraint rules applied (a rule refusing the point: ValueError)."""
    values = dict(space.defaults)
    chosen = {}
    for p in space.params:
        if p.when is not None and not p.when(values):
            continue
        if p.kind == "int":
            v = trial.suggest_int(p.name, int(p.low), int(p.high), step=p.step, log=p.log)
        elif p.kind == "float":
            v = trial.suggest_float(p.name, p.low, p.high, log=p.log)
        else:
            v = trial.suggest_categorical(p.name, list(p.choices))
        values[p.name] = chosen[p.name] = v
    blur = bool(chosen.pop(BLUR_PARAM))
    chosen.update(space.fixed)
    # The entry's rules read whole points: give them every setting (defaults for those not
    # chosen) and keep what was chosen and what a rule changed.
    full = {**space.defaults, **chosen}
    for rule in space.rules:
        full = rule(full)
        if full is None:
            raise ValueError(f"{space.method}: the point is refused by {rule.__name__}")
    return {k: v for k, v in full.items() if k in chosen or v != space.defaults[k]}, blur


def preset_params(space: Space, values: dict) -> dict | None:
    """A named preset (settings + "blur") as the trial params that reproduce it, or None when
    one of its values lies outside the bounds (it is then not enqueued)."""
    values = dict(values)
    if space.builtin_blur and values.get(space.builtin_blur, space.defaults.get(
            space.builtin_blur)):
        values[BLUR_PARAM] = True           # the builtin Gaussian is the shared blur
    full = {**space.defaults, **values}
    params = {}
    for p in space.params:
        if p.when is not None and not p.when(full):
            continue
        v = full.get(p.name, False)
        if p.kind == "set":
            if v not in p.choices:
                return None
        elif not (p.low <= v <= p.high) or (p.kind == "int" and (v - p.low) % p.step):
            return None
        params[p.name] = v
    return params


# ----------------------------------------------------------------------------------------
# Evaluating one configuration


def load_scenes(folders: list[Path], crop, follow_symlinks: bool = False) -> list[Scene]:
    """The scenes of a run as ``aolab compare`` loads them (runner.load_scene), each with its
    family; a crop's times stay the crop's."""
    out = []
    for folder in folders:
        scene = load_scene(folder, crop, follow_symlinks=follow_symlinks)
        scene.family = family(folder)
        out.append(scene)
    return out


# ----------------------------------------------------------------------------------------
# The studies


@dataclass
class Options:
    methods: list[str] | None = None
    trials: int = DEFAULT_TRIALS
    scenes: list[str] = field(default_factory=list)
    out: Path = Path("out/tune")
    seed: int = 0
    timeout: float | None = None
    sampler: str = "tpe"
    crop: object = None
    scenes_dir: Path | None = None
    presets_file: Path | None = None
    timing: Timing = field(default_factory=lambda: Timing(max_ms=DEFAULT_MAX_MS))
    progress: bool = True
    #: Score trials on a Dask cluster: a local one of this many workers, or the scheduler's.
    workers: int = 1
    scheduler: str | None = None
    #: How to meet a remote scheduler (TLS files, or consent to plain tcp on the network).
    security: ClusterSecurity | None = None
    #: Read a scene's files through symbolic links (scenes.check_confined); refused without.
    follow_symlinks: bool = False


def default_methods() -> list[str]:
    """Every method but the bounds (method_info's "bound": True)."""
    return [m for m in aolab.methods() if not aolab.method_info(m)["bound"]]


def trial_constraints(trial) -> list[float]:
    """The whole-frame constraints of a finished trial (:func:`constraints`), for the
    sampler: it then prefers configurations no worse than AO = 1 and the default."""
    return trial.user_attrs.get("constraints", [0.0, 0.0])


def _sampler(name: str, seed: int):
    import optuna
    if name == "nsga2":
        return optuna.samplers.NSGAIISampler(seed=seed, constraints_func=trial_constraints)
    return optuna.samplers.TPESampler(seed=seed, constraints_func=trial_constraints)


def _protocol(opts: Options, scenes: list[Scene]) -> dict:
    """What makes two trials comparable: a study keeps to one protocol."""
    return {"scenes": [s.name for s in scenes], "families": [s.family for s in scenes],
            "time": "ms per 1280x720 frame", "objective": "occluded MAE, whole frame guarded",
            "size": [[int(s.g.width), int(s.g.height)] for s in scenes],
            "warmup": opts.timing.warmup, "repeat": opts.timing.repeat,
            "threads": opts.timing.threads, "max_ms": opts.timing.max_ms}


def open_study(opts: Options, method: str, scenes: list[Scene]):
    """The method's study in opts.out/tune.db, created or loaded (its protocol must match);
    trials left RUNNING by a killed run are marked FAIL."""
    import optuna
    opts.out.mkdir(parents=True, exist_ok=True)
    storage = optuna.storages.RDBStorage(f"sqlite:///{(opts.out / DB_NAME).resolve()}")
    study = optuna.create_study(storage=storage, study_name=STUDY_PREFIX + method,
                                directions=["minimize", "minimize"], load_if_exists=True,
                                sampler=_sampler(opts.sampler, opts.seed))
    protocol = _protocol(opts, scenes)
    known = study.user_attrs.get("protocol")
    if known is None:
        study.set_user_attr("protocol", protocol)
        study.set_user_attr("method", method)
    elif known != protocol:
        raise ValueError(f"the study of {method} in {opts.out / DB_NAME} was made with "
                         f"{json.dumps(known)}, this run asks for {json.dumps(protocol)}; use "
                         "another --out, or the same scenes, crop and timing options")
    fail_running(study)
    # The sampler's seed moves on with the trials done, so that a resumed run does not draw
    # the same random start again.
    study.sampler = _sampler(opts.sampler, opts.seed + len(study.trials))
    return study


def counted(study) -> int:
    """Trials that count towards --trials: complete ones and those the method refused."""
    from optuna.trial import TrialState
    return sum(1 for t in study.get_trials(deepcopy=False)
               if t.state == TrialState.COMPLETE or
               (t.state == TrialState.FAIL and "error" in t.user_attrs))


def enqueue_presets(study, space: Space) -> int:
    """A new study starts from the method's named presets (those inside the bounds)."""
    n = 0
    for name, values in presets_mod.named(space.method).items():
        params = preset_params(space, values)
        if params is not None:
            study.enqueue_trial(params, user_attrs={"preset": name}, skip_if_exists=True)
            n += 1
    return n


def _key(settings: dict, blur: bool) -> str:
    return json.dumps({**settings, BLUR_PARAM: blur}, sort_keys=True)


def table(study) -> list[dict]:
    """The complete trials as dicts for budget.select."""
    from optuna.trial import TrialState
    return [{"number": t.number, "settings": t.user_attrs["settings"],
             "preset": t.user_attrs.get("preset"), "scenes": t.user_attrs["scenes"]}
            for t in study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))]


def guard(rows: list[dict], scenes: list[Scene]) -> budget.Guard:
    """What a choice must not be worse than on the whole frame: AO = 1 on each scene, and the
    method's default trial (the enqueued preset "default") on the mean."""
    default = next((t for t in rows if t.get("preset") == budget.DEFAULT_PRESET), None)
    return budget.Guard(ao_one={s.name: s.ao_one_mae for s in scenes}, default=default)


def run_method(opts: Options, method: str, scenes: list[Scene], bar, deadline,
               client=None) -> dict:
    """Trials of ``method`` until the study has opts.trials of them (or the deadline); the
    selection from every complete trial of the study."""
    from optuna.trial import TrialState
    space = search_space(method)
    study = open_study(opts, method, scenes)
    if not study.trials:
        enqueue_presets(study, space)
    if bar is not None:
        bar.update(min(counted(study), opts.trials))
    done = {t.user_attrs["key"]: t for t in
            study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))}
    try:
        _trials(opts, method, scenes, bar, deadline, study, space, done, client)
    except BaseException:   # Ctrl-C: the finished trials are kept, none is left running
        fail_running(study)
        raise
    rows = table(study)
    families = {s.name: s.family for s in scenes}
    selection, unshipped = budget.select(rows, families, BUDGETS_MS, guard(rows, scenes))
    return {"study": study, "space": space, "done": counted(study) >= opts.trials,
            "selection": selection, "unshipped": unshipped}


# Ctrl-C and `kill` only ask to stop: a KeyboardInterrupt raised inside an Optuna or SQLite
# call could leave the store half-written, so the trial loop stops at its next safe point
# (before a trial, between scenes). A second Ctrl-C stops at once.
_STOP = threading.Event()


def _ask_to_stop(signum, frame) -> None:
    if _STOP.is_set():
        raise KeyboardInterrupt
    _STOP.set()


def _stop_if_asked() -> None:
    if _STOP.is_set():
        raise KeyboardInterrupt


def fail_running(study) -> None:
    """Marks the study's RUNNING trials failed: one process runs a study at a time, so they
    are an interrupted trial of this run, or of a run that was killed."""
    from optuna.trial import TrialState
    for t in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        study._storage.set_trial_user_attr(t._trial_id, "interrupted", True)
        study._storage.set_trial_state_values(t._trial_id, TrialState.FAIL)


@dataclass
class Asked:
    """A trial asked of the sampler, its configuration and, if the same configuration was
    scored before, that trial (the methods are deterministic: it is reused)."""
    trial: object
    settings: dict
    blur: bool
    key: str
    same: object = None


def constraints(per_scene: dict, scenes: list[Scene], default_all_mae: float | None):
    """The sampler's constraints (feasible when <= 0): the largest excess of the whole-frame
    MAE over AO = 1's on any scene, and the excess of the mean whole-frame MAE over the
    default's (0 until the default is scored)."""
    worst = max(per_scene[s.name]["all_mae"] - s.ao_one_mae for s in scenes)
    mean_all = float(np.mean([per_scene[s.name]["all_mae"] for s in scenes]))
    return [worst, 0.0 if default_all_mae is None else mean_all - default_all_mae]


def _ask(study, space, done, n: int) -> list[Asked]:
    """n trials of the sampler (1 without a cluster, a batch for its workers)."""
    out = []
    for _ in range(n):
        trial = study.ask()
        try:
            settings, blur = suggest(trial, space)
        except ValueError as e:
            trial.set_user_attr("error", str(e))
            study.tell(trial, state=_fail())
            continue
        key = _key(settings, blur)
        trial.set_user_attr("settings", {**settings, BLUR_PARAM: blur})
        trial.set_user_attr("key", key)
        out.append(Asked(trial, settings, blur, key, done.get(key)))
    return out


def _fail():
    from optuna.trial import TrialState
    return TrialState.FAIL


def _trials(opts, method, scenes, bar, deadline, study, space, done, client=None) -> None:
    """The trial loop of run_method: without a cluster one trial at a time, scored as it is
    timed; with one, a batch of trials (one per worker thread) scored on the workers, then
    timed here one after another while the workers are idle."""
    def next_scene(name):  # between scenes: a safe point to stop, no storage call in flight
        _stop_if_asked()
        if bar is not None:
            bar.set_description(f"{method} {name}")

    default_all = [None]
    while counted(study) < opts.trials:
        _stop_if_asked()
        if deadline is not None and time.monotonic() >= deadline:
            break
        n = 1 if client is None else max(1, min(dask_cluster.threads(client),
                                                opts.trials - counted(study)))
        batch = _ask(study, space, done, n)
        fresh = [a for a in batch if a.same is None]
        remote = score_on_cluster(client, fresh, scenes, method, opts.crop,
                                  opts.follow_symlinks) if client else {}
        for a in batch:
            _finish(a, method, scenes, opts, study, done, remote.get(a.trial.number),
                    next_scene, default_all)
            if bar is not None:
                bar.update(1)


def _finish(a: Asked, method, scenes, opts, study, done, remote, next_scene,
            default_all) -> None:
    """Times one asked trial (its scores from ``remote`` when the cluster computed them) and
    tells the sampler; a configuration the method refuses fails, not fatally."""
    same = done.get(a.key) if a.same is None else a.same
    try:
        if same is not None:   # deterministic: reuse, do not recompute
            a.trial.set_user_attr("scenes", same.user_attrs["scenes"])
            a.trial.set_user_attr("same_as", same.number)
            a.trial.set_user_attr("constraints", same.user_attrs.get("constraints", [0.0, 0.0]))
            study.tell(a.trial, list(same.values))
            return
        if isinstance(remote, Exception):
            raise remote
        per_scene = evaluate(method, a.settings, a.blur, scenes, opts.timing,
                             on_scene=next_scene, remote=remote)
        if a.trial.user_attrs.get("preset") == budget.DEFAULT_PRESET:
            default_all[0] = float(np.mean([r["all_mae"] for r in per_scene.values()]))
        a.trial.set_user_attr("scenes", per_scene)
        a.trial.set_user_attr("constraints", constraints(per_scene, scenes, default_all[0]))
        study.tell(a.trial, [float(np.mean([r["mae"] for r in per_scene.values()])),
                             float(np.mean([r["ms"] for r in per_scene.values()]))])
        done[a.key] = study.get_trials(deepcopy=False)[a.trial.number]
    except ValueError as e:     # a configuration the method refuses: failed, not fatal
        a.trial.set_user_attr("error", str(e))
        study.tell(a.trial, state=_fail())


def score_on_cluster(client, batch: list[Asked], scenes: list[Scene], method: str,
                     crop, follow_symlinks: bool = False) -> dict:
    """Trial number -> scene -> runner.score_remotely's result (one task per trial and
    scene), or the ValueError of a configuration the method refused. A worker lost mid-task
    loses nothing: the scheduler gives its tasks to another worker. Ctrl-C cancels the tasks
    not yet done."""
    futures = {(a.trial.number, sc.name): client.submit(
        score_remotely, str(sc.folder), crop, None, method, a.settings, [a.blur],
        trial_scores, None, follow_symlinks, pure=False)
        for a in batch for sc in scenes}
    wait_all(client, list(futures.values()), _stop_if_asked)
    out: dict = {}
    for (number, scene), f in futures.items():
        got = f.result()
        if "error" in got:
            if not got["refused"]:
                raise RuntimeError(got["error"])
            out[number] = ValueError(got["error"])
        elif not isinstance(out.get(number), Exception):
            out.setdefault(number, {})[scene] = got
    return out


# ----------------------------------------------------------------------------------------
# Output


def _shown(path: Path) -> str:
    """``path`` relative to the current folder when it lies inside it (the presets file is
    committed: it names no folder of the machine it was made on)."""
    try:
        return str(Path(path).resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def command_line(opts: Options) -> str:
    """The command that reproduces this run (its options spelled out)."""
    parts = ["aolab", "tune", "--methods", *(opts.methods or default_methods()),
             "--trials", str(opts.trials), "--seed", str(opts.seed),
             "--sampler", opts.sampler, "--out", _shown(opts.out)]
    if opts.scenes:
        parts += ["--scenes", *opts.scenes]
    if opts.crop is not None:
        parts += ["--crop", f"{opts.crop.width}x{opts.crop.height}"]
    if opts.timeout is not None:
        parts += ["--timeout", f"{opts.timeout:g}"]
    t = opts.timing
    if (t.warmup, t.repeat, t.threads, t.max_ms) != (1, 3, 0, DEFAULT_MAX_MS):
        parts += ["--warmup", str(t.warmup), "--repeat", str(t.repeat), "--threads",
                  str(t.threads), "--max-ms", f"{t.max_ms:g}"]
    return " ".join(shlex.quote(p) for p in parts)


def method_entry(opts: Options, result: dict, scenes: list[Scene], meta: dict) -> dict:
    """The tuned-presets JSON entry of one method."""
    study, space, sel = result["study"], result["space"], result["selection"]
    from optuna.trial import TrialState
    states = [t.state for t in study.get_trials(deepcopy=False)]
    return {
        **meta,
        "trials": {"complete": states.count(TrialState.COMPLETE),
                   "failed": states.count(TrialState.FAIL),
                   "study": study.study_name, "storage": _shown(opts.out / DB_NAME)},
        "search_space": space.notes,
        "presets": {name: s["settings"] for name, s in sel.items()},
        "selection": {name: {k: v for k, v in s.items() if k != "settings"}
                      for name, s in sel.items()},
        "unshipped": result["unshipped"],
        "whole_frame_guard": {"ao_one_mae": {s.name: s.ao_one_mae for s in scenes}},
    }


def write_presets(path: Path, entries: dict) -> None:
    """Merges the methods' entries into the tuned-presets JSON at ``path`` (others kept)."""
    data = {}
    if path.exists():
        data = json.loads(path.read_text())
    data["about"] = ("Tuned presets of `aolab tune` (docs/tuning.md): per method and time "
                     "budget (ms per 1280x720 frame), the configuration with the lowest mean "
                     "occluded-region MAE within the budget over all scenes whose whole-frame "
                     "MAE is no worse than AO = 1 on any scene nor than the default on the "
                     "mean; `selection` gives its leave-one-family-out scores and says whether "
                     "the tuned choice or the default ships; `unshipped` names the budgets "
                     "with neither. Loaded by aolab.presets.")
    data.setdefault("methods", {}).update(entries)
    data["methods"] = dict(sorted(data["methods"].items()))
    path.parent.mkdir(parents=True, exist_ok=True)
    files.write_text(path, json.dumps(data, indent=1, sort_keys=False) + "\n")


def summary(method: str, sel: dict, unshipped: dict, n_trials: int) -> str:
    lines = [f"{method}: {n_trials} complete trials"]
    for name, s in sel.items():
        held = s["held_out_mean_mae"]
        held_text = (f"{held:.4f} (gap {s['gap']:+.4f}, {s['held_out_folds']} families)"
                     if held is not None else "-")
        text = ", ".join(f"{k}={v}" for k, v in s["settings"].items())
        lines.append(f"  {name:<13} {s['mean_ms']:7.1f} ms  occluded MAE {s['mean_mae']:.4f}  "
                     f"whole frame {s['mean_all_mae']:.4f}  held out {held_text}  "
                     f"ships {s['ships']}: trial {s['trial']}: {text}")
    for name, why in unshipped.items():
        lines.append(f"  {name:<13} not shipped: {why}")
    return "\n".join(lines)


def _git_date() -> str:
    return time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())


#: The first bytes of every SQLite database file.
SQLITE_MAGIC = b"SQLite format 3\x00"


def check_store(out: Path) -> Path:
    """The trial store out/tune.db, checked before any trial: --out a folder (or one that can
    be made), and tune.db absent or a regular file that is an SQLite database. A FIFO would
    have been opened (SQLite said "disk I/O error") and a stray file read as a database
    (SQLAlchemy's "file is not a database" and a web link), neither naming the file."""
    check_paths(folders={"--out": out})
    db = out / DB_NAME
    if os.path.lexists(db):
        files.regular_file(db, "the trial store")
        with open(db, "rb") as f:
            head = f.read(len(SQLITE_MAGIC))
        if head and head != SQLITE_MAGIC:   # an empty file is an empty database to SQLite
            raise ValueError(f"the trial store {db} is not an SQLite database (aolab tune keeps "
                             "its trials there): move it away or choose another --out")
    return db


def store_error(db: Path, e: BaseException) -> str:
    """One line for an error of the trial store (Optuna's storage, SQLAlchemy, SQLite): the
    file and SQLite's own reason, without SQLAlchemy's SQL and web link."""
    cause = e.__cause__ if e.__cause__ is not None else e
    reason = str(getattr(cause, "orig", None) or cause).strip().splitlines()
    return (f"the trial store {db} cannot be used: {reason[0] if reason else type(e).__name__}"
            " (move it away or choose another --out)")


def check_presets_file(path: Path) -> None:
    """The tuned-presets file the run will update, before any trial: an existing one must be
    a regular file that can be replaced and hold what aolab tune writes (named_presets.read_tuned),
    a new one a folder it can go in. A folder or a malformed file was refused only when the
    first method's presets were written, after its trials."""
    if os.path.lexists(path):
        check_paths(edited={"--presets-file": path})
        presets_mod.read_tuned(path)
    else:
        check_paths(folders={"--presets-file": path.parent})


def default_presets_file(folders: list[Path], scenes_dir: Path | None, opts: Options) -> Path:
    """The checkout's committed tuned presets for a run on every scene of the checkout at
    full size; DIR/tuned_presets.json for any other run (a crop, some scenes), so that a
    quick look never replaces the committed presets."""
    if scenes_dir is not None and opts.crop is None:
        checkout = Path(scenes_dir).resolve().parent
        every = [f.resolve() for f in tuning_folders([], scenes_dir)]
        if [f.resolve() for f in folders] == every and \
                (checkout / PACKAGE_PRESETS).parent.is_dir():
            return checkout / PACKAGE_PRESETS
    return opts.out / presets_mod.TUNED_FILE


def run(opts: Options) -> dict:
    """Every method's trials, then its tuned presets written to the presets file."""
    import warnings

    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)
    known = aolab.methods()
    methods = opts.methods or default_methods()
    for m in methods:
        if m not in known:
            raise ValueError(f"method {m!r} is not one of {known}")
    if opts.trials < 1:
        raise ValueError(f"--trials must be >= 1, got {opts.trials}")
    scenes_dir = opts.scenes_dir or find_scenes_dir()
    folders = tuning_folders(opts.scenes, scenes_dir, opts.follow_symlinks)
    presets_file = opts.presets_file or default_presets_file(folders, scenes_dir, opts)
    check_paths(reads=scene_files(folders),
                made={"--out": [opts.out / DB_NAME], "--presets-file": presets_file})
    db = check_store(opts.out)
    check_presets_file(presets_file)
    deadline = None if opts.timeout is None else time.monotonic() + opts.timeout
    scenes = load_scenes(folders, opts.crop, opts.follow_symlinks)
    meta = {"command": command_line(opts), "commit": git_commit(folders[0]),
            "date": _git_date(), "machine": machine_info(opts.timing.threads),
            "scenes": [s.name for s in scenes],
            "size": sorted({f"{s.g.width}x{s.g.height}" for s in scenes}),
            "crop": None if opts.crop is None else f"{opts.crop.width}x{opts.crop.height}",
            "families": {s.name: s.family for s in scenes},
            "objectives": "mean over the scenes of the occluded-region MAE (reference AO < "
                          "0.9) and of the time in ms per 1280x720 frame (method + shared "
                          "blur); constrained: whole-frame MAE no worse than AO = 1 on any "
                          "scene and no worse than the method's default on the mean",
            "validation": "leave one family out; a tuned preset ships only if its held-out "
                          "occluded MAE beats the default's on the same families",
            "timing": f"{opts.timing.warmup} warm-up + median of {opts.timing.repeat} runs "
                      f"per scene; a configuration whose first run exceeds "
                      f"{opts.timing.max_ms:g} ms is timed by that run alone",
            "sampler": opts.sampler, "seed": opts.seed, "budgets_ms": list(BUDGETS_MS)}
    bar = progress_bar(opts.progress, opts.trials * len(methods), "trial")
    results = {}
    from optuna.exceptions import StorageInternalError
    from sqlalchemy.exc import SQLAlchemyError
    client, cluster = (connect(opts.scheduler, opts.workers, opts.security)
                       if opts.scheduler is not None or opts.workers > 1 else (None, None))
    try:
        for m in methods:
            try:
                res = run_method(opts, m, scenes, bar, deadline, client)
            except (SQLAlchemyError, StorageInternalError) as e:   # a full disk, a bad file
                raise ValueError(store_error(db, e)) from None
            results[m] = res
            entry = method_entry(opts, res, scenes, {**meta, "date": _git_date()})
            text = summary(m, res["selection"], res["unshipped"], entry["trials"]["complete"])
            if res["done"]:
                write_presets(presets_file, {m: entry})
            else:   # --timeout: never presets from half a search
                text += (f"\n  {counted(res['study'])} of {opts.trials} trials (--timeout): "
                         "presets not written; run the command again to go on")
            (print if bar is None else bar.write)(text)
    finally:
        if bar is not None:
            bar.close()
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    return {"results": results, "presets_file": presets_file}


def tuning_folders(scenes: list[str], scenes_dir, follow_symlinks: bool = False) -> list[Path]:
    """The scene folders tune runs on (scenes.resolve_scenes): the still ones (a sequence's
    frames are the temporal study's, not tuning's)."""
    return [f for f in resolve_scenes(scenes, scenes_dir, follow_symlinks=follow_symlinks)
            if frame_numbers(f) is None]


def run_command(opts: Options) -> int:
    """``aolab tune``: :func:`run` with its output folder held, Ctrl-C and `kill` keeping
    the finished trials; the exit status."""
    try:
        import optuna  # noqa: F401
    except ImportError:
        raise ValueError("aolab tune needs Optuna: apt-get install python3-optuna") from None
    check_paths(folders={"--out": opts.out})   # before the lock makes the folder

    _STOP.clear()
    # Ctrl-C and `kill` keep the finished trials alike.
    previous = {sig: signal.signal(sig, _ask_to_stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    t0 = time.perf_counter()
    try:
        # One run at a time in an output folder: two would each rewrite the presets file
        # from what they read (files.output_lock).
        with files.output_lock(opts.out, "aolab tune"):
            out = run(opts)
    except KeyboardInterrupt:
        print(f"\naolab tune: interrupted. Every finished trial is kept in "
              f"{opts.out / DB_NAME}; run the same command again to resume.", file=sys.stderr)
        return 130
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    print(f"aolab tune: {len(out['results'])} method(s) in {time.perf_counter() - t0:.0f} s; "
          f"trials in {opts.out / DB_NAME}; presets in {out['presets_file']}")
    return 0
