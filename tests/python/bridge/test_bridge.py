"""The Blender bridge: intrinsics, pass selection, export and reference renders, scene
restoration, `aolab reference` (cache, errors, --disable-autoexec). Blender runs for real,
headless; these tests skip with a reason where it is absent."""
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab.bridge.intrinsics import intrinsics
from aolab.bridge.passes import parse_passes, required_passes
from aolab.cycles.blender import package_path
from blender_support import (BLENDER, BLENDER_VERSION, ROOT, TINY, aolab_reference,
                             blender_check, blender_spy, checkout_env, needs_blender)


# ---- bpy-free parts ----

def test_intrinsics_square_pixels_centred():
    k = intrinsics(1280, 720, lens=50, sensor_width=36, sensor_height=24, sensor_fit="AUTO")
    assert k["fx"] == pytest.approx(50 / 36 * 1280) and k["fy"] == k["fx"]
    assert (k["cx"], k["cy"]) == (640, 360)


def test_intrinsics_vertical_fit_shift_and_aspect():
    k = intrinsics(100, 50, lens=40, sensor_width=36, sensor_height=20, sensor_fit="VERTICAL",
                   shift_x=0.1, shift_y=-0.2, pixel_aspect_x=1, pixel_aspect_y=2)
    ycor = 2.0
    viewfac = ycor * 50
    assert k["fx"] == pytest.approx(40 / 20 * viewfac)
    assert k["fy"] == pytest.approx(k["fx"] / 2)
    assert k["cx"] == pytest.approx(50 - 0.1 * viewfac)
    assert k["cy"] == pytest.approx(25 - 0.2 * viewfac / ycor)
    with pytest.raises(ValueError, match="sensor_fit"):
        intrinsics(10, 10, lens=1, sensor_width=1, sensor_height=1, sensor_fit="DIAGONAL")


DEPTH_ONLY = {"needs_normal": False, "needs_color": False}
NORMALS = {"needs_normal": True, "needs_color": False}
COLOUR = {"needs_normal": True, "needs_color": True}


@pytest.mark.parametrize("methods, effects, expected", [
    ([DEPTH_ONLY], [], ["depth"]),
    ([DEPTH_ONLY, NORMALS], [], ["depth", "normal"]),
    ([NORMALS], ["color_bleeding"], ["depth", "normal"]),  # nobody reads colour
    ([COLOUR], [], ["depth", "normal"]),                    # the scene asks for no effect
    ([COLOUR], ["color_bleeding"], ["depth", "normal", "diffuse_color"]),
    ([DEPTH_ONLY, COLOUR], ["luminance_sensitivity"],
     ["depth", "normal", "diffuse_color", "emission"]),
    ([], [], ["depth"]),
])
def test_only_needed_passes_are_selected(methods, effects, expected):
    assert required_passes(methods, effects) == expected


def test_pass_names_are_checked():
    assert parse_passes("normal") == ["depth", "normal"]
    with pytest.raises(ValueError, match="passes"):
        parse_passes("depth,mist")
    with pytest.raises(ValueError, match="effects"):
        required_passes([], ["bloom"])


# ---- inside Blender ----


@needs_blender
def test_stored_intrinsics_reconstruct_cycles_position_pass():
    results = blender_check("camera_check.py", str(TINY))
    assert len(results) == 6
    for name, r in results.items():
        assert r["valid"] > 1000, name
        assert r["max_rel"] < 1e-4, (name, r)


@needs_blender
def test_scene_is_restored_after_export_failure_and_cancel():
    r = blender_check("restore_check.py", str(TINY))
    assert r["export"]["outcome"] == "ok"
    assert r["failed"]["outcome"].startswith("failed")
    assert r["failed_late"]["outcome"].startswith("failed")
    for stage in ("prepare", "gbuffer", "reference", "merge"):
        assert r[f"cancel_{stage}"]["outcome"] == "cancelled", stage
    for case, v in r.items():
        if isinstance(v, dict):
            assert v["diff"] == [], (case, v["diff"][:10])
    slots_before = r["user_render_result"]["slots_before"]
    slots_after = r["user_render_result"]["slots_after"]
    assert slots_after[1] == slots_before[1]                 # the user's active slot
    assert slots_after[0][:len(slots_before[0])] == slots_before[0]
    # The G-buffer render had the asked passes only; the reference render AO alone.
    gbuffer, reference = r["passes_of_export"]
    assert gbuffer == ["use_pass_combined", "use_pass_normal", "use_pass_z"]
    assert reference == ["use_pass_ambient_occlusion", "use_pass_combined"]


@needs_blender
def test_reference_end_to_end_cached_and_scored(tmp_path):
    cache = tmp_path / "cache"
    res = aolab_reference(str(TINY), "--spp", "16", "--cache", str(cache), "--methods", "hbao")
    assert "rendered" in res.stdout
    folder = next(cache.iterdir())
    before = {p.name: p.stat().st_mtime_ns for p in folder.iterdir()}
    # Served from the cache: no render (the files are untouched), by a Blender that answers
    # --version (the release is part of the cache key) and leaves a mark if asked for
    # anything else. Not timed: a loaded machine can take seconds just to start Python, and
    # speed is measured in benchmarks.
    spy, mark = blender_spy(tmp_path)
    res = aolab_reference(str(TINY), "--spp", "16", "--cache", str(cache), "--methods", "hbao",
                          env=dict(os.environ, AOLAB_BLENDER=str(spy)))
    assert "cached" in res.stdout and not mark.exists()
    assert {p.name: p.stat().st_mtime_ns for p in folder.iterdir()} == before
    assert not [p for p in cache.iterdir() if p.name.startswith(".")]  # no temporary leftovers
    g = aolab.load_gbuffer(folder / "reference.exr")
    side = g.sidecar
    assert (g.width, g.height) == (96, 54) and side["passes"] == ["depth", "normal", "ao"]
    assert side["render"] == {"engine": "CYCLES", "device": "CPU", "reference_samples": 16,
                              "gbuffer_samples": 1, "use_adaptive_sampling": False,
                              "use_denoising": False, "max_bounces": 0, "filter_width": 0.01,
                              "shadow_terminator_geometry_offset": 0.0, "seed": 0,
                              "lights_hidden": True, "dof": False, "motion_blur": False,
                              "ao_distance": 0.75}
    for key in ("clip_start", "clip_end", "camera_to_world", "blender_version", "scene_hash",
                "render_time", "samples", "ao_distance"):
        assert key in side, key
    assert side["blender_version"].startswith("%d.%d" % BLENDER_VERSION)
    mask = g.valid_mask()
    assert mask.mean() > 0.95
    ao = aolab.compute("hbao", g, radius=side["ao_distance"])
    m = aolab.metrics(ao, g.reference, mask)
    assert np.isfinite(list(m.values())).all() and m["mae"] < 0.2
    # View-space normals agree with normals estimated from depth on flat faces.
    est = aolab.GBuffer(g.depth, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy).prepared_normals()
    stored = g.normal / np.linalg.norm(g.normal, axis=-1, keepdims=True).clip(1e-12)  # half
    dots = (est * stored).sum(-1)[mask]
    # Pixels beside an edge (one neighbour on another face) are the only disagreements.
    assert np.mean(dots > 0.9999) > 0.85, np.mean(dots > 0.9999)
    assert np.median(dots) > 0.99999


@needs_blender
def test_passes_follow_the_request(tmp_path):
    cache = tmp_path / "cache"

    def channels(*args):
        aolab_reference(str(TINY), "--spp", "2", "--cache", str(cache), *args)
        folder = max(cache.iterdir(), key=lambda p: p.stat().st_mtime)
        side = json.loads((folder / "reference.json").read_text())
        passes = {c.split(".")[-2] for c in aolab._core.exr_channels(str(folder / "reference.exr"))}
        return side["passes"], passes
    assert channels("--methods") == (["depth", "ao"], {"Depth", "AO"})  # no method: depth only
    assert channels("--methods", "hbao") == (["depth", "normal", "ao"], {"Depth", "Normal", "AO"})
    assert channels("--passes", "depth,diffuse_color") == (["depth", "diffuse_color", "ao"],
                                                           {"Depth", "DiffCol", "AO"})


@needs_blender
@pytest.mark.parametrize("camera_setup, message", [
    ("bpy.data.objects.remove(scene.camera)", "no camera"),
    ("scene.camera.data.type = 'ORTHO'", "orthographic"),
    ("scene.camera.data.type = 'PANO'", "panoramic"),
])
def test_unsupported_cameras_are_clear_errors(tmp_path, camera_setup, message):
    script = tmp_path / "scene.py"
    script.write_text(TINY.read_text() + f"\n{camera_setup}\n")
    res = aolab_reference(str(script), "--spp", "1", "--cache", str(tmp_path / "c"), check=False)
    assert res.returncode == 2, res.stdout + res.stderr
    assert message in res.stderr
    if message != "no camera":
        assert "perspective cameras only" in res.stderr


#: A camera under a parent scaled unevenly and rotated: its world matrix, scale removed, is
#: sheared. Left for the bridge to evaluate (no view_layer.update() here): refused all the same.
SHEARED_CAMERA = """
rig = bpy.data.objects.new("Rig", None)
scene.collection.objects.link(rig)
rig.rotation_euler = (0.3, 0.0, 0.5)
rig.scale = (1.0, 3.0, 1.0)
cam.parent = rig
"""


def euler_xz(rx: float, rz: float) -> np.ndarray:
    """Blender's XYZ Euler rotation (rx, 0, rz) as a 4x4 matrix."""
    from math import cos, sin
    x = np.array([[1, 0, 0], [0, cos(rx), -sin(rx)], [0, sin(rx), cos(rx)]])
    z = np.array([[cos(rz), -sin(rz), 0], [sin(rz), cos(rz), 0], [0, 0, 1]])
    m = np.eye(4)
    m[:3, :3] = z @ x
    return m


def test_a_sheared_camera_is_refused_by_the_bridge_as_by_the_ray_tracer():
    """One rule, one tolerance: the bridge's check is RayScene's. The tiny scene's camera
    under SHEARED_CAMERA's rig, its scale removed as the bridge records it."""
    from aolab.bridge.intrinsics import check_camera_to_world
    cam = euler_xz(1.15, 0.65)
    check_camera_to_world(cam)
    m = euler_xz(0.3, 0.5) @ np.diag([1.0, 3.0, 1.0, 1.0]) @ cam
    m[:3, :3] /= np.linalg.norm(m[:3, :3], axis=0, keepdims=True)
    with pytest.raises(ValueError) as bridge:
        check_camera_to_world(m)
    with pytest.raises(ValueError) as tracer:
        aolab.RayScene(np.zeros((3, 3), np.float32), [[0, 1, 2]], m)
    assert str(bridge.value) == str(tracer.value)
    assert str(bridge.value).startswith("camera_to_world must be a rotation and a translation")


@needs_blender
def test_a_sheared_camera_is_refused_before_rendering(tmp_path):
    """Was: rendered and cached, its sidecar then refused by `aolab rtao`."""
    script = tmp_path / "scene.py"
    script.write_text(TINY.read_text() + SHEARED_CAMERA)
    res = aolab_reference(str(script), "--spp", "1", "--cache", str(tmp_path / "c"),
                          check=False)
    assert res.returncode == 2, res.stdout + res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert "camera 'Camera' cannot be rendered from: camera_to_world must be a rotation" \
        in lines[0] and "scale the parent evenly" in lines[0], lines[0]
    assert not list((tmp_path / "c").rglob("*.exr"))


def test_missing_blender_and_missing_file_are_clear_errors(tmp_path):
    env = dict(os.environ, AOLAB_BLENDER=str(tmp_path / "no-blender"))
    res = aolab_reference(str(TINY), "--cache", str(tmp_path / "c"), env=env, check=False)
    assert res.returncode == 2 and "Blender not found" in res.stderr
    assert "apt-get install blender" in res.stderr
    res = aolab_reference(str(tmp_path / "nope.blend"), check=False)
    assert res.returncode == 2 and "no such scene" in res.stderr


@needs_blender
def test_blend_files_never_run_their_scripts(tmp_path):
    """A .blend whose registered text block writes a marker when run: --disable-autoexec
    keeps it from running. The same file opened with auto-run enabled does write it, so the
    test can fail."""
    marker = tmp_path / "marker.txt"
    blend = tmp_path / "trap.blend"
    maker = tmp_path / "make_trap.py"
    maker.write_text(TINY.read_text() + f"""
text = bpy.data.texts.new("trap.py")
text.write("open({str(marker)!r}, 'w').write('ran')\\n")
text.use_module = True
bpy.ops.wm.save_as_mainfile(filepath={str(blend)!r})
""")
    subprocess.run([BLENDER, "-b", "--factory-startup", "-noaudio", "--python-exit-code", "1",
                    "--python", str(maker)], check=True, capture_output=True, timeout=120)
    assert blend.exists() and not marker.exists()
    aolab_reference(str(blend), "--spp", "1", "--cache", str(tmp_path / "c"))
    assert not marker.exists(), "the .blend ran its own script"
    subprocess.run([BLENDER, "-b", "--factory-startup", "--enable-autoexec", str(blend)],
                   capture_output=True, timeout=120)
    assert marker.exists(), "control: with auto-run enabled the trap does fire"


@needs_blender
def test_a_bridge_that_dies_before_its_handler_renders_nothing(tmp_path):
    """A package Blender cannot import (one being rebuilt while a farm renders, say) kills the
    bridge before its own error handler, where Blender used to exit 0: the command fails with
    one line naming the scene, and the cache has no entry for it, not even an empty one."""
    package = Path(aolab.__file__).parent
    broken = tmp_path / "pkg"
    shutil.copytree(package, broken / "aolab")
    (broken / "aolab" / "bridge" / "intrinsics.py").write_text("raise ImportError('half-copied')\n")
    cache = tmp_path / "cache"
    # The broken copy is imported by this command alone (first on its sys.path), not named in
    # PYTHONPATH, which Blender 3.4 reads and 4.2+ ignores: so on both releases only
    # $AOLAB_PACKAGE_PATH (package_path()) can bring it to Blender's Python.
    res = subprocess.run(
        [sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv[1]); "
         "from aolab.cli import main; sys.exit(main(sys.argv[2:]))", str(broken), "reference",
         "--quiet", str(TINY), "--spp", "1", "--cache", str(cache)],
        capture_output=True, text=True, timeout=900)
    assert res.returncode != 0 and "tiny_scene" in res.stderr, res.stdout + res.stderr
    lines = res.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("aolab: ") and "half-copied" in lines[0]
    assert not cache.exists() or not any(cache.iterdir()), list(cache.iterdir())


def test_blender_is_given_the_folder_that_holds_this_package():
    """$AOLAB_PACKAGE_PATH, first on Blender's sys.path, holds aolab/ itself: the folder of
    aolab/ (as it once was) would make `import aolab` in Blender find another build."""
    held = Path(package_path()) / "aolab" / "__init__.py"
    assert held.resolve() == Path(aolab.__file__).resolve()


@needs_blender
def test_interrupted_batch_resumes_from_the_cache(tmp_path):
    """Killed during the second scene of a batch: the first stays cached, nothing half-written
    is left, and the same command finishes the batch, serving the first from the cache. A
    temporary folder left by a process that no longer exists is removed."""
    import signal
    slow = tmp_path / "slow_scene.py"
    slow.write_text(TINY.read_text().replace("96, 54, 100", "320, 180, 100"))
    cache = tmp_path / "cache"
    cmd = [sys.executable, "-m", "aolab", "reference", "--quiet", str(TINY), str(slow),
           "--spp", "256", "--cache", str(cache)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 300
    while time.time() < deadline:  # wait for the first scene's result, then interrupt
        if cache.exists() and any(p.name.startswith("tiny_scene-") for p in cache.iterdir()):
            break
        time.sleep(0.1)
    time.sleep(1.0)  # the second render is under way
    proc.send_signal(signal.SIGTERM)  # like `kill`; Ctrl-C (SIGINT) takes the same path
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, out + err
    assert "run the same command again to resume" in err
    assert [p.name.split("-")[0] for p in cache.iterdir()] == ["tiny_scene"]  # no temp dirs
    stale = cache / ".slow_scene-0123456789abcdef.tmp-999999999"  # no such pid
    stale.mkdir()
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    assert not stale.exists()
    lines = res.stdout.splitlines()
    assert "tiny_scene: cached" in lines[0] and "slow_scene: rendered" in lines[1]


@needs_blender
def test_background_reference_is_one(tmp_path):
    script = tmp_path / "sky.py"  # the tiny scene seen from where part of the frame is sky
    script.write_text(TINY.read_text() + "\ncam.rotation_euler = (1.5, 0, 0.65)\n")
    aolab_reference(str(script), "--spp", "4", "--cache", str(tmp_path / "c"))
    g = aolab.load_gbuffer(next((tmp_path / "c").iterdir()) / "reference.exr")
    background = ~g.valid_mask()
    assert background.sum() > 100
    assert (g.reference[background] == 1).all()


def test_scene_key_covers_the_shared_helpers(tmp_path):
    """A reference scene's content hash (the cache key's scene part) covers its build.py,
    its manifest and reference_scenes/scene_kit.py, which every build.py imports."""
    from aolab.cycles.plan import SCENE_KIT, resolve_scene
    scenes = tmp_path / "reference_scenes"
    shutil.copytree(ROOT / "reference_scenes" / "analytic", scenes / "analytic",
                    ignore=shutil.ignore_patterns("*.exr", "peers"))
    shutil.copyfile(ROOT / "reference_scenes" / SCENE_KIT, scenes / SCENE_KIT)
    before = resolve_scene(str(scenes / "analytic")).content_sha256
    assert resolve_scene(str(scenes / "analytic")).content_sha256 == before
    with open(scenes / SCENE_KIT, "a") as f:
        f.write("\n# a changed helper\n")
    assert resolve_scene(str(scenes / "analytic")).content_sha256 != before


TINY_SCENE = ROOT / "tests" / "data" / "tiny_scene.py"


def run_batch(out, *args: str, scene: Path = TINY_SCENE) -> subprocess.CompletedProcess:
    """batch.py run directly inside Blender on the tiny scene, writing to `out`."""
    return subprocess.run(
        [BLENDER, "-b", "--factory-startup", "-noaudio", "--disable-autoexec", "--python",
         str(ROOT / "blender_addon" / "aolab_blender" / "export" / "batch.py"), "--", "--scene",
         str(scene), "--kind", "script", "--out", str(out),
         *args], capture_output=True, text=True, timeout=300, env=checkout_env())


@needs_blender
@pytest.mark.parametrize("args, message", [
    (["--resolution", "1x1"], "--resolution must be WxH with integers in [4, 16384]"),
    (["--resolution", "abc"], "--resolution must be WxH"),
    (["--radius", "inf"], "--radius must be a number > 0 scene units, got 'inf'"),
    (["--radius", "nan"], "--radius must be a number > 0"),
    (["--spp", "0"], "--spp must be an integer in [1, 16777216], got 0"),
    (["--ladder", "1,0"], "--ladder must be comma-separated integers"),
    (["--extra", "[1]"], "--extra must be a JSON object, got list"),
    (["--extra", "{"], "--extra must be a JSON object"),
    (["--passes", "depth,bloom"], "passes must be among"),
    (["--radius=--"], "expected one value, got '--'"),
])
def test_batch_refuses_bad_options_by_name(tmp_path, args, message):
    """batch.py run directly (as a farm script may): every option checked when read, exit 2
    with one message naming it, before any scene is loaded."""
    res = run_batch(tmp_path / "r.exr", *args)
    assert res.returncode == 2, res.stdout[-2000:] + res.stderr[-2000:]
    assert message in res.stderr, res.stderr[-2000:]
    assert "Traceback" not in res.stdout + res.stderr
    assert not (tmp_path / "r.exr").exists()


@needs_blender
def test_batch_out_under_a_file_is_a_message(tmp_path):
    (tmp_path / "file").write_text("x")
    res = run_batch(tmp_path / "file" / "r.exr", "--spp", "1")
    assert res.returncode == 2, res.stdout[-2000:] + res.stderr[-2000:]
    assert "AOLAB_ERROR" in res.stdout and "file" in res.stdout, res.stdout[-2000:]
    assert "Traceback" not in res.stdout + res.stderr


@needs_blender
@pytest.mark.parametrize("out, passes, message", [
    ("scene.py", "depth", "--out {d}/scene.py is --scene {d}/scene.py: an output would "
                          "overwrite an input"),
    ("x.json", "depth", "the sidecar {d}/x.json is also written as --out {d}/x.json"),
    ("x.mesh", "depth,mesh", "the mesh {d}/x.mesh is also written as --out {d}/x.mesh"),
])
def test_batch_refuses_an_export_over_the_scene_or_itself(tmp_path, out, passes, message):
    """The bridge's export checks its files before the scene runs: none is the scene (the
    build script, the open .blend) or another file of the same export (aolab.bridge.outputs);
    one AOLAB_ERROR line naming both, exit 2, nothing written."""
    scene = tmp_path / "scene.py"
    scene.write_bytes(TINY_SCENE.read_bytes())
    res = run_batch(tmp_path / out, "--passes", passes, "--spp", "1", scene=scene)
    assert res.returncode == 2, res.stdout[-2000:] + res.stderr[-2000:]
    assert f"AOLAB_ERROR {message.format(d=tmp_path)}" in res.stdout.splitlines()
    assert scene.read_bytes() == TINY_SCENE.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.py"]


@needs_blender
def test_the_blender_release_is_in_the_cache_key(tmp_path):
    """Another Blender release samples Cycles differently: a reference cached by one is not
    handed out for another (docs/blender_bridge.md, "Across Blender releases")."""
    from aolab.cycles.blender import blender_version
    from aolab.cycles.plan import make_plan, resolve_scene
    version = blender_version()
    assert re.fullmatch(r"\d+\.\d+(\.\d+)?", version) and \
        version.startswith("%d.%d" % BLENDER_VERSION)
    other = tmp_path / "blender"
    other.write_text("#!/bin/sh\necho 'Blender 9.9.9'\n")
    other.chmod(0o755)
    assert blender_version(str(other)) == "9.9.9"
    plan = make_plan(resolve_scene(str(TINY)), spp=16, methods=["hbao"])
    assert plan.key() == plan.key(BLENDER) != plan.key(str(other))
    assert blender_version(str(tmp_path / "absent")) == "none"
