"""`aolab tune`: the search space, the leave-one-scene-out choice, the SQLite store (resume,
Ctrl-C) and the tuned presets it writes (docs/tuning.md). Short runs on small crops of two
committed scenes."""
from __future__ import annotations

import json
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import scenes
from aolab import cli
from aolab import named_presets as presets
from aolab.cli.options import crop_of
from aolab.study import budget, runner, tune

optuna = pytest.importorskip("optuna")

ROOT = Path(__file__).resolve().parents[3]
SCENES = ROOT / "reference_scenes"
CROP = "96x54"
# Two families (thin, mechanical) where HBAO beats AO = 1 on the whole frame of the crop.
FAST = ["--scenes", "grille", "engine", "--scenes-dir", str(SCENES), "--crop", CROP,
        "--warmup", "0", "--repeat", "1", "--no-progress"]


def load(out: Path, method: str):
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    return optuna.load_study(study_name=tune.STUDY_PREFIX + method,
                             storage=f"sqlite:///{out / tune.DB_NAME}")


def complete(study) -> dict:
    states = (optuna.trial.TrialState.COMPLETE,)
    return {t.number: t for t in study.get_trials(deepcopy=False, states=states)}


# ----------------------------------------------------------------------------------------
# The search space


def test_search_space_covers_every_setting_of_every_method():
    for method in tune.default_methods():
        space = tune.search_space(method)
        names = {p.name for p in space.params}
        info = {s["name"] for s in aolab.method_info(method)["settings"]}
        assert set(space.notes) == info | {"blur"}, method    # every setting accounted for
        assert "radius" not in names and "seed" not in names
        assert "blur" in names
        for p in space.params:
            if p.kind != "set":
                assert p.low < p.high and p.why, (method, p.name)
                assert p.high < 1e4, (method, p.name)           # bounded, not 1e30
                if p.log:
                    assert p.low > 0
    lsao = tune.search_space("lsao")
    assert "directions" in {p.name for p in lsao.params if p.when is not None}
    assert tune.search_space("pyramid_hbao").fixed == {"gaussian_filter": False}
    vao_pp = {p.name: p for p in tune.search_space("vao_pp").params}
    assert vao_pp["samples"].choices == (2, 4, 8, 16, 32)
    assert "color_bleeding" not in vao_pp and "luminance_sensitivity" not in vao_pp


def test_suggestions_respect_the_constraints():
    """Sampled points of LSAO keep K = 8 x template size (presets.py's rule); every method
    accepts its sampled points (a few random trials per method, on a tiny scene)."""
    g = aolab.analytic_scene("blocks", 48, 27)
    for method in tune.default_methods():
        space = tune.search_space(method)
        study = optuna.create_study(directions=["minimize", "minimize"],
                                    sampler=optuna.samplers.RandomSampler(seed=1))
        for _ in range(6):
            trial = study.ask()
            settings, blur = tune.suggest(trial, space)
            if method == "lsao" and settings["template_size"] > 0:   # a default is left out
                k = settings.get("directions", space.defaults["directions"])
                assert k == 8 * settings["template_size"]
            aolab.compute(method, g, radius=0.5, blur=blur, **settings)
            study.tell(trial, [0.0, 0.0])


def test_default_methods_leave_out_bounds(monkeypatch):
    real = aolab.method_info
    first = aolab.methods()[0]
    monkeypatch.setattr(aolab, "method_info",
                        lambda m: {**real(m), "bound": True} if m == first else real(m))
    assert first not in tune.default_methods()
    assert tune.default_methods() == [m for m in aolab.methods()
                                      if m != first and not real(m)["bound"]]


def test_presets_enter_as_trials_inside_the_bounds():
    space = tune.search_space("pyramid_hbao")
    # the builtin Gaussian of the defaults is the shared blur of the search
    assert tune.preset_params(space, presets.named("pyramid_hbao")["default"])["blur"] is True
    space = tune.search_space("lsao")
    params = tune.preset_params(space, presets.named("lsao")["low"])
    assert params["template_size"] == 1 and "directions" not in params
    assert tune.preset_params(space, {"line_spacing": 60.0}) is None     # out of bounds


# ----------------------------------------------------------------------------------------
# Timing and scoring


def test_timing_counts_warmup_and_repeat():
    """tune times with the runner, as compare does: warm-up runs, then the timed ones; a
    configuration over the cap is timed by its first run, and so on every later scene."""
    calls = []
    (sc,) = tune.load_scenes([SCENES / "room"], crop_of("32x18"))

    def counted(*args, **kw):
        calls.append(1)
        return np.ones((18, 32), np.float32)
    original = aolab.compute
    aolab.compute = counted
    try:
        for warmup, repeat, runs, timed in ((1, 3, 4, 3), (0, 1, 1, 1), (0, 3, 3, 3),
                                            (2, 2, 4, 2)):
            calls.clear()
            run = runner.run_configuration("hbao", {}, sc, runner.Timing(warmup, repeat))
            assert (len(calls), len(run.times), run.single) == (runs, timed, False)
        calls.clear()
        slow = runner.Timing(1, 3, max_ms=-1.0)      # every run is "over the cap": one run only
        run = runner.run_configuration("hbao", {}, sc, slow)
        assert (len(calls), len(run.times), run.single) == (1, 1, True)
        calls.clear()
        run = runner.run_configuration("hbao", {}, sc, runner.Timing(1, 3), single=True)
        assert (len(calls), len(run.times), run.single) == (1, 1, True)
    finally:
        aolab.compute = original


def test_occluded_mae_is_the_studys():
    crop = crop_of("160x90")
    (sc,) = tune.load_scenes([SCENES / "room"], crop)
    got = runner.evaluate("vao", {"samples": 4}, True, [sc], runner.Timing(0, 1))["room"]
    full = scenes.load_scene(SCENES / "room", crop)
    ao = aolab.compute("vao", full.g, radius=full.radius, samples=4, blur=True)
    want = runner.score(ao, full)["regions"]
    assert got["mae"] == pytest.approx(want["occluded"]["mae"], abs=1e-12)
    assert got["bias"] == pytest.approx(want["occluded"]["bias"], abs=1e-12)
    assert got["all_mae"] == pytest.approx(want["all"]["mae"], abs=1e-12)
    assert got["measured_ms"] == pytest.approx(got["method_ms"] + got["blur_ms"])
    # full frames are scaled to 1280x720 (test_full_frame_times_are_per_1280x720_frame)
    assert got["ms"] == got["measured_ms"]   # a crop keeps its own time


# ----------------------------------------------------------------------------------------
# Choosing within a budget, the whole-frame guard, leave one family out


def _trial(number, ms, mae, all_mae=(0.0, 0.0, 0.0), preset=None):
    return {"number": number, "settings": {"n": number}, "preset": preset,
            "scenes": {s: {"ms": ms[i], "mae": mae[i], "all_mae": all_mae[i]}
                       for i, s in enumerate("ABC")}}


TABLE = [
    _trial(0, (50, 50, 50), (0.30, 0.30, 0.30)),
    _trial(1, (90, 90, 90), (0.10, 0.40, 0.40)),
    _trial(2, (80, 80, 80), (0.35, 0.20, 0.20)),
    _trial(3, (300, 60, 60), (0.05, 0.05, 0.05)),   # mean 140 ms: over 100 on all scenes
]
#: A in one family, B and C in another.
FAMILIES = {"A": "f", "B": "g", "C": "g"}


def test_choice_within_a_budget_is_the_lowest_mean_error():
    assert budget.choose(TABLE, list("ABC"), 100)["number"] == 2
    assert budget.choose(TABLE, list("ABC"), 50)["number"] == 0
    assert budget.choose(TABLE, list("ABC"), 20) is None
    assert budget.choose(TABLE, list("ABC"), 1000)["number"] == 3
    tie = TABLE + [_trial(4, (40, 40, 40), (0.30, 0.30, 0.30))]   # same error, faster
    assert budget.choose(tie, list("ABC"), 50)["number"] == 4


def test_the_guard_excludes_a_choice_worse_than_ao_one_or_the_default_on_the_whole_frame():
    default = _trial(0, (50, 50, 50), (0.30, 0.30, 0.30), (0.05, 0.05, 0.05), "default")
    darker = _trial(1, (50, 50, 50), (0.10, 0.10, 0.10), (0.05, 0.05, 0.09))  # C: > AO = 1
    worse = _trial(2, (50, 50, 50), (0.20, 0.20, 0.20), (0.06, 0.06, 0.06))   # > default
    fine = _trial(3, (50, 50, 50), (0.25, 0.25, 0.25), (0.05, 0.04, 0.05))
    rows = [default, darker, worse, fine]
    guard = budget.Guard(ao_one={"A": 0.08, "B": 0.08, "C": 0.08}, default=default)
    assert budget.choose(rows, list("ABC"), 100)["number"] == 1      # unguarded: the darker
    assert budget.choose(rows, list("ABC"), 100, guard)["number"] == 3
    # on A and B alone, the darker one is no worse than AO = 1
    assert budget.choose(rows, list("AB"), 100, guard)["number"] == 1
    no_default = budget.Guard(ao_one=guard.ao_one)
    assert budget.choose(rows, list("ABC"), 100, no_default)["number"] == 2


def test_degenerate_outputs_cannot_pass_the_whole_frame_guard():
    """All dark, all grey, or the reference darkened everywhere: each is worse than AO = 1
    on the whole frame of a real scene, so no budget can choose it."""
    (sc,) = tune.load_scenes([SCENES / "room"], crop_of("320x180"))
    guard = budget.Guard(ao_one={"room": sc.ao_one_mae})
    ref = sc.reference

    def row(ao):
        return {"number": 0, "scenes": {"room": {"ms": 1.0, **runner.trial_scores(ao, sc)}}}
    for bad in (np.zeros_like(ref), np.full_like(ref, 0.5), np.clip(ref - 0.2, 0, 1)):
        assert not budget.admits(guard, row(bad.astype(np.float32)), ["room"])
    for good in (np.ones_like(ref), ref):
        assert budget.admits(guard, row(good.astype(np.float32)), ["room"])


def test_leave_one_family_out_chooses_on_the_other_families_only():
    held = budget.leave_one_family_out(TABLE, FAMILIES, 100)
    # family f (A) held out: on B, C trial 3 is best and fast (60 ms); on A it takes 300 ms.
    assert held["f"]["trial"] == 3 and held["f"]["mae"] == 0.05
    assert held["f"]["within_budget"] is False and held["f"]["scenes"]["A"]["ms"] == 300
    assert held["f"]["train_mae"] == pytest.approx(0.05)
    # family g (B, C) held out: on A alone trial 3 takes 300 ms, so trial 1 (0.10) wins
    assert held["g"]["trial"] == 1 and held["g"]["mae"] == pytest.approx(0.40)
    assert set(held["g"]["scenes"]) == {"B", "C"}
    summary = budget.held_out_summary(held)
    assert summary["held_out_mean_mae"] == pytest.approx((0.05 + 0.40) / 2)
    assert summary["gap"] == pytest.approx((0.05 + 0.40) / 2 - (0.05 + 0.10) / 2)
    assert summary["held_out_folds"] == 2


def test_a_tuned_choice_that_loses_to_the_default_held_out_ships_the_default():
    default = _trial(9, (40, 40, 40), (0.20, 0.20, 0.20), preset="default")
    balanced = _trial(2, (50, 50, 50), (0.15, 0.15, 0.15))
    trap = _trial(3, (50, 50, 50), (0.30, 0.05, 0.05))      # great on family g, bad on f
    trap2 = _trial(4, (50, 50, 50), (0.05, 0.30, 0.30))     # great on family f, bad on g
    guard = budget.Guard(default=default)
    # A choice that holds on every family ships.
    sel, unshipped = budget.select([default, balanced], FAMILIES, (100,), guard)
    assert sel["tuned-100ms"]["trial"] == 2 and sel["tuned-100ms"]["ships"] == "tuned"
    assert sel["tuned-100ms"]["held_out_mean_mae"] == pytest.approx(0.15)
    assert sel["tuned-100ms"]["default_held_out_mean_mae"] == pytest.approx(0.20)
    assert not unshipped
    # trap wins on all scenes (0.133) but each fold picks the configuration that is bad on
    # the held-out family (0.30 there, the default 0.20): the default ships.
    sel, unshipped = budget.select([default, trap, trap2], FAMILIES, (100,), guard)
    assert sel["tuned-100ms"]["tuned_trial"] == 3
    assert sel["tuned-100ms"]["trial"] == 9 and sel["tuned-100ms"]["ships"].startswith("default")
    assert sel["tuned-100ms"]["settings"] == default["settings"]
    # Within 45 ms only the default fits: it is the choice.
    sel, _ = budget.select([default, trap, trap2], FAMILIES, (45,), guard)
    assert sel["tuned-45ms"]["trial"] == 9 and sel["tuned-45ms"]["ships"].startswith("default")
    # A default over the budget cannot stand in: nothing ships, and the reason is given.
    slow = _trial(9, (80, 80, 80), (0.20, 0.20, 0.20), preset="default")
    sel, unshipped = budget.select([slow, trap, trap2], FAMILIES, (60,),
                                   budget.Guard(default=slow))
    assert sel == {} and "lost to the default" in unshipped["tuned-60ms"]


def test_best_across_methods_is_chosen_on_the_other_families():
    """Per scene, the method whose fold for the scene's family has the lowest training error
    wins, whatever its score on the scene itself."""
    def fold(trial, scores, train_mae):
        return {"trial": trial, "train_mae": train_mae,
                "scenes": {s: {"mae": m, "ms": ms} for s, (m, ms) in scores.items()}}

    methods = {
        "a": {"selection": {"tuned-100ms": {"held_out": {
            "f": fold(1, {"S": (0.30, 40.0)}, 0.10),
            "g": fold(2, {"T": (0.05, 40.0), "U": (0.07, 40.0)}, 0.20)}}}},
        "b": {"selection": {"tuned-100ms": {"held_out": {
            "f": fold(7, {"S": (0.01, 40.0)}, 0.15),
            "g": fold(8, {"T": (0.50, 130.0), "U": (0.40, 50.0)}, 0.12)}}}},
        "c": {"selection": {"tuned-50ms": {"held_out": {"f": fold(9, {"S": (0.0, 1.0)}, 0.0)}}}},
    }
    best = budget.best_across_methods(methods, 100)
    assert best["S"] == {"method": "a", "trial": 1, "mae": 0.30, "ms": 40.0,
                         "within_budget": True, "train_mae": 0.10}   # not b's 0.01 on S
    assert best["T"]["method"] == "b" and best["T"]["within_budget"] is False
    assert best["U"]["method"] == "b" and best["U"]["mae"] == 0.40
    assert budget.best_across_methods(methods, 50)["S"]["method"] == "c"
    assert budget.best_across_methods({}, 100) == {}
    # A file from before families: one fold per scene
    old = {"a": {"selection": {"tuned-100ms": {"held_out": {
        "S": {"trial": 1, "mae": 0.2, "ms": 10.0, "train_mae": 0.1}, "T": None}}}}}
    assert budget.best_across_methods(old, 100) == {
        "S": {"method": "a", "trial": 1, "mae": 0.2, "ms": 10.0, "within_budget": True,
              "train_mae": 0.1}, "T": None}


# ----------------------------------------------------------------------------------------
# The command: store, resume, interruption, presets


def test_store_resume_and_tuned_presets(tmp_path, monkeypatch, capsys):
    out, pfile = tmp_path / "tune", tmp_path / "tuned.json"
    args = ["tune", "--methods", "hbao", "--out", str(out), "--presets-file", str(pfile), *FAST]
    assert cli.main([*args, "--trials", "3"]) == 0
    assert (out / tune.DB_NAME).exists()
    first = complete(load(out, "hbao"))
    assert len(first) == 3
    # The study starts from the presets (default, low, medium: enqueued in that order).
    assert [first[n].user_attrs.get("preset") for n in sorted(first)] == \
        ["default", "low", "medium"]
    assert cli.main([*args, "--trials", "5"]) == 0
    second = complete(load(out, "hbao"))
    assert len(second) == 5
    for n, t in first.items():   # kept as they were: nothing recomputed
        assert second[n].values == t.values
        assert second[n].datetime_complete == t.datetime_complete
    assert cli.main([*args, "--trials", "5"]) == 0             # nothing left to do
    assert len(complete(load(out, "hbao"))) == 5
    # Another protocol (other timing) is refused, not mixed in.
    assert cli.main([*args[:-5], "--warmup", "1", "--repeat", "1", "--no-progress",
                     "--trials", "6"]) == 2
    assert "another --out" in capsys.readouterr().err

    data = json.loads(pfile.read_text())
    entry = data["methods"]["hbao"]
    assert entry["command"].startswith("aolab tune --methods hbao --trials 5")
    assert entry["commit"] and entry["date"] and entry["crop"] == CROP
    assert entry["scenes"] == ["grille", "engine"] and entry["trials"]["complete"] == 5
    assert entry["presets"], "a crop this small fits every budget"
    assert set(entry["whole_frame_guard"]["ao_one_mae"]) == {"grille", "engine"}
    for name, sel in entry["selection"].items():
        assert set(sel["held_out"]) == {"thin", "mechanical"}   # the scenes' families
        assert sel["held_out_folds"] == 2
        assert sel["gap"] == pytest.approx(sel["held_out_mean_mae"] - sel["train_mean_mae"])
    # The JSON round-trips into aolab.presets and compute(preset=...).
    monkeypatch.setenv("AOLAB_TUNED_PRESETS", str(pfile))
    named = aolab.presets("hbao")
    assert [n for n in named if n.startswith("tuned-")] == list(entry["presets"])
    for name, values in entry["presets"].items():
        assert named[name] == values
    name, values = next(iter(entry["presets"].items()))
    g = aolab.analytic_scene("blocks", 64, 36)
    np.testing.assert_array_equal(aolab.compute("hbao", g, radius=0.5, preset=name),
                                  aolab.compute("hbao", g, radius=0.5, **values))


def test_ctrl_c_exits_cleanly_and_keeps_the_finished_trials(tmp_path):
    out = tmp_path / "tune"
    cmd = [sys.executable, "-m", "aolab", "tune", "--methods", "lsao", "--trials", "100000",
           "--out", str(out), "--presets-file", str(tmp_path / "p.json"), *FAST]
    # A background shell starts children with SIGINT ignored; Ctrl-C needs the default.
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    db = out / tune.DB_NAME
    deadline = time.monotonic() + 40
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.3)
            if not db.exists():
                continue
            try:
                with sqlite3.connect(db, timeout=1) as con:
                    n = con.execute("SELECT count(*) FROM trials WHERE state = 'COMPLETE'"
                                    ).fetchone()[0]
            except sqlite3.OperationalError:
                continue
            if n >= 3:
                break
        assert proc.poll() is None, proc.communicate()
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr and str(db) in stderr and "resume" in stderr
    assert "Traceback" not in stderr
    study = load(out, "lsao")
    assert len(complete(study)) >= 3
    states = {t.state for t in study.get_trials(deepcopy=False)}
    assert optuna.trial.TrialState.RUNNING not in states
    assert not (tmp_path / "p.json").exists()        # no presets from an interrupted run


def test_command_line_errors_are_clear(tmp_path, capsys):
    base = ["tune", "--out", str(tmp_path), *FAST]
    assert cli.main([*base, "--methods", "nope"]) == 2
    assert "nope" in capsys.readouterr().err
    assert cli.main([*base, "--methods", "vao", "--trials", "0"]) == 2
    assert "--trials" in capsys.readouterr().err
    res = subprocess.run([sys.executable, "-m", "aolab", "tune", "--help"],
                         capture_output=True, text=True)
    assert res.returncode == 0 and "--trials" in res.stdout and "--timeout" in res.stdout


def test_timeout_keeps_the_study_and_writes_no_presets(tmp_path, capsys):
    pfile = tmp_path / "p.json"
    assert cli.main(["tune", "--methods", "vao", "--trials", "3", "--timeout", "0", "--out",
                     str(tmp_path), "--presets-file", str(pfile), *FAST]) == 0
    assert "0 of 3 trials (--timeout): presets not written" in capsys.readouterr().out
    assert (tmp_path / tune.DB_NAME).exists() and not pfile.exists()


def test_default_presets_file_is_the_checkouts_only_for_a_full_run(tmp_path):
    """A run on a crop or on some scenes writes beside its trials, never into the package."""
    every = tune.tuning_folders([], SCENES)   # tuning's scenes
    opts = tune.Options(out=tmp_path)
    assert tune.default_presets_file(every, SCENES, opts) == ROOT / tune.PACKAGE_PRESETS
    assert tune.default_presets_file(every[:2], SCENES, opts) == tmp_path / presets.TUNED_FILE
    opts.crop = crop_of(CROP)
    assert tune.default_presets_file(every, SCENES, opts) == tmp_path / presets.TUNED_FILE


@pytest.mark.parametrize("kind, said", [
    ("garbage", "the trial store {db} is not an SQLite database (aolab tune keeps its trials "
     "there): move it away or choose another --out"),
    ("fifo", "the trial store must be a regular file, got '{db}', which is a FIFO"),
    ("corrupt", "the trial store {db} cannot be used: file is not a database (move it away or "
     "choose another --out)"),
])
def test_a_bad_trial_store_is_one_line_naming_it(tmp_path, capsys, kind, said):
    """A garbage tune.db gave SQLAlchemy's text and a web link, a FIFO "disk I/O error";
    neither named the file."""
    import os
    db = tmp_path / tune.DB_NAME
    if kind == "fifo":
        os.mkfifo(db)
    else:   # garbage; or an SQLite header over garbage, which only SQLite itself refuses
        db.write_bytes((tune.SQLITE_MAGIC if kind == "corrupt" else b"") + b"garbage" * 50)
    assert cli.main(["tune", "--methods", "vao", "--trials", "1", "--out", str(tmp_path),
                     "--presets-file", str(tmp_path / "p.json"), *FAST]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("aolab: " + said.format(db=db)), err
    assert "sqlalche.me" not in err and not (tmp_path / "p.json").exists()


@pytest.mark.parametrize("kind, said", [
    ("folder", "--presets-file must be a regular file, got '{p}', which is a folder"),
    ("malformed", "tuned presets file {p}: \"methods\" must be a JSON object, got a list"),
])
def test_the_presets_file_is_checked_before_any_trial(tmp_path, capsys, kind, said):
    """--presets-file DIR (or a file it cannot merge into) was refused only after the first
    method's trials."""
    pfile = tmp_path / "p.json"
    if kind == "folder":
        pfile.mkdir()
    else:
        pfile.write_text('{"methods": []}')
    assert cli.main(["tune", "--methods", "vao", "--trials", "1", "--out", str(tmp_path / "t"),
                     "--presets-file", str(pfile), *FAST]) == 2
    assert capsys.readouterr().err.startswith("aolab: " + said.format(p=pfile))
    assert not (tmp_path / "t" / tune.DB_NAME).exists()   # no trial ran


def test_an_out_that_is_a_file_is_refused_naming_the_option(tmp_path, capsys):
    """It said "File exists" (the output folder's lock could not make it)."""
    (tmp_path / "file").write_text("x")
    assert cli.main(["tune", "--methods", "vao", "--trials", "1", "--out",
                     str(tmp_path / "file"), *FAST]) == 2
    assert capsys.readouterr().err == (f"aolab: --out must be a folder, got "
                                       f"'{tmp_path / 'file'}', which is a regular file\n")
