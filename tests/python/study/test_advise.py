"""The quick reference and Advise (aolab.study.quick_reference, aolab.study.advise, `aolab
advise`; docs/comparison.md, "Advise"): the stated noise bounds what it does to a score, on
known answers and on a committed scene against its Cycles reference; the advice is the
guarded best within the budget and never a degenerate output; the command answers bad input
with one line and exit status 2."""
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab.scenes import Crop, load_cropped
from aolab.scoring import reference_noise
from aolab.study import advise, budget, quick_reference, runner, tune
from aolab.util.arguments import parse_budget

ROOT = Path(__file__).resolve().parents[3]
SCENES = ROOT / "reference_scenes"
TINY_SCENE = ROOT / "tests" / "data" / "tiny_scene.py"
BLENDER = shutil.which("blender")
from cli_support import assert_one_error_line, status_of  # noqa: E402


# --- the noise a reference of N binary rays puts on an MAE: known answers ---------------------

def binomial_reference(truth: np.ndarray, rays: int, seed: int = 0) -> np.ndarray:
    """Each pixel the mean of `rays` independent binary rays of mean `truth`."""
    rng = np.random.default_rng(seed)
    return (rng.binomial(rays, truth) / rays).astype(np.float32)


@pytest.mark.parametrize("rays", [16, 64, 256])
def test_an_exact_method_reads_the_noise_and_a_far_one_reads_nothing(rays):
    """Against a binomial reference an exact method's MAE is the reference's mean absolute
    noise, which reference_noise estimates from the reference alone (within 5 %: the normal
    approximation of a binomial at these N); a method off by 0.5 everywhere loses nothing to
    the noise (within 2 % of 0.5). Stratified rays are less noisy: an upper estimate there."""
    truth = np.linspace(0.05, 1.0, 200_000).reshape(400, 500)
    ref = binomial_reference(truth, rays)
    mask = np.ones(truth.shape, bool)
    noise = reference_noise(ref, rays, mask)
    exact = float(np.mean(np.abs(truth - ref)))
    assert noise == pytest.approx(exact, rel=0.05)
    off = np.clip(truth + 0.5, 0, 2)   # never within the noise of the reference
    assert float(np.mean(np.abs(off - ref))) == pytest.approx(np.mean(np.abs(off - truth)),
                                                              rel=0.02)
    assert reference_noise(ref, 1, mask) is None and reference_noise(ref, rays, ~mask) is None
    assert reference_noise(np.ones_like(ref), rays, mask) == 0.0   # unoccluded: exactly 1


@pytest.mark.parametrize("rays", [16, 64, 255])
def test_the_inflation_estimated_from_two_halves_bounds_what_the_noise_adds(rays):
    """A reference averaged from two independent halves of the rays (as the quick one is):
    Reference.inflation estimates, from the output alone, how much its MAE reads high — the
    whole noise for an exact output (within 10 %), nearly nothing for one far off, and for
    one off by about the noise's spread at least what the noise adds (the estimate is an
    upper one) and well below the reference's noise."""
    truth = np.linspace(0.2, 0.9, 200_000).reshape(400, 500)
    n1, n2 = rays // 2, rays - rays // 2
    h1, h2 = binomial_reference(truth, n1, seed=1), binomial_reference(truth, n2, seed=2)
    ref = ((n1 * h1.astype(np.float64) + n2 * h2) / rays).astype(np.float32)
    mask = np.ones(truth.shape, bool)
    r = quick_reference.Reference("quick", ref, rays, reference_noise(ref, rays, mask), None,
                                  halves=((n1, h1), (n2, h2)))
    for off, low, high in ((0.0, 0.9, 1.1), (0.3, 0.0, 0.1)):
        ao = (truth + off).astype(np.float32)
        added = float(np.mean(np.abs(ao - ref)) - np.mean(np.abs(ao - truth)))
        got = r.inflation(ao, mask)
        if off == 0.0:
            assert got == pytest.approx(added, rel=0.1)
            assert added == pytest.approx(r.noise, rel=0.05)
        else:
            assert got <= high * r.noise and abs(added) < 0.01 * r.noise
    spread = float(np.mean(np.sqrt(truth * (1 - truth) / rays)))
    ao = (truth + spread).astype(np.float32)
    added = float(np.mean(np.abs(ao - ref)) - np.mean(np.abs(ao - truth)))
    got = r.inflation(ao, mask)
    assert 0.9 * added <= got < 0.8 * r.noise, (added, got, r.noise)
    assert r.inflation(ao, ~mask) is None
    assert quick_reference.Reference("cycles", ref, rays, None, None).inflation(ao, mask) is None


# --- the quick reference against the Cycles reference on committed scenes ---------------------

#: Committed scenes with their triangles (reference.mesh) and of other families.
NOISE_SCENES = ("room", "organic_duck")


@pytest.fixture(scope="module", params=NOISE_SCENES)
def both_references(request):
    g, reference, radius, _ = load_cropped(SCENES / request.param)
    cycles = quick_reference.cycles(g)
    quick = quick_reference.quick(g, radius=radius, rays=quick_reference.QUICK_RAYS, threads=0)
    return request.param, g, radius, cycles, quick


def test_scores_against_the_quick_reference_lie_within_the_stated_noise(both_references):
    """Every method (its defaults and its medium preset) scored against rtao at 64 rays and
    against the committed Cycles reference (1024 spp). Each score reads high by between 0
    and its reference's noise (scoring.reference_noise), so the quick score minus the Cycles
    score lies in [-n_cycles, n_quick]: within the quick reference's stated noise of the Cycles
    score, as the panel says. The bound is the formula's, nothing fitted. On the whole frame
    (Quick Compare's MAE) and on each reference's occluded region (Advise's). On the whole
    frame the output's own estimate from the two halves (Reference.inflation) bounds the
    difference too; on the occluded region it does not have to, as the region itself moves
    with the reference's noise."""
    name, g, radius, cycles, quick = both_references
    assert quick.label == "quick (rtao 64 rays)" and cycles.label == "Cycles 1024 spp"
    assert 0 < cycles.noise < quick.noise < 0.05, (cycles.noise, quick.noise)
    on_cycles = runner.make_scene(name, g, cycles.ao, radius)
    on_quick = runner.make_scene(name, g, quick.ao, radius)
    checked = []
    for method in tune.default_methods():
        for preset in ("default", "medium"):
            if preset not in aolab.presets(method):
                continue
            values, blur = aolab.named_presets.preset_values(method, preset)
            run = runner.run_configuration(method, values, on_cycles, runner.Timing(0, 1))
            ao = runner.score_outputs(run, on_cycles, runner.Timing(0, 1), [blur]).output(blur).ao
            a, b = runner.trial_scores(ao, on_quick), runner.trial_scores(ao, on_cycles)
            own = quick.inflation(ao, on_quick.valid)
            assert a["all_mae"] - b["all_mae"] <= own, (method, preset, a, b, own)
            for key, n_quick, n_cycles in (("all_mae", quick.noise, cycles.noise),
                                           ("mae", quick.noise_occluded,
                                            cycles.noise_occluded)):
                diff = a[key] - b[key]
                checked.append((method, preset, key, diff, n_quick))
                assert -n_cycles <= diff <= n_quick, (method, preset, key, a[key], b[key],
                                                      n_cycles, n_quick)
    assert len(checked) >= 2 * len(tune.default_methods())
    print(name, [(m, p, k, f"{d:+.5f}", f"{n:.5f}") for m, p, k, d, n in checked])


def test_quick_reference_is_refused_without_its_triangles(tmp_path):
    g = aolab.analytic_scene("plane", 32, 18)
    with pytest.raises(ValueError, match="mesh"):
        quick_reference.quick(g, radius=1.0)
    mesh = type("Mesh", (), {"info": {}})()
    mesh.vertices, mesh.triangles = aolab.analytic_scene_mesh("plane")
    with pytest.raises(ValueError, match="rays must be an integer in \\[2, 65536\\]"):
        quick_reference.quick(g, mesh, radius=1.0, rays=1)
    got = quick_reference.quick(g, mesh, radius=1.0, rays=4)
    assert got.kind == "quick" and np.all(got.ao == 1.0) and got.noise == 0.0


# --- the advice -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def room_advice():
    """Advise on a 320x180 crop of the room (the panel's default size) against its Cycles
    reference: every method, every preset."""
    g, reference, radius, _ = load_cropped(SCENES / "room", Crop(320, 180))
    result = advise.run(g, quick_reference.cycles(g), radius, name="room", threads=0)
    return result


def test_the_advice_is_the_guarded_best_within_the_budget(room_advice):
    """Per budget the advice fits it, passes its method's whole-frame guard, and no other
    admissible configuration within the budget has a lower occluded MAE (checked by brute
    force); those named beside it lie within the reference's noise of it."""
    r = room_advice
    assert r["trials"] and not r["refused"], r["refused"]
    assert {t["method"] for t in r["trials"]} == set(tune.default_methods())
    ok = {t["number"] for t in advise.contenders(r)}
    noise = r["reference"]["noise_occluded"]
    for budget_ms in advise.BUDGETS_MS + (1000.0,):
        got = advise.choose(r, budget_ms)
        fits = [t for t in r["trials"] if t["number"] in ok and
                t["scenes"]["room"]["ms"] <= budget_ms]
        if not fits:
            assert got["best"] is None and got["why"], budget_ms
            continue
        best = got["best"]
        assert best["number"] in ok and best["scenes"]["room"]["ms"] <= budget_ms
        assert best["scenes"]["room"]["mae"] == min(t["scenes"]["room"]["mae"] for t in fits)
        for t in got["as_good"]:   # against Cycles: within the reference's noise
            assert advise.reads_high(r, t) == noise
            assert t["scenes"]["room"]["mae"] - best["scenes"]["room"]["mae"] <= noise
        for t in got["others"]:
            assert t["scenes"]["room"]["mae"] - best["scenes"]["room"]["mae"] > noise
        lines = advise.advice_lines(r, budget_ms)
        assert best["label"] in lines[0] and f"within {budget_ms:g} ms" in lines[0]
    front = advise.front(r)
    assert front and all(a["scenes"]["room"]["ms"] <= b["scenes"]["room"]["ms"] and
                         a["scenes"]["room"]["mae"] > b["scenes"]["room"]["mae"]
                         for a, b in zip(front, front[1:]))


def test_a_degenerate_output_never_wins(room_advice):
    """Flat grey at the occluded region's median reference, and all white (AO = 1), both
    instantly: with no guard the grey one is a valid choice within any budget, but on the whole
    frame it is worse than drawing no occlusion, so the guard (runner.whole_frame_ok) keeps
    it out of every budget's advice and off the front; white is no better than itself on the
    occluded region, which the advice requires."""
    r = json.loads(json.dumps(room_advice))   # a copy
    g, reference, radius, _ = load_cropped(SCENES / "room", Crop(320, 180))
    sc = runner.make_scene("room", g, reference, radius)
    grey = np.full(reference.shape, float(np.median(reference[sc.occluded])), np.float32)
    for number, (name, ao) in enumerate((("grey", grey), ("white", np.ones_like(grey))),
                                        start=len(r["trials"])):
        scores = {**runner.trial_scores(ao, sc), "ms": 0.01, "measured_ms": 0.01}
        r["trials"].append({"number": number, "method": name, "preset": "default",
                            "names": ["default"], "label": name, "settings": {},
                            "scenes": {"room": scores}})
    grey_trial = r["trials"][-2]
    assert budget.choose([grey_trial], ["room"], 16, budget.Guard()) is grey_trial
    for budget_ms in advise.BUDGETS_MS:
        got = advise.choose(r, budget_ms)
        named = [got["best"]] + got["as_good"] + got["others"]
        assert not any(t is not None and t["method"] in ("grey", "white") for t in named)
    assert not any(t["method"] in ("grey", "white") for t in advise.front(r))


def test_the_front_is_drawn(room_advice):
    image = advise.plot(room_advice, size=(600, 400))
    assert image.shape == (400, 600, 4) and image.dtype == np.float32
    assert 0 <= image.min() and image.max() <= 1 and image[..., :3].std() > 0.05


def test_configurations_merge_presets_that_compute_the_same():
    configs, notes = advise.configurations(["hbao", "sao"])
    assert notes == []
    names = {c["method"]: [] for c in configs}
    for c in configs:
        names[c["method"]].append(c["names"])
    for method in ("hbao", "sao"):
        flat = [n for group in names[method] for n in group]
        assert sorted(flat) == sorted(aolab.presets(method)), method


@pytest.mark.parametrize("text, ms", [("16ms", 16.0), ("33 ms", 33.0), ("100", 100.0),
                                      ("8.5ms", 8.5)])
def test_budgets_are_read_in_ms(text, ms):
    assert parse_budget(text) == ms


@pytest.mark.parametrize("text", ["fast", "0ms", "-16ms", "16s", "nan", "inf", "", "1e9",
                                  "16msms"])
def test_an_unknown_budget_is_one_line_and_status_2(capsys, monkeypatch, tmp_path, text):
    monkeypatch.setenv("AOLAB_BLENDER", str(tmp_path / "no_blender"))
    assert status_of(["advise", str(TINY_SCENE), f"--budget={text}"]) == 2
    assert_one_error_line(capsys.readouterr().err, "--budget must be a time per 1280x720 "
                          "frame in ms")


def test_no_blender_is_one_line_and_status_2(capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("AOLAB_BLENDER", str(tmp_path / "no_blender"))
    assert status_of(["advise", str(TINY_SCENE), "--cache", str(tmp_path / "cache")]) == 2
    assert_one_error_line(capsys.readouterr().err, "Blender not found")


@pytest.mark.parametrize("argv, said", [
    (["advise", "no_such_scene"], "no such scene: no_such_scene"),
    (["advise", "reference_scenes/room/reference.exr", "--scale", "50"], "--scale applies to"),
    (["advise", "reference_scenes/room/reference.exr", "--radius", "2"],
     "--radius applies to"),
    (["advise", "reference_scenes/room/reference.exr", "--reference", "best"],
     "--reference must be one of auto, cycles, quick"),
    (["advise", "reference_scenes/room/reference.exr", "--methods", "nope"],
     "method 'nope' is not one of"),
    (["advise", "reference_scenes/room/reference.exr", "--plot", "front.svg"],
     "--plot must name a .png file"),
])
def test_other_bad_input_is_one_line_and_status_2(capsys, monkeypatch, argv, said):
    monkeypatch.chdir(ROOT)
    assert status_of(argv) == 2
    assert_one_error_line(capsys.readouterr().err, said)


def test_advise_on_a_committed_gbuffer(tmp_path, monkeypatch, capsys):
    """A G-buffer .exr is advised on as it is: against its Cycles AO pass, or rtao against
    its triangles with --reference quick; the advice per budget, the JSON and the PNG."""
    monkeypatch.chdir(ROOT)
    out = tmp_path / "advice.json"
    argv = ["advise", "reference_scenes/room/reference.exr", "--methods", "sao", "alchemy",
            "--budget", "33ms", "--budget", "100ms", "--json", str(out),
            "--plot", str(tmp_path / "front.png")]
    assert status_of(argv) == 0
    text = capsys.readouterr().out
    assert "against Cycles 1024 spp" in text and "within 33 ms per 1280x720 frame" in text
    data = json.loads(out.read_text())
    assert set(data["advice"]) == {"33ms", "100ms"} and data["reference"]["kind"] == "cycles"
    assert (tmp_path / "front.png").stat().st_size > 1000
    assert status_of(argv[:5] + ["--reference", "quick", "--budget", "100ms"]) == 0
    assert "against quick (rtao 64 rays)" in capsys.readouterr().out


# --- with Blender: a .blend or build script rendered at the panel's size ----------------------

needs_blender = pytest.mark.skipif(BLENDER is None, reason="Blender is not installed "
                                   "(scripts/install-deps.sh installs it)")


def aolab_env() -> dict:
    package = str(Path(aolab.__file__).resolve().parents[1])
    return dict(os.environ, PYTHONPATH=os.pathsep.join([package,
                                                        os.environ.get("PYTHONPATH", "")]))


@pytest.mark.blender
@needs_blender
def test_a_scene_without_a_camera_is_one_line_and_status_2(tmp_path):
    script = tmp_path / "no_camera.py"
    script.write_text("import bpy\nbpy.ops.mesh.primitive_plane_add()\n"
                      "bpy.context.scene.world = bpy.data.worlds.new('W')\n")
    res = subprocess.run([sys.executable, "-m", "aolab", "advise", str(script), "--cache",
                          str(tmp_path / "cache")], capture_output=True, text=True,
                         timeout=300, env=aolab_env())
    assert res.returncode == 2, res.stdout + res.stderr
    assert_one_error_line(res.stderr, "has no camera")


@pytest.mark.blender
@needs_blender
def test_advise_renders_a_build_script_at_the_panels_size(tmp_path):
    """The tiny scene's build script at 50 %: Blender renders its G-buffer and triangles at
    48x27 (cached: the second run renders nothing), scored against the quick reference."""
    cmd = [sys.executable, "-m", "aolab", "advise", str(TINY_SCENE), "--scale", "50",
           "--cache", str(tmp_path / "cache"), "--methods", "hbao", "gtao", "--json",
           str(tmp_path / "a.json")]
    for _ in range(2):
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=aolab_env())
        assert res.returncode == 0, res.stdout + res.stderr
    data = json.loads((tmp_path / "a.json").read_text())
    assert (data["width"], data["height"]) == (48, 27) and data["radius"] == 0.75
    assert data["reference"]["kind"] == "quick" and data["reference"]["samples"] == 64
    assert len(os.listdir(tmp_path / "cache")) == 1
    assert "within 16 ms per 1280x720 frame" in res.stdout


def test_the_addon_offers_the_studys_budgets_and_rays():
    """The add-on takes its budgets and rays from aolab.study (its library's copies are for a
    missing aolab only)."""
    text = (ROOT / "blender_addon" / "aolab_blender" / "library.py").read_text()
    assert f"else {advise.BUDGETS_MS}" in text
    assert f"else {quick_reference.QUICK_RAYS}" in text
    assert math.isclose(runner.hd_scale(320, 180), 16.0)
