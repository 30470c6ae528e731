"""``aolab advise`` and the add-on's Advise: which method, at which settings, for this scene
within a time budget (docs/comparison.md, "Advise: which method for this scene").

Every method but the bounds runs each of its named presets — default, the study's presets
and the tuned ones (aolab.presets) — once per distinct configuration on the scene's
G-buffer, timed and scored by the study's runner as ``aolab tune``'s trials are (a warm-up,
the median of the repeats, the shared blur timed apart and added, scaled to a 1280x720
frame: the budgets' unit, as for the tuned presets) and scored against the scene's reference
(study.quick_reference: the Cycles one where there is one, else the quick one) by its MAE on
the occluded region and on the whole frame (runner.evaluate).

Within a budget, budget.choose picks each method's best configuration among those that pass
the whole-frame guard (no worse than AO = 1, nor than the method's own default: so that no
flat grey image can win), the pick must beat AO = 1 on the occluded region (so that no
white one can), and the advice is the best of these picks. Two scores against
a noisy reference read high by up to its noise (scoring.reference_noise), and each output's
own share of that can be estimated from the quick reference's two halves
(quick_reference.Reference.inflation): the picks that lie above the best by no more than
theirs are named beside it, as ones this reference cannot tell apart from it.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

import aolab

from .. import named_presets as presets_mod
from ..bridge.constants import RESULT_EXR
from ..bridge.passes import required_passes
from ..cycles import blender
from ..cycles.cache import default_cache, find_by_content
from ..cycles.plan import make_plan, resolve_scene
from ..cycles.run import render
from ..scenes import find_scenes_dir
from ..scoring import require_scoreable
from ..util import files
from . import budget, quick_reference, tune
from .runner import Timing, evaluate, make_scene, trial_scores
from .findings import pareto_front

#: The budgets the panel offers and ``aolab advise`` answers by default: ms per 1280x720
#: frame (60, 30 and 10 frames a second).
BUDGETS_MS = (16, 33, 100)
#: A configuration whose first run is slower than this many times the largest budget asked
#: is timed by that run alone (as aolab tune does): it is past every budget...
SINGLE_RUN_FACTOR = 2.0
#: ...but never one whose first run (measured, not scaled) is below this: a first run pays
#: for allocations and cold caches, which at the panel's 320x180 can make it 20 times a warm
#: one (VAO++ at its defaults in a new process, measured: 54 ms, then 2 ms).
SINGLE_RUN_FLOOR_MS = 250.0
#: The panel's default Resolution: ``aolab advise`` renders a scene at this % of its size.
DEFAULT_SCALE = 25
#: Samples of the Cycles reference looked for in the cache (the panel's default).
CYCLES_SPP = 1024
#: Where the reference comes from: the Cycles one when there is one, else the quick one.
REFERENCE_CHOICES = ("auto", quick_reference.CYCLES, quick_reference.QUICK)


# ----------------------------------------------------------------------------------------
# The configurations and their scores


def configurations(methods: list[str]) -> tuple[list[dict], list[str]]:
    """Every named preset of each method, those that compute the same merged (named together:
    "default/low"), as [{"method", "names", "settings", "blur"}]; and notes (a tuned-presets
    file that cannot be read leaves the tuned presets out, and says so)."""
    out, notes = [], []
    for method in methods:
        try:
            named = presets_mod.named(method)
        except ValueError as e:
            notes.append(f"{method}: tuned presets left out ({e})")
            named = {n: presets_mod.settings_of(method, n) for n in
                     [presets_mod.DEFAULT_PRESET] + presets_mod.preset_names(method)}
        seen: dict[tuple, dict] = {}
        for name, values in named.items():
            settings = dict(values)
            blur = bool(settings.pop("blur", False))
            key = presets_mod.identity(method, settings, blur)
            if key in seen:
                seen[key]["names"].append(name)
                continue
            seen[key] = {"method": method, "names": [name], "settings": settings, "blur": blur}
            out.append(seen[key])
    return out, notes


def run(g, reference: quick_reference.Reference, radius: float, *, name: str,
        threads: int = 0, methods: list[str] | None = None, budgets=BUDGETS_MS,
        warmup: int = 1, repeat: int = 3, on_step=None) -> dict:
    """Every configuration of :func:`configurations` on G-buffer ``g`` at R = ``radius``,
    timed and scored against ``reference``. ``on_step(i, n, config)`` is called before each
    (progress; it may raise to stop). Returns the advice's data, JSON-ready: the scene, the
    reference's info, AO = 1's scores, the trials (budget's trial form: "scenes" -> {name: scores})
    and the configurations a method refused. A G-buffer with no geometry pixel, or a
    reference nowhere finite on geometry, is a ValueError before anything runs."""
    require_scoreable(g, reference.ao, name=name)
    t0 = time.perf_counter()
    scene = make_scene(name, g, reference.ao, radius)
    chosen = list(methods) if methods else tune.default_methods()
    configs, notes = configurations(chosen)
    # A first run slower than SINGLE_RUN_FACTOR x the largest budget is past every budget.
    single_ms = max(SINGLE_RUN_FACTOR * max(budgets) / scene.time_scale, SINGLE_RUN_FLOOR_MS)
    timing = Timing(warmup=warmup, repeat=repeat, threads=threads, max_ms=single_ms)

    def scorer(ao, sc) -> dict:
        """runner.trial_scores, and how high the two MAEs may read against this reference
        (Reference.inflation; None against the Cycles one)."""
        return {**trial_scores(ao, sc), "inflation": reference.inflation(ao, sc.occluded),
                "all_inflation": reference.inflation(ao, sc.valid)}
    trials, refused = [], []
    for i, c in enumerate(configs):
        if on_step is not None:
            on_step(i, len(configs), c)
        try:
            scores = evaluate(c["method"], c["settings"], c["blur"], [scene], timing,
                              scorer=scorer)
        except (ValueError, RuntimeError) as e:
            refused.append({"method": c["method"], "names": c["names"], "error": str(e)})
            continue
        for row in scores.values():
            row.pop("digest", None)
        same = f" (= {', '.join(c['names'][1:])})" if len(c["names"]) > 1 else ""
        trials.append({"number": len(trials), "method": c["method"], "preset": c["names"][0],
                       "names": c["names"], "short": f"{c['method']} {c['names'][0]}",
                       "label": f"{c['method']} {c['names'][0]}{same}",
                       "settings": {**c["settings"], "blur": c["blur"]}, "scenes": scores})
    occluded = scene.occluded
    return {"scene": name, "width": g.width, "height": g.height, "radius": radius,
            "time_scale": scene.time_scale, "threads": threads,
            "reference": reference.info(), "methods": chosen, "notes": notes,
            "pixels": {"scored": int(scene.valid.sum()), "occluded": int(occluded.sum())},
            "ao_one": {"all_mae": scene.ao_one_mae,
                       "occluded_mae": (float(np.mean(1.0 - reference.ao[occluded]))
                                        if occluded.any() else None)},
            "trials": trials, "refused": refused, "seconds": time.perf_counter() - t0}


def _scores(result: dict, trial: dict) -> dict:
    return trial["scenes"][result["scene"]]


def _by_method(result: dict) -> dict:
    out: dict = {}
    for t in result["trials"]:
        out.setdefault(t["method"], []).append(t)
    return out


def _guard(result: dict, rows: list[dict]) -> budget.Guard:
    """The whole-frame guard of one method's trials: AO = 1 on this scene, and the method's
    default (the trial its "default" preset names)."""
    default = next((t for t in rows if presets_mod.DEFAULT_PRESET in t["names"]), None)
    return budget.Guard(ao_one={result["scene"]: result["ao_one"]["all_mae"]}, default=default)


def _draws_occlusion(result: dict, trial: dict) -> bool:
    """Whether the trial's occluded MAE is finite and below AO = 1's there: better than
    drawing no occlusion where there is some (AO = 1 passes the whole-frame guard, which
    takes it as its bound)."""
    mae, one = _scores(result, trial)["mae"], result["ao_one"]["occluded_mae"]
    return math.isfinite(mae) and one is not None and mae < one


def reads_high(result: dict, trial: dict) -> float | None:
    """How much higher the trial's occluded MAE may read against the reference than against
    the noise-free AO: its own estimate from the quick reference's halves when there is one
    (Reference.inflation), else the reference's noise there (None: unknown)."""
    own = _scores(result, trial).get("inflation")
    return own if own is not None else result["reference"]["noise_occluded"]


def contenders(result: dict) -> list[dict]:
    """The trials that pass their method's whole-frame guard (budget.admits) and draw
    occlusion better than AO = 1 on the occluded region."""
    scenes = [result["scene"]]
    return [t for rows in _by_method(result).values() for t in rows
            if _draws_occlusion(result, t)
            and budget.admits(_guard(result, rows), t, scenes)]


def front(result: dict) -> list[dict]:
    """The admissible trials no other admissible one beats in both time and occluded MAE,
    fastest first."""
    pts = contenders(result)
    keys = pareto_front([(_scores(result, t)["ms"], _scores(result, t)["mae"], t["number"])
                         for t in pts], lower_is_better=True)
    by_number = {t["number"]: t for t in pts}
    return [by_number[k] for k in keys]


def choose(result: dict, budget_ms: float) -> dict:
    """The advice within ``budget_ms`` (per 1280x720 frame): ``best``, each method's pick
    (budget.choose with its guard; it must also beat AO = 1 on the occluded region) with the
    lowest occluded MAE (ties: the faster); ``as_good``, the other methods' picks whose MAE
    may read high by as much as they lie above it (:func:`reads_high`): this reference
    cannot tell that they are worse; ``others``,
    the remaining picks, best first; and, when there is no best, ``fastest`` (the fastest
    admissible trial, else the fastest of all) and ``why``. Trials are given whole."""
    scenes = [result["scene"]]
    picks = []
    for rows in _by_method(result).values():
        t = budget.choose(rows, scenes, budget_ms, _guard(result, rows))
        if t is not None and _draws_occlusion(result, t):
            picks.append(t)
    picks.sort(key=lambda t: (_scores(result, t)["mae"], _scores(result, t)["ms"], t["number"]))
    out = {"budget_ms": budget_ms, "best": picks[0] if picks else None, "as_good": [],
           "others": [], "fastest": None, "why": None}
    if picks:
        best = _scores(result, picks[0])["mae"]
        for t in picks[1:]:
            high = reads_high(result, t)
            close = high is not None and _scores(result, t)["mae"] - best <= high
            out["as_good" if close else "others"].append(t)
        return out
    pool = contenders(result) or result["trials"]
    if pool:
        out["fastest"] = min(pool, key=lambda t: (_scores(result, t)["ms"], t["number"]))
    if not result["pixels"]["occluded"]:
        out["why"] = ("nothing in the frame is occluded (the reference is 0.9 or more on "
                      "every pixel): there is no occlusion to be right about")
    elif not result["trials"]:
        out["why"] = "every configuration was refused"
    elif all(_scores(result, t)["ms"] > budget_ms for t in result["trials"]):
        out["why"] = f"no configuration takes {budget_ms:.10g} ms or less per 1280x720 frame here"
    else:
        out["why"] = (f"every configuration within {budget_ms:.10g} ms is worse on the whole frame "
                      "than AO = 1 or than its method's default, or no better than AO = 1 "
                      "where there is occlusion")
    return out


# ----------------------------------------------------------------------------------------
# What the advice says


def describe(result: dict, trial: dict) -> str:
    """One trial in words: "gtao tuned-50ms: occluded MAE 0.0612, whole frame 0.0213, 14.2 ms
    per 1280x720 frame (0.89 ms at 320x180)"; presets that compute the same are named after
    the first: "lsao default (= medium)"."""
    s = _scores(result, trial)
    measured = "" if result["time_scale"] == 1 else \
        f" ({s['measured_ms']:.2f} ms at {result['width']}x{result['height']})"
    occluded = f"{s['mae']:.4f}" if math.isfinite(s["mae"]) else "none (no occluded pixel)"
    return (f"{trial['label']}: occluded MAE {occluded}, whole frame {s['all_mae']:.4f}, "
            f"{s['ms']:.1f} ms per 1280x720 frame{measured}")


def headline(result: dict) -> str:
    """What was run, against what, and how noisy that is."""
    ref = result["reference"]
    noise = ("noise unknown" if ref["noise"] is None else
             f"noise {ref['noise']:.4f} on the whole frame, "
             f"{ref['noise_occluded'] or 0:.4f} on the occluded region")
    n = len(result["trials"])
    methods = len({t["method"] for t in result["trials"]})
    return (f"{result['scene']} at {result['width']}x{result['height']}, R = "
            f"{result['radius']:g}: {n} configurations of {methods} methods against "
            f"{ref['label']} ({noise}) in {result['seconds']:.1f} s")


def advice_lines(result: dict, budget_ms: float) -> list[str]:
    """The advice for one budget as lines: the best, those not told apart from it at the
    reference's noise, or why there is none."""
    got = choose(result, budget_ms)
    head = f"within {budget_ms:.10g} ms per 1280x720 frame: "
    if got["best"] is None:
        lines = [head + f"no advice: {got['why']}"]
        if got["fastest"] is not None:
            lines.append(f"  the fastest: {describe(result, got['fastest'])}")
        return lines
    lines = [head + describe(result, got["best"])]
    for t in got["as_good"]:
        lines.append(f"  not told apart from it at this reference's noise: {describe(result, t)}")
    return lines


# ----------------------------------------------------------------------------------------
# The front as an image (matplotlib, off screen)

#: The time axis's ticks (ms), the budgets among them.
TIME_TICKS_MS = (0.5, 1, 2, 5, 10, 16, 33, 50, 100, 200, 500, 1000, 2000, 5000, 10000)
#: Markers per method: the colour cycle has ten colours, the methods are more.
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "<", ">", "h", "*", "p")


def plot(result: dict, budgets=BUDGETS_MS, size: tuple[int, int] = (640, 540)) -> np.ndarray:
    """This scene's accuracy-against-time front as an RGBA float32 image (H, W, 4), row 0 at
    the top: every configuration (a colour and marker per method), the front of the
    admissible ones, the budgets, each budget's advice ringed, AO = 1's occluded MAE and the
    band of the reference's noise. matplotlib's Agg canvas, no window: any thread may call
    it."""
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    dpi = 100
    fig = Figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    colours = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (method, rows) in enumerate(sorted(_by_method(result).items())):
        pts = [(_scores(result, t)["ms"], _scores(result, t)["mae"]) for t in rows
               if math.isfinite(_scores(result, t)["mae"])]
        if pts:
            x, y = zip(*pts)
            ax.scatter(x, y, s=16, color=colours[i % len(colours)],
                       marker=MARKERS[i % len(MARKERS)], label=method, zorder=3)
    line = [(_scores(result, t)["ms"], _scores(result, t)["mae"]) for t in front(result)]
    if line:
        x, y = zip(*line)
        ax.step(x, y, where="post", color="black", lw=1, zorder=2, label="front (guarded)")
    ref = result["reference"]
    if ref["noise_occluded"]:
        ax.axhspan(0, ref["noise_occluded"], color="0.88", zorder=0,
                   label="reference noise (occluded)")
    one = result["ao_one"]["occluded_mae"]
    if one is not None:
        ax.axhline(one, color="tab:red", ls="--", lw=1, zorder=1, label="AO = 1")
    ax.set_xscale("log")
    advised: dict = {}   # trial number -> (trial, the budgets it is the advice of)
    for b in budgets:
        ax.axvline(b, color="0.4", ls=":", lw=1, zorder=1)
        got = choose(result, b)["best"]
        if got is not None:
            advised.setdefault(got["number"], (got, []))[1].append(b)
    for got, within in advised.values():
        s = _scores(result, got)
        ax.scatter([s["ms"]], [s["mae"]], s=140, facecolors="none", edgecolors="black",
                   lw=1.4, zorder=4)
        ax.annotate(f"{', '.join(f'{b:g}' for b in within)} ms: {got['short']}",
                    (s["ms"], s["mae"]), fontsize=7, xytext=(6, 6), textcoords="offset points",
                    zorder=5)
    lo, hi = ax.get_xlim()
    ticks = [t for t in TIME_TICKS_MS if lo <= t <= hi]
    if ticks:
        ax.set_xticks(ticks)
        ax.set_xticklabels([f"{t:g}" for t in ticks])
        ax.minorticks_off()
    ax.set_ylim(bottom=0)
    ax.set_xlabel(f"ms per 1280x720 frame (measured at {result['width']}x{result['height']}, "
                  f"scaled by pixels)", fontsize=8)
    ax.set_ylabel("MAE on the occluded region", fontsize=8)
    ax.set_title(f"{result['scene']}: against {ref['label']}", fontsize=9)
    ax.tick_params(labelsize=7)
    ax.grid(True, which="both", color="0.93", lw=0.5)
    ax.legend(fontsize=6, ncol=2, loc="upper right", framealpha=0.9)
    fig.tight_layout()
    canvas.draw()
    w, h = canvas.get_width_height()
    rgba = np.asarray(canvas.buffer_rgba(), np.uint8).reshape(h, w, 4)
    return rgba.astype(np.float32) / 255.0


# ----------------------------------------------------------------------------------------
# A scene from the command line


def scene_spec(spec: str) -> Path:
    """A path, else a reference_scenes name; a ValueError naming what is accepted."""
    p = Path(spec)
    if p.exists():
        return p
    scenes_dir = find_scenes_dir()
    if scenes_dir is not None and (Path(scenes_dir) / spec).is_dir():
        return Path(scenes_dir) / spec
    raise ValueError(f"no such scene: {spec} (give a .blend, a build script .py, a "
                     "reference_scenes name or folder, or a G-buffer .exr with its sidecar)")


def _radius_of(g, where: str) -> float:
    r = (g.sidecar or {}).get("ao_distance")
    if not (isinstance(r, (int, float)) and not isinstance(r, bool) and math.isfinite(r)
            and r > 0):
        raise ValueError(f"the sidecar of {where} has no ao_distance > 0 (got {r!r})")
    return float(r)


def load(spec: str, *, scale: int | None = None, radius: float | None = None,
         reference: str = "auto", rays: int = quick_reference.QUICK_RAYS,
         spp: int = CYCLES_SPP, threads: int = 0, cache: Path | None = None,
         progress: bool = False, follow_symlinks: bool = False):
    """The scene ``aolab advise`` advises on: (name, G-buffer, R, Reference).

    A G-buffer ``.exr`` with its sidecar is used as it is, scored against its own AO pass
    (Cycles) or, with ``reference`` "quick" or without an AO pass, rtao against the `.mesh`
    beside it. Anything ``aolab reference`` renders — a .blend, a build script .py, a
    reference_scenes name or folder — is rendered by Blender at ``scale`` % of its output size
    (default DEFAULT_SCALE, the panel's) and at R = ``radius`` (default: its manifest's, else
    its world's AO distance), its G-buffer and triangles at 1 sample (cached), and
    scored against the Cycles reference of the same content, size and R at ``spp`` samples
    when the cache holds one (the panel's Render Reference, or ``aolab reference
    --resolution WxH``), else the quick reference. ``reference`` "cycles" insists on
    Cycles, "quick" on rtao. A scene folder with a symbolic link among its files is refused
    unless ``follow_symlinks`` (scenes.check_confined). Problems are ValueErrors saying what
    to do."""
    p = scene_spec(spec)
    if reference not in REFERENCE_CHOICES:
        raise ValueError(f"--reference must be one of {', '.join(REFERENCE_CHOICES)}, "
                         f"got {reference!r}")
    if p.suffix.lower() == ".exr":
        for option, value in (("--scale", scale), ("--radius", radius)):
            if value is not None:
                raise ValueError(f"{option} applies to a scene Blender renders (.blend, .py, "
                                 f"a reference_scenes name or folder); the G-buffer {spec} is "
                                 "used as it is, at its sidecar's size and R")
        g = aolab.load_gbuffer(files.regular_file(p, "G-buffer"))
        radius = _radius_of(g, spec)
        name = p.parent.name if p.stem == "reference" else p.stem
        cycles = g if getattr(g, "reference", None) is not None else None
        where = f"{spec} has no AO pass"
    else:
        g, radius, name, cycles = _rendered(p, scale if scale is not None else DEFAULT_SCALE,
                                            radius, spp, cache, progress,
                                            want=reference != "quick",
                                            follow_symlinks=follow_symlinks)
        where = (f"no {spp}-spp Cycles reference of {name} at {g.width}x{g.height}, R = "
                 f"{radius:g} is cached: render one (aolab reference {spec} --resolution "
                 f"{g.width}x{g.height} --spp {spp}, or the panel's Render Reference)")
    if reference == quick_reference.CYCLES and cycles is None:
        raise ValueError(where + "; or use --reference quick")
    # Nothing to score is refused before the work: no scores of NaN, no time from no pixel.
    require_scoreable(g, np.ones((g.height, g.width), np.float32), name=spec)
    if reference != quick_reference.QUICK and cycles is not None:
        require_scoreable(cycles, name=spec if cycles is g else f"the cached Cycles reference "
                          f"of {name}", hint="; or use --reference quick")
    if reference != quick_reference.QUICK and cycles is not None:
        return name, cycles, radius, quick_reference.cycles(cycles)
    return name, g, radius, quick_reference.quick(g, radius=radius, rays=rays, threads=threads)


def _rendered(path: Path, scale: int, radius: float | None, spp: int, cache: Path | None,
              progress: bool, want: bool, follow_symlinks: bool = False):
    """Blender's 1-sample G-buffer and triangles of a scene at ``scale`` % (cached), and the
    G-buffer of its cached Cycles reference at ``spp`` when ``want`` (else None)."""
    try:
        scene = resolve_scene(str(path), follow_symlinks)
        infos = [aolab.method_info(m) for m in aolab.methods()]
        passes = required_passes(infos, scene.manifest.get("effects", [])) + ["mesh"]
        plan = make_plan(scene, spp=1, radius=radius, passes=passes, scale=scale)
        cache = Path(cache) if cache else default_cache()
        folder, _ = render(plan, cache, progress=progress)
    except blender.ReferenceError as e:
        raise ValueError(str(e)) from None
    g = aolab.load_gbuffer(folder / RESULT_EXR)
    radius = _radius_of(g, str(folder / RESULT_EXR))
    found = None
    if want:
        side = g.sidecar or {}
        found = find_by_content(cache, scene_hash=side.get("scene_hash"),
                                size=(g.width, g.height), radius=radius, spp=spp)
    return g, radius, scene.name, (aolab.load_gbuffer(found / RESULT_EXR) if found else None)
