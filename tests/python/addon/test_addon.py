"""The Blender add-on (docs/blender_addon.md), in real Blender, headless: installed and
enabled by scripts/install_addon.sh into temporary user folders (the real preferences are
untouched), registered and unregistered cleanly, and its operators run on the tiny scene:
Preview, Render Reference (8 spp), a cancelled Render Reference, Compare. Their images and
metrics equal the command line's (`aolab run`) for the same inputs, and the user's scene is
exactly as before. Skipped with a reason where Blender is absent."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import aolab

ROOT = Path(__file__).resolve().parents[3]
TINY = ROOT / "tests" / "data" / "tiny_scene.py"
CHECK = ROOT / "tests" / "blender" / "addon_check.py"
from blender_support import BLENDER, BLENDER_VERSION  # noqa: E402

pytestmark = [pytest.mark.blender,
              pytest.mark.skipif(BLENDER is None, reason="Blender is not installed "
                                 "(scripts/install-deps.sh installs it)")]


#: A tuned preset of hbao that Blender is given (AOLAB_TUNED_PRESETS), as `aolab tune` writes.
TUNED = {"directions": 4, "steps": 6, "incremental_attenuation": True, "blur": True}


def blender_env(base: Path) -> dict:
    """Temporary Blender user folders, and the `aolab` this test imports placed first on
    Blender's path (with --python-use-system-env), so that Blender, its child processes and
    this test use one build."""
    aolab_dir = str(Path(aolab.__file__).resolve().parents[1])
    tuned = base / "tuned_presets.json"      # the preset menu offers the tuned presets too
    tuned.write_text(json.dumps({"methods": {"hbao": {"presets": {"tuned-100ms": TUNED}}}}))
    return dict(os.environ, BLENDER_USER_CONFIG=str(base / "config"),
                BLENDER_USER_SCRIPTS=str(base / "scripts"),
                BLENDER_USER_EXTENSIONS=str(base / "extensions"), AOLAB_TUNED_PRESETS=str(tuned),
                PYTHONPATH=os.pathsep.join([aolab_dir, os.environ.get("PYTHONPATH", "")]))


def run_blender(env, *args, factory=True, script=CHECK) -> dict:
    cmd = [BLENDER, "-b"] + (["--factory-startup"] if factory else []) + \
        ["-noaudio", "--python-use-system-env", "--python-exit-code", "1",
         "--python", str(script), "--", *args]
    res = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    lines = [line for line in res.stdout.splitlines() if line.startswith("RESULT ")]
    assert res.returncode == 0 and lines, res.stdout[-4000:] + res.stderr[-3000:]
    return json.loads(lines[-1][len("RESULT "):])


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    base = tmp_path_factory.mktemp("blender_user")
    env = blender_env(base)
    env["AOLAB_ADDON_ZIP"] = str(base / "aolab_blender.zip")
    res = subprocess.run([str(ROOT / "scripts" / "install_addon.sh")], capture_output=True,
                         text=True, env=env, timeout=120)
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    assert "AO Lab enabled" in res.stdout
    return base, env


def on_tiny_scene(installed, tmp_path_factory, name: str, mode: str,
                  script: Path = CHECK) -> tuple[dict, Path]:
    """A check script's mode run in Blender on the tiny scene, with a new cache and out/
    folder in a temporary `name` folder: (its RESULT, that folder)."""
    base, env = installed
    work = tmp_path_factory.mktemp(name)
    (work / "out").mkdir()
    return run_blender(env, mode, str(TINY), str(work / "cache"), str(work / "out"),
                       script=script), work


@pytest.fixture(scope="module")
def flow(installed, tmp_path_factory):
    return on_tiny_scene(installed, tmp_path_factory, "addon_flow", "flow")


def aolab_run(method, exr, out, *settings):
    cmd = [sys.executable, "-m", "aolab", "run", method, str(exr), "--out", str(out),
           "--json", str(out) + ".json"]
    for s in settings:
        cmd += ["--set", s]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stdout + res.stderr
    import OpenImageIO as oiio
    image = oiio.ImageBuf(str(out) + ".exr").get_pixels(oiio.FLOAT)
    return np.asarray(image)[..., 0], json.loads(Path(str(out) + ".json").read_text())


def cli_settings(run: dict) -> list[str]:
    return [f"{k}={v}" for k, v in run["settings"].items()]


def test_installs_enables_and_unregisters_cleanly(installed):
    base, env = installed
    r = run_blender(env, "installed", factory=False)  # the saved preferences enable it
    assert r["enabled"]
    # Blender 4.2+: an extension in the user repository; 3.4: a legacy add-on
    assert r["file"].startswith(str(base / "extensions" / "user_default" / "aolab_blender")
                                if BLENDER_VERSION >= (4, 2) else
                                str(base / "scripts" / "addons" / "aolab_blender"))
    for name in ("AOLAB_PT_sidebar", "AOLAB_PT_view_layer", "AOLAB_OT_preview",
                 "AOLAB_OT_render_reference", "AOLAB_OT_compare",
                 "AOLAB_AddonPreferences (is_registered)",
                 "Scene.aolab", "WindowManager.aolab"):
        assert name in r["registered_enabled"], name
    assert r["registered_disabled"] == []
    assert r["registered_reenabled"] == len(r["registered_enabled"])
    assert r["registered_disabled_again"] == []


def test_user_errors_are_reported(flow):
    r, _ = flow
    expected = {"compare_without_reference": "reference missing",
                "nothing_selected": "nothing selected", "not_built": "module not built: run "
                "scripts/setup.sh", "orthographic": "orthographic", "no_camera": "no camera",
                "zero_distance": "the world's AO distance is 0: set World > Ambient Occlusion",
                "huge_distance": "the world's AO distance is 3.40282e+38",
                "too_small": "Blender renders at least 4x4: raise the panel's Resolution",
                "cache_under_file": "cache_is_a_file' is an existing file",
                "save_copy_fails": "Preview: OSError: [Errno 28] No space left on device",
                "report_under_file": "cache_is_a_file' is an existing file"}
    for case, text in expected.items():
        assert r[case]["result"] == ["CANCELLED"], case
        assert text in r[case]["error"] and text in r[case]["message"], (case, r[case])
    assert r["cache_after_errors"] in (None, []), "a refused operation wrote into the cache"
    assert r["report"]["result"] == ["FINISHED"], r["report"]
    assert Path(r["report_path"]).name == "report.html" and Path(r["report_path"]).exists()
    from aolab import named_presets as presets
    assert r["presets"]["hbao"] == ["default"] + presets.preset_names("hbao") + ["tuned-100ms"]
    values, blur = presets.preset_values("hbao", "low")
    for k, v in {**values, "blur": blur}.items():  # the preset's values, the rest defaults
        assert r["hbao_low"][k] == pytest.approx(v), k
    defaults = {s["name"]: s["default"] for s in aolab.method_info("hbao")["settings"]}
    for k, v in {**defaults, **TUNED}.items():      # a tuned preset, chosen from the menu
        if k != "radius":
            assert r["hbao_tuned"][k] == pytest.approx(v), k
    assert r["hbao_default_again"] == {}
    assert "no window" in r["show_image_background"]["error"]


def test_preview_images_equal_the_command_line(flow):
    r, work = flow
    assert r["preview"]["result"] == ["FINISHED"], r["preview"]
    assert r["preview_diff"] == []
    runs = {run["method"]: run for run in r["settings_passed"]}
    assert runs["hbao"]["settings"] == {"directions": 4} and runs["lsao"]["settings"] == {}
    gbuffer = Path(r["preview_folder"]) / "reference.exr"
    assert json.loads(gbuffer.with_suffix(".json").read_text())["samples"] == 1
    for row in r["preview_table"]:
        info = r["preview_images"][row["method"]]
        assert info["size"] == [96, 54] and info["colorspace"] == "Non-Color" and info["grey"]
        assert row["ms"] > 0 and not row["has_metrics"]
        cli, _ = aolab_run(row["method"], gbuffer, work / f"cli_preview_{row['method']}",
                           *cli_settings(runs[row["method"]]))
        ours = np.load(work / "out" / f"preview_{row['method']}.npy")[..., 0]
        assert np.array_equal(ours, cli), row["method"]


def test_reference_render_and_cancel_leave_the_scene_as_before(flow):
    r, work = flow
    assert r["reference"]["result"] == ["FINISHED"] and "rendered" in r["reference"]["message"]
    assert r["reference_diff"] == []
    assert r["reference_again"]["result"] == ["FINISHED"]
    assert "found in the cache" in r["reference_again"]["message"]
    assert r["reference_again"]["seconds"] < 1.0
    side = json.loads((Path(r["reference_folder"]) / "reference.json").read_text())
    assert side["samples"] == 8 and (side["width"], side["height"]) == (96, 54)
    # Cancelled during the 4096-sample render: nothing changed, nothing half-written.
    assert "/4096 samples" in r["cancel_seen"]["stage"]
    assert r["cancel"]["result"] == ["CANCELLED"] and "cancelled" in r["cancel"]["message"]
    assert r["cancel"]["seconds"] < 60
    assert r["cancel_diff"] == []
    assert not [n for n in r["cache_after_cancel"] if n.startswith(".")]
    sides = [json.loads((work / "cache" / n / "reference.json").read_text())
             for n in r["cache_after_cancel"]]
    assert sorted(s["samples"] for s in sides) == [1, 8]


def test_compare_metrics_and_images_equal_the_command_line(flow):
    r, work = flow
    assert r["compare"]["result"] == ["FINISHED"], r["compare"]
    assert r["compare_folder"] == r["reference_folder"]
    runs = {run["method"]: run for run in r["settings_passed"]}
    reference = Path(r["reference_folder"]) / "reference.exr"
    for row in r["compare_table"]:
        method = row["method"]
        assert row["has_metrics"] and row["error_image"] == f"AO Lab {method} error"
        cli, result = aolab_run(method, reference, work / f"cli_compare_{method}",
                                *cli_settings(runs[method]))
        assert row["metrics"] == result["metrics"], method        # exact, every metric
        ours = np.load(work / "out" / f"compare_{method}.npy")[..., 0]
        assert np.array_equal(ours, cli), method
    expected = {"AO Lab hbao error", "AO Lab lsao error", "AO Lab reference"}
    assert expected <= set(r["compare_images"])
    # The error map is white where the method equals the reference, blue where lighter.
    g = aolab.load_gbuffer(reference)
    err = np.load(work / "out" / "error_hbao.npy")[..., :3]
    ao = np.load(work / "out" / "compare_hbao.npy")[..., 0]
    lighter = g.valid_mask() & (ao - g.reference > 0.25)
    if lighter.any():
        assert np.allclose(err[lighter], [0.1, 0.3, 0.9], atol=1e-6)
    assert r["registered_after_disable"] == []


# ---- Live preview (tests/blender/live_check.py) ----

LIVE_CHECK = ROOT / "tests" / "blender" / "live_check.py"


@pytest.fixture(scope="module")
def live(installed, tmp_path_factory):
    return on_tiny_scene(installed, tmp_path_factory, "addon_live", "live", LIVE_CHECK)


def live_expected(r: dict, method: str, shown: dict) -> np.ndarray:
    """aolab.compute of the settings an image was shown with, on the G-buffer Preview
    cached, in this process."""
    g = aolab.load_gbuffer(Path(r["gbuffer_folder"]) / "reference.exr")
    return aolab.compute(method, g, radius=shown["radius"], threads=2, blur=shown["blur"],
                         **shown["settings"])


def assert_live_image(r, work, name: str, method: str, shown: dict) -> None:
    ours = np.load(work / "out" / f"{name}.npy")
    assert np.array_equal(ours[..., 0], live_expected(r, method, shown)), name
    assert np.array_equal(ours[..., 0], ours[..., 2]) and np.all(ours[..., 3] == 1), name


def grew(step: dict, key: str) -> int:
    return step["stats"][key] - step["stats_before"][key]


def test_live_without_a_cached_gbuffer_says_so_and_computes_nothing(live):
    r, _ = live
    step = r["no_gbuffer"]
    assert r["no_gbuffer_timer"] and step["error"]
    assert "no G-buffer of this scene at 96x54 is cached" in step["message"]
    assert "click Preview" in step["message"]
    assert step["stats"]["computes"] == 0 and step["stats"]["applied"] == 0
    assert not [n for n in step["images"] if n.startswith("AO Lab")]
    assert "no G-buffer of this scene" in " ".join(step["panel"]), step["panel"]  # wrapped


def test_live_off_does_nothing(live):
    r, _ = live
    assert r["preview"] == ["FINISHED"]
    off = r["off"]
    assert not off["timer"] and not off["pending"] and not off["image"]
    assert off["stats"] == off["stats_before"]


def test_live_images_follow_the_settings_and_equal_compute(live):
    r, work = live
    on = r["on"]
    assert not on["error"] and on["kind"] == "Live"
    assert {m for m, _, _ in on["table"]} == {"hbao", "lsao"}
    assert on["hbao"]["settings"] == {"directions": 5}
    assert_live_image(r, work, "on_hbao", "hbao", on["hbao"])
    assert_live_image(r, work, "on_lsao", "lsao", on["lsao"])
    # One changed setting: one compute, its image, no button press.
    changed = r["changed"]
    assert r["changed_timer"]
    assert grew(changed, "computes") == 1 and grew(changed, "applied") == 1
    assert changed["hbao"]["settings"] == {"directions": 3}
    assert_live_image(r, work, "changed_hbao", "hbao", changed["hbao"])
    last = changed["last"]
    assert last["method"] == "hbao" and 0 < last["compute_ms"] <= last["total_ms"]
    assert changed["compute_ms"] == pytest.approx(last["compute_ms"], rel=1e-5)
    assert changed["total_ms"] == pytest.approx(last["total_ms"], rel=1e-5)
    assert "ms from the change to the image" in changed["message"]
    assert "Live: hbao" in changed["panel"], changed["panel"]   # the panel shows the times
    assert f"{last['total_ms']:.1f} ms change to image" in changed["panel"]
    # A preset sets every setting: one compute of the preset's values.
    preset = r["preset"]
    assert grew(preset, "computes") == 1 and grew(preset, "applied") == 1
    from aolab import named_presets as presets
    values, blur = presets.preset_values("hbao", "low")
    assert preset["hbao"]["blur"] == blur
    assert_live_image(r, work, "preset_hbao", "hbao", preset["hbao"])
    # The world's AO distance: every ticked method, through the depsgraph handler.
    world = r["world"]
    assert grew(world, "applied") == 2
    assert world["hbao"]["radius"] == pytest.approx(world["distance"])
    assert_live_image(r, work, "world_hbao", "hbao", world["hbao"])
    # R: every ticked method.
    radius = r["radius"]
    assert radius["hbao"]["radius"] == pytest.approx(0.6) and grew(radius, "applied") == 2
    assert_live_image(r, work, "radius_hbao", "hbao", radius["hbao"])
    assert_live_image(r, work, "radius_lsao", "lsao", radius["lsao"])
    # Unticked: out of the table, nothing computed.
    assert r["untick"]["table"] == ["hbao"] and grew(r["untick"], "computes") == 0


def test_live_coalesces_quick_changes_and_drops_stale_results(live):
    r, work = live
    quick = r["quick"]
    assert grew(quick, "computes") == 1 and grew(quick, "applied") == 1
    assert quick["hbao"]["settings"] == {"directions": 9, "steps": 3}
    assert quick["hbao"]["blur"] is True
    assert_live_image(r, work, "quick_hbao", "hbao", quick["hbao"])
    stale = r["stale"]   # changed while its compute ran: that result dropped, the latest shown
    assert grew(stale, "computes") == 2 and grew(stale, "dropped") == 1
    assert grew(stale, "applied") == 1
    assert stale["hbao"]["settings"] == {"steps": 3}   # 8 directions: the default
    assert_live_image(r, work, "stale_hbao", "hbao", stale["hbao"])


def test_live_cancels_a_stale_compute(live):
    r, _ = live
    slow = r["slow"]   # screen_space_limit changed while it computed
    assert grew(slow, "cancelled") == 1 and grew(slow, "dropped") == 1
    assert grew(slow, "applied") == 1 and slow["last"]["method"] == "screen_space_limit"
    # The stale compute stopped: the change was shown sooner than two full computes.
    assert slow["ms"] < 2 * r["slow_full_ms"], (slow["ms"], r["slow_full_ms"])


def test_live_notices_a_changed_scene(live):
    r, _ = live
    assert r["moved"]["error"] and "no G-buffer of this scene" in r["moved"]["message"]
    assert not r["moved_back"]["error"], r["moved_back"]


def test_live_unregisters_with_a_pending_timer(live):
    r, _ = live
    assert r["pending_before_disable"]
    after = r["after_disable"]
    assert not after["timer"] and after["handlers"] == [] and after["threads"] == []
    assert not after["wm_aolab"]


# ---- Live converges while nothing changes (live_check.py's accumulate mode) ----

FRAMES = 6   # Accumulate in the test: enough frames to tell a mean from one frame, quickly


@pytest.fixture(scope="module")
def live_accumulated(installed, tmp_path_factory):
    base, env = installed
    work = tmp_path_factory.mktemp("addon_live_accumulate")
    (work / "out").mkdir()
    return run_blender(env, "accumulate", str(TINY), str(work / "cache"), str(work / "out"),
                       str(FRAMES), script=LIVE_CHECK), work


def live_frames(r: dict, method: str, shown: dict, n: int) -> list[np.ndarray]:
    """aolab.compute of frames 0 .. n-1 (per-frame seeds) of the settings an image was
    shown with, on the G-buffer Preview cached, in this process."""
    g = aolab.load_gbuffer(Path(r["gbuffer_folder"]) / "reference.exr")
    return [aolab.compute(method, g, radius=shown["radius"], threads=2, blur=shown["blur"],
                          frame=k, **shown["settings"]) for k in range(n)]


def assert_accumulated(r, work, name: str, method: str, shown: dict, n: int) -> None:
    """The image `name` is the running mean of the first n frames: bit for bit what
    aolab.accumulate makes of them (alpha 0, no clamp, zero motion), and within 1e-6 of
    their mean in double (one float rounding per frame)."""
    frames = live_frames(r, method, shown, n)
    g = aolab.load_gbuffer(Path(r["gbuffer_folder"]) / "reference.exr")
    history, motion = aolab.TemporalHistory(), np.zeros(frames[0].shape + (2,), np.float32)
    for ao in frames:
        ours, _ = aolab.accumulate(ao, g, motion, history, threads=2, alpha=0.0,
                                   clamp="off", max_history=FRAMES)
    shown_ao = np.load(work / "out" / f"{name}.npy")[..., 0]
    assert np.array_equal(shown_ao, ours), name
    mean = np.mean(np.stack(frames).astype(np.float64), axis=0)
    assert np.max(np.abs(shown_ao - mean)) < 1e-6, name
    if n > 1:   # the frames differ: the mean is no single frame
        assert not np.array_equal(shown_ao, frames[0]), name


def test_live_converges_to_the_mean_of_its_frames_then_stops(live_accumulated):
    r, work = live_accumulated
    assert r["default_frames"] == 16 and r["preview"] == ["FINISHED"]
    done = r["converged"]
    assert not done["error"] and not done["timer"] and done["accum"] == []
    # Frames 0 .. FRAMES-1 of each seeded method, one per compute, interleaved; chebyshev
    # (no seed) once.
    shown = done["updates"]
    for m in ("hbao", "lsao"):
        assert [k for mm, k in shown if mm == m] == list(range(FRAMES)), shown
    assert [k for mm, k in shown if mm == "chebyshev"] == [0]
    # Frame 0 of every method in one worker (as before), then one worker per frame.
    assert grew(done, "applied") == 2 * FRAMES + 1
    assert grew(done, "computes") == 1 + 2 * (FRAMES - 1) == 1 + grew(done, "frames")
    assert (done["frame"], done["goal"]) == (FRAMES, FRAMES)
    assert any(f"frame {FRAMES}/{FRAMES}" in line for line in done["panel"]), done["panel"]
    for m in ("hbao", "lsao"):
        assert_accumulated(r, work, f"converged_{m}", m, done[m], FRAMES)
    assert np.array_equal(np.load(work / "out" / "converged_chebyshev.npy")[..., 0],
                          live_expected(r, "chebyshev", done["chebyshev"]))
    # Converged: no timer, and a stray call of it computes nothing.
    assert r["idle_tick"] is None and not r["idle"]["pending"]
    assert r["idle"]["stats"] == r["idle"]["stats_before"]


def test_live_restarts_at_frame_0_after_a_change(live_accumulated):
    r, work = live_accumulated
    partial = r["partial"]   # 3 frames of directions = 4
    assert partial["hbao"]["settings"] == {"directions": 4}
    assert_accumulated(r, work, "partial_hbao", "hbao", partial["hbao"], 3)
    assert any(f"frame 3/{FRAMES}" in line for line in partial["panel"]), partial["panel"]
    # Changed mid-way: the image is the single frame 0 of the new value (compute's bits, as
    # Live showed before accumulation), then the mean of its own frames only.
    reset = r["reset"]
    assert r["reset_first"]["frame"] == 0 and reset["hbao"]["settings"] == {"directions": 5}
    ours = np.load(work / "out" / "reset_hbao.npy")[..., 0]
    assert np.array_equal(ours, live_expected(r, "hbao", reset["hbao"]))
    assert_accumulated(r, work, "reset_converged_hbao", "hbao", reset["hbao"], FRAMES)
    assert [k for m, k in reset["updates"] if m == "hbao"] == list(range(FRAMES))
    assert {m for m, _ in reset["updates"]} == {"hbao"}   # the others stay converged
    # Unticked while converging: no further frame of it, the others go on to the end.
    untick = r["untick"]
    assert "lsao" not in {m for m, _ in untick["updates"]} and "lsao" not in untick["table"]
    assert [k for m, k in untick["updates"] if m == "hbao"][-1] == FRAMES - 1, untick
    # The object moved while converging: stopped, the panel says Preview must export it.
    moved = r["moved"]
    assert moved["error"] and "no G-buffer of this scene" in moved["message"]
    assert moved["accum"] == [] and len(moved["updates"]) <= 1, moved["updates"]
    # Accumulate changed: every ticked method from frame 0, to its new count.
    changed = r["frames_changed"]
    assert sorted(map(tuple, changed["updates"])) == [
        ("chebyshev", 0), ("hbao", 0), ("hbao", 1), ("lsao", 0), ("lsao", 1)]
    assert_accumulated(r, work, "two_hbao", "hbao", changed["hbao"], 2)


def test_live_says_an_error_and_blends_each_channel_of_an_rgb_result(live_accumulated):
    r, work = live_accumulated
    bad = r["rgb_error"]   # colour bleeding without a colour pass: said, nothing more done
    assert bad["error"] and bad["message"].startswith("vao_pp: color is required"), bad
    assert "Traceback" not in bad["message"]
    assert bad["updates"] == [] and bad["accum"] == [] and not bad["timer"]
    assert not bad["image"] and grew(bad, "computes") == 1
    # The worker's blend of RGB frames: each channel as aolab.accumulate blends it alone.
    g = aolab.load_gbuffer(Path(r["gbuffer_folder"]) / "reference.exr")
    hbao = [aolab.compute("hbao", g, radius=0.75, threads=2, frame=k) for k in range(5)]
    ours = np.load(work / "out" / "rgb.npy")
    motion = np.zeros(hbao[0].shape + (2,), np.float32)
    for c in range(3):
        history = aolab.TemporalHistory()
        for k in range(3):
            alone, _ = aolab.accumulate(hbao[k + c], g, motion, history, threads=2,
                                        alpha=0.0, clamp="off", max_history=3)
        assert np.array_equal(ours[..., c], alone), c


def test_manifest_and_bl_info_agree():
    """The extension's manifest (Blender 4.2+) and the legacy bl_info (3.4) describe one
    add-on: the same name, version and category; the manifest's id is the module name."""
    import ast
    import tomllib
    folder = ROOT / "blender_addon" / "aolab_blender"
    manifest = tomllib.loads((folder / "blender_manifest.toml").read_text())
    tree = ast.parse((folder / "__init__.py").read_text())
    bl_info = next(ast.literal_eval(n.value) for n in tree.body if isinstance(n, ast.Assign)
                   and getattr(n.targets[0], "id", None) == "bl_info")
    assert manifest["id"] == folder.name and manifest["type"] == "add-on"
    assert manifest["name"] == bl_info["name"]
    assert manifest["version"] == ".".join(str(v) for v in bl_info["version"])
    assert manifest["tags"] == [bl_info["category"]]
    assert tuple(int(v) for v in manifest["blender_version_min"].split(".")) >= (4, 2, 0)
    assert bl_info["blender"] < (4, 2, 0)   # below it, Blender reads bl_info


# ---- Scenes the methods cannot see or score (tests/blender/hostile_check.py) ----

HOSTILE_CHECK = ROOT / "tests" / "blender" / "hostile_check.py"


@pytest.fixture(scope="module")
def hostile(installed, tmp_path_factory):
    base, env = installed
    work = tmp_path_factory.mktemp("addon_hostile")
    r = run_blender(env, "hostile", str(TINY), str(work / "cache"), str(work),
                    script=HOSTILE_CHECK)
    return r, work


@pytest.mark.parametrize("case, said", [
    ("zero_scale", "camera 'Camera' is scaled to zero (world scale 0, 0, 0)"),
    ("infinite_location", "camera 'Camera' is at the world location (3.40282e+38, -2.5, 1.8), "
     "beyond +-1.844e+18 along an axis")])
def test_a_degenerate_camera_is_refused_by_every_operation(hostile, case, said):
    """Scaled to zero, its sidecar held NaN (no JSON reader takes it) and broke the cache's
    entry; at 1e39 (Blender stores the largest float32), Blender died rendering from it and
    the operators said "Blender failed:". Both are refused, naming the camera, before any
    work."""
    r, _ = hostile
    for op in ("preview", "render_reference", "compare", "write_report"):
        step = r[case][op]
        assert step["result"] == ["CANCELLED"], (case, op, step)
        assert said in step["message"] and said in step["error"], (case, op, step)
        assert "Traceback" not in step["error"], (case, op)
    assert r[case]["live"]["error"] and said in r[case]["live"]["message"]
    assert r["cache_after_camera"], "a refused operation wrote into the cache"


def test_a_huge_object_works(hostile):
    r, _ = hostile
    for op in ("preview", "render_reference", "compare", "write_report"):
        assert r["huge"][op]["result"] == ["FINISHED"], (op, r["huge"][op])
    metrics = r["huge"]["metrics"]
    assert len(metrics) == 2 and all(0 <= m["mae"] <= 1 for m in metrics), metrics
    huge = r["huge"]["live"]   # two methods, each converged over Accumulate frames
    assert not huge["error"] and huge["applied"] == 2 * huge["frames"] == 32, huge


@pytest.mark.parametrize("case", ["sky", "empty"])
def test_nothing_in_the_frame_renders_and_says_there_is_nothing_to_score(hostile, case):
    """Compare said TypeError: 'NoneType' object is not subscriptable; it now says what Write
    HTML Report says (aolab compare's words)."""
    r, _ = hostile
    steps = r[case]
    assert steps["preview"]["result"] == ["FINISHED"], steps["preview"]
    assert steps["render_reference"]["result"] == ["FINISHED"], steps["render_reference"]
    for op in ("compare", "write_report"):
        assert steps[op]["result"] == ["CANCELLED"], (op, steps[op])
        assert "reference.exr has no geometry pixel" in steps[op]["message"], (op, steps[op])
        assert "Traceback" not in steps[op]["error"], (op, steps[op]["error"])
    assert steps["compare"]["message"].startswith("nothing to compare: ")
    live = steps["live"]
    assert not live["error"] and live["applied"] == 2 * live["frames"] == 32, live


def test_a_bad_tuned_presets_file_keeps_the_built_in_presets(hostile):
    r, work = hostile
    bad = r["bad_tuned"]
    assert bad["tuned_before"] == ["tuned-100ms"]
    from aolab import named_presets as presets
    assert bad["menu"] == ["default"] + presets.preset_names("hbao")
    said = f"tuned presets file {work / 'tuned_bad.json'}: preset name 'tuned-xms'"
    assert bad["apply_message"].startswith("Preset: " + said), bad["apply_message"]
    panel = " ".join(bad["panel"])   # wrapped into lines at spaces
    assert "tuned presets left out of the menus: " + said in panel, bad["panel"]
    assert bad["low"] == {"directions": 4, "steps": 4, "blur": True}


# ---- Quick Compare and Advise (tests/blender/advise_check.py) ----

ADVISE_CHECK = ROOT / "tests" / "blender" / "advise_check.py"


@pytest.fixture(scope="module")
def advise_flow(installed, tmp_path_factory):
    return on_tiny_scene(installed, tmp_path_factory, "addon_advise", "flow", ADVISE_CHECK)


def test_quick_compare_scores_against_rtao_as_python_does(advise_flow):
    """Quick Compare exports the G-buffer with the scene's triangles (1 sample, cached: the
    second click renders nothing), traces rtao at 64 rays and scores the ticked methods: its
    reference image, every metric and every image equal what aolab computes from the same
    files in this process, bit for bit; the panel labels the scores and states the noise.
    Without a camera it is refused before anything is cached; the scene is left as it was."""
    from aolab.study import quick_reference
    r, work = advise_flow
    for case in ("quick_no_camera", "advise_no_camera"):
        assert r[case]["result"] == ["CANCELLED"] and "no camera" in r[case]["message"], r[case]
    assert r["cache_after_errors"] == []
    assert r["quick"]["result"] == ["FINISHED"], r["quick"]
    assert r["quick_diff"] == []
    session = r["quick_session"]
    assert session["kind"] == "Quick Compare" and session["reference"] == "quick (rtao 64 rays)"
    assert "quick (rtao 64 rays)" in r["quick"]["message"]
    folder = Path(session["gbuffer_folder"])
    side = json.loads((folder / "reference.json").read_text())
    assert "mesh" in side["passes"] and side["samples"] == 1
    assert (folder / "reference.mesh").exists()
    g = aolab.load_gbuffer(folder / "reference.exr")
    quick = quick_reference.quick(g, radius=r["quick_radius"], rays=64, threads=2)
    assert session["noise"] == pytest.approx(quick.noise, rel=1e-6)
    ref_image = np.load(work / "out" / "quick_reference.npy")[..., 0]
    assert np.array_equal(ref_image, quick.ao)
    g.reference = quick.ao
    mask = g.valid_mask() & np.isfinite(quick.ao)
    runs = {run["method"]: run for run in r["quick_settings"]}
    for row in r["quick_table"]:
        run = runs[row["method"]]
        ao = aolab.compute(row["method"], g, radius=r["quick_radius"], threads=2,
                           blur=run["blur"], **run["settings"])
        assert row["metrics"] == dict(aolab.metrics(ao, quick.ao, mask)), row["method"]
        assert np.array_equal(np.load(work / "out" / f"quick_{row['method']}.npy")[..., 0], ao)
    assert r["quick_again"]["result"] == ["FINISHED"]
    assert [row["metrics"] for row in r["quick_again_table"]] == \
        [row["metrics"] for row in r["quick_table"]]
    assert len(r["cache_after_quick"]) == 1


def test_advise_names_the_best_configuration_and_applies_it(advise_flow):
    """Advise runs every method's presets against the quick reference, draws the front (an
    image and the panel's preview), names a configuration within a budget in the panel,
    and Apply ticks that method and puts its preset's values into its settings; a preset
    the menu lacks is refused. With the Cycles reference cached, Advise scores against it,
    and Compare states its noise too. Disabling the add-on frees the preview."""
    from aolab.study import tune
    r, _ = advise_flow
    assert r["advise"]["result"] == ["FINISHED"], r["advise"]
    a = r["advice"]
    assert a["reference"]["kind"] == "quick" and a["reference"]["samples"] == 64
    assert set(a["methods"]) == set(tune.default_methods()) and a["refused"] == []
    assert a["trials"] >= len(a["methods"]) and (a["width"], a["height"]) == (96, 54)
    assert r["front_image"] == r["front_preview"] and 0.5 < r["front_preview_pixels"] < 1
    assert "Which method for this scene?" in r["panel"]
    assert any(t.startswith("Within 16 ms") or t.startswith("No advice within 16 ms")
               for t in r["panel"]), r["panel"]
    assert r["picks"][str(1e6)] is not None   # without a budget, something is the best
    applied = r["applied"]
    assert r["apply"]["result"] == ["FINISHED"] and applied["use_method"]
    assert applied["menu"] == applied["preset"]
    values, blur = aolab.named_presets.preset_values(applied["method"], applied["preset"])
    for k, v in values.items():
        assert applied["settings"][k] == pytest.approx(v), k
    assert applied["use_blur"] == blur
    assert r["apply_unknown"]["result"] == ["CANCELLED"]
    assert r["advise_cycles"]["result"] == ["FINISHED"], r["advise_cycles"]
    assert r["advice_cycles_reference"]["label"] == "Cycles 8 spp"
    assert r["compare"]["result"] == ["FINISHED"]
    assert r["compare_session"]["reference"] == "Cycles 8 spp"
    assert r["compare_session"]["noise"] > 0
    assert not r["preview_after_disable"]
