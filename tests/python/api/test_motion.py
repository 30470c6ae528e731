"""Motion vectors (docs/conventions.md, "Motion vectors"): Cycles' Vector pass converted to AO
Lab's convention by the bridge, the Motion pass read back by aolab.load_gbuffer, and
aolab.camera_motion. The bpy-free parts first; then real Blender renders (marked `blender`)
of a camera panning by exactly K pixels per frame against a plane, and of an object moving
in front of a still camera."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import cli
from aolab.bridge import exr
from aolab.bridge.motion import from_cycles_vector

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "tests" / "data"
BLENDER = shutil.which("blender")

#: tests/data/motion_pan.py: 64x48, fx = 64 px, a plane at depth 4, the camera moving
#: K_PIXELS px per frame to the left (0.125 m), so the image content moves right: dx = -K.
K_PIXELS = 2.0
#: The tolerance on interior pixels, in pixels: Cycles' Vector pass came out within 4e-6 px
#: of K (float32 projection in Cycles), camera_motion within 1e-6.
TOLERANCE_PX = 1e-3


# ---- bpy-free ----

def test_cycles_vector_becomes_aolab_motion():
    """Cycles: (X, Y) = previous - current with y up, (Z, W) towards the next frame;
    AO Lab: dx = X, dy = -Y (rows go down), NaN on background."""
    vector = np.zeros((2, 3, 4), np.float32)
    vector[..., 0], vector[..., 1] = 2.0, 3.0
    vector[..., 2], vector[..., 3] = 7.0, 9.0          # towards the next frame: unused
    depth = np.full((2, 3), 4.0, np.float32)
    depth[1, 2] = 1e10                                  # Cycles' background
    m = from_cycles_vector(vector, depth)
    assert m.dtype == np.float32 and m.shape == (2, 3, 2)
    assert np.all(m[0] == [2.0, -3.0])
    assert np.all(np.isnan(m[1, 2])) and np.all(m[1, :2] == [2.0, -3.0])
    with pytest.raises(ValueError, match="Vector pass"):
        from_cycles_vector(vector[..., :2], depth)


def plane_gbuffer(camera_to_world, depth=4.0, size=(64, 48), fx=64.0) -> aolab.GBuffer:
    """A G-buffer of planar depth `depth` (a number: a plane filling the view; or an array),
    with a sidecar."""
    w, h = size
    depth = np.broadcast_to(np.asarray(depth, np.float32), (h, w)).copy()
    g = aolab.GBuffer(depth, fx=fx, fy=fx, cx=w / 2, cy=h / 2)
    g.sidecar = {"width": w, "height": h, "fx": fx, "fy": fx, "cx": w / 2, "cy": h / 2,
                 "camera_to_world": np.asarray(camera_to_world).tolist()}
    return g


def translation(x=0.0, y=0.0, z=0.0) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def test_camera_motion_of_a_pan_is_minus_k():
    """The camera moves 0.125 m to the left in front of a plane at depth 4 (fx = 64 px): the
    content moves 2 px to the right, so every pixel's point was 2 px to its left."""
    previous = plane_gbuffer(translation(x=0.125))
    current = plane_gbuffer(translation())
    m = aolab.camera_motion(previous, current)
    assert m.dtype == np.float32 and m.shape == (48, 64, 2)
    np.testing.assert_allclose(m[..., 0], -K_PIXELS, atol=1e-6)
    np.testing.assert_allclose(m[..., 1], 0.0, atol=1e-6)
    # a camera moving up: the content moves down in the image, dy = -k (y down)
    m = aolab.camera_motion(plane_gbuffer(translation(y=-0.125)), current)
    np.testing.assert_allclose(m[..., 1], -K_PIXELS, atol=1e-6)
    # the previous frame may be given as its sidecar alone
    same = aolab.camera_motion(previous.sidecar, current)
    np.testing.assert_array_equal(same, aolab.camera_motion(previous, current))


def test_camera_motion_reprojects_through_the_world():
    """A general pair of cameras: every pixel's point, carried into the previous camera by
    hand, lands where camera_motion says."""
    rng = np.random.default_rng(1)

    def pose(angles, position):
        a, b, c = angles
        rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
        ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
        rz = np.array([[np.cos(c), -np.sin(c), 0], [np.sin(c), np.cos(c), 0], [0, 0, 1]])
        m = np.eye(4)
        m[:3, :3], m[:3, 3] = rz @ ry @ rx, position
        return m

    depth = np.full((48, 64), 3.0, np.float32)
    depth[10:20, 5:30] = 2.0                             # a box in front of a wall
    current = plane_gbuffer(pose((1.1, 0.02, 0.6), (2.0, -2.5, 1.8)), depth=depth)
    prev_pose = pose((1.12, 0.0, 0.55), (2.1, -2.45, 1.8))
    previous = {"fx": 70.0, "fy": 70.0, "cx": 30.0, "cy": 25.0,
                "camera_to_world": prev_pose.tolist()}
    m = aolab.camera_motion(previous, current)
    for _ in range(20):
        i, j = int(rng.integers(64)), int(rng.integers(48))
        d = float(current.depth[j, i])
        p = np.array([(i + 0.5 - 32) / 64 * d, -(j + 0.5 - 24) / 64 * d, -d, 1.0])
        world = np.asarray(current.sidecar["camera_to_world"]) @ p
        q = np.linalg.inv(prev_pose) @ world
        u, v = 30 + 70 * q[0] / -q[2], 25 - 70 * q[1] / -q[2]
        assert m[j, i] == pytest.approx([u - i - 0.5, v - j - 0.5], abs=1e-4)


def test_camera_motion_marks_background_and_points_behind_the_camera():
    depth = np.full((48, 64), 4.0, np.float32)
    depth[0, 0] = 1e10
    current = plane_gbuffer(translation(), depth=depth)
    m = aolab.camera_motion(plane_gbuffer(translation(z=-10.0)), current)   # 10 m ahead
    assert np.isnan(m).all()       # the plane, 4 m ahead, is behind the previous camera
    m = aolab.camera_motion(plane_gbuffer(translation()), current)
    assert np.isnan(m[0, 0]).all() and np.all(m[1:] == 0)


def test_camera_motion_refuses_what_it_cannot_use():
    current = plane_gbuffer(translation())
    with pytest.raises(ValueError, match="previous: the sidecar has no camera_to_world"):
        aolab.camera_motion({"fx": 1, "fy": 1, "cx": 0, "cy": 0}, current)
    with pytest.raises(ValueError, match="previous: .*finite 4x4"):
        aolab.camera_motion({"fx": 1, "fy": 1, "cx": 0, "cy": 0,
                             "camera_to_world": [[1, 0], [0, 1]]}, current)
    with pytest.raises(ValueError, match="current must be"):
        aolab.camera_motion(current, current.sidecar)
    with pytest.raises(ValueError, match="previous must be"):
        aolab.camera_motion(42, current)


def write_gbuffer(path: Path, layers, size=(5, 4)) -> None:
    exr.write_multilayer(str(path), layers)
    w, h = size
    path.with_suffix(".json").write_text(json.dumps(
        {"width": w, "height": h, "fx": 5.0, "fy": 5.0, "cx": 2.5, "cy": 2.0,
         "normal_space": "view", "background_depth": 1e9}))


def test_load_gbuffer_reads_the_motion_pass(tmp_path):
    depth = np.full((4, 5, 1), 3.0, np.float32)
    depth[0, 0] = 1e10
    motion = np.random.default_rng(0).normal(size=(4, 5, 2)).astype(np.float32) * 10
    motion[0, 0] = 0.0                                   # background: NaN once loaded
    write_gbuffer(tmp_path / "g.exr", [("Depth", depth, "float"), ("Motion", motion, "float")])
    g = aolab.load_gbuffer(tmp_path / "g.exr")
    assert g.motion.dtype == np.float32 and g.motion.shape == (4, 5, 2)
    assert np.isnan(g.motion[0, 0]).all()
    flat = np.ones((4, 5), bool)
    flat[0, 0] = False
    np.testing.assert_array_equal(g.motion[flat], motion[flat])      # float32: bit for bit
    write_gbuffer(tmp_path / "none.exr", [("Depth", depth, "float")])
    assert aolab.load_gbuffer(tmp_path / "none.exr").motion is None


def test_a_bad_motion_pass_is_an_error_naming_the_file(tmp_path):
    depth = np.full((4, 5, 1), 3.0, np.float32)
    motion = np.zeros((4, 5, 2), np.float32)
    motion[2, 3, 1] = np.nan
    path = tmp_path / "nan.exr"
    write_gbuffer(path, [("Depth", depth, "float"), ("Motion", motion, "float")])
    with pytest.raises(ValueError, match=r"nan\.exr: motion is not finite at 1 surface pixels, "
                                         r"first at \(x=3, y=2\)"):
        aolab.load_gbuffer(path)
    # one of the two channels: written by hand, as no writer of AO Lab's would
    path = tmp_path / "half.exr"
    import OpenImageIO as oiio
    spec = oiio.ImageSpec(5, 4, 2, oiio.TypeFloat)
    spec.channelnames = ("ViewLayer.Depth.Z", "ViewLayer.Motion.X")
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec)
    assert out.write_image(np.full((4, 5, 2), 3.0, np.float32))
    out.close()
    path.with_suffix(".json").write_text((tmp_path / "nan.json").read_text())
    with pytest.raises(ValueError, match=r"half\.exr: the Motion pass has .*Motion\.X.* but "
                                         r"not .*Motion\.Y"):
        aolab.load_gbuffer(path)


# ---- real Blender renders ----

needs_blender = pytest.mark.skipif(BLENDER is None, reason="Blender is not installed "
                                   "(scripts/install-deps.sh installs it)")


def sequence_folder(tmp_path: Path, script: str) -> Path:
    """A sequence scene (manifest with "frames") built by tests/data/<script>, copied into
    the folder with the kit it runs (a scene's build script is a file of its folder)."""
    folder = tmp_path / "scenes" / Path(script).stem
    folder.mkdir(parents=True)
    for name in (script, "motion_kit.py"):
        shutil.copy(DATA / name, folder / name)
    (folder / "manifest.json").write_text(json.dumps(
        {"name": folder.name, "build": script, "radius": 0.5,
         "resolution": [64, 48],
         "camera": "Camera", "frames": {"start": 1, "end": 3, "step": 1}}))
    return folder


def render_frames(tmp_path: Path, script: str, frames: str) -> dict[int, aolab.GBuffer]:
    """`aolab reference` of the sequence at 1 sample (G-buffer and AO), frames `frames`."""
    folder = sequence_folder(tmp_path, script)
    out = tmp_path / "out"
    assert cli.main(["reference", str(folder), "--spp", "1", "--frames", frames,
                     "--cache", str(tmp_path / "cache"), "--out", str(out)]) == 0
    return {int(f.name): aolab.load_gbuffer(f / "reference.exr")
            for f in sorted((out / "frames").iterdir())}


@pytest.mark.blender
@needs_blender
def test_a_pan_by_k_pixels_gives_minus_k(tmp_path):
    """The acceptance test: the camera pans so that the content moves K px to the right per
    frame; the Vector pass and camera_motion both give dx = -K, dy = 0 on every plane pixel
    (edges included: at 1 sample and filter width 0.01 a pixel's motion is its depth's
    surface's), NaN on the background columns."""
    g = render_frames(tmp_path, "motion_pan.py", "1-2")
    current = g[2]
    assert "motion" in current.sidecar["passes"]          # a sequence gets it unasked
    assert current.sidecar["motion_previous_frame"] == 1
    assert current.sidecar["fx"] == 64
    surface = current.depth < 1e9
    assert surface[:, :49].all() and not surface[:, 49:].any()   # the plane ends at u = 49.2
    m = current.motion
    assert np.abs(m[surface] - [-K_PIXELS, 0.0]).max() < TOLERANCE_PX
    assert np.isnan(m[~surface]).all()
    from_cameras = aolab.camera_motion(g[1], current)
    assert np.abs(from_cameras[surface] - [-K_PIXELS, 0.0]).max() < TOLERANCE_PX
    assert np.isnan(from_cameras[~surface]).all()
    # The first frame looks back to frame 0, where the keys' constant extrapolation holds
    # the camera still: no motion.
    assert np.abs(g[1].motion[g[1].depth < 1e9]).max() < TOLERANCE_PX


@pytest.mark.blender
@needs_blender
def test_a_moving_object_moves_and_its_background_does_not(tmp_path):
    """A still camera, a cube moving 4 px to the right per frame in front of a plane: the
    Vector pass gives dx = -4 on the cube and 0 on the plane; camera_motion, which knows only
    the cameras, gives 0 on both."""
    current = render_frames(tmp_path, "motion_object.py", "2")[2]
    cube = np.abs(current.depth - 2.5) < 1e-4
    plane = np.abs(current.depth - 4.0) < 1e-4
    assert cube.sum() > 300 and plane.sum() > 1500 and (cube | plane).all()
    m = current.motion
    assert np.abs(m[cube] - [-4.0, 0.0]).max() < TOLERANCE_PX
    assert np.abs(m[plane]).max() < TOLERANCE_PX
    still = aolab.camera_motion(current, current)     # the camera does not move
    assert np.abs(still[cube | plane]).max() < TOLERANCE_PX


def test_motion_is_added_to_a_committed_reference_leaving_the_rest(tmp_path):
    """scripts/update_motion.sh's step: the Motion pass of a fresh 1-sample G-buffer copied
    into a reference whose AO is not rendered again; every channel it had stays bit for bit."""
    from aolab.bridge.motion import add_motion_pass
    rng = np.random.default_rng(3)
    depth = rng.uniform(1, 5, (4, 5, 1)).astype(np.float32)
    depth[0, 0] = 1e10
    side = {"width": 5, "height": 4, "fx": 5.0, "fy": 5.0, "cx": 2.5, "cy": 2.0,
            "normal_space": "view", "background_depth": 1e9, "scene_hash": "abc", "frame": 2,
            "camera_to_world": np.eye(4).tolist()}
    target, source = tmp_path / "target.exr", tmp_path / "source.exr"
    ao = rng.uniform(0, 1, (4, 5, 3)).astype(np.float16).astype(np.float32)
    normal = rng.normal(size=(4, 5, 3)).astype(np.float16).astype(np.float32)
    exr.write_multilayer(str(target), [("Depth", depth, "float"), ("Normal", normal, "half"),
                                       ("AO", ao, "half")])
    target.with_suffix(".json").write_text(json.dumps({**side, "passes": ["depth", "normal",
                                                                          "ao"]}))
    motion = rng.normal(size=(4, 5, 2)).astype(np.float32)
    exr.write_multilayer(str(source), [("Depth", depth, "float"), ("Motion", motion, "float")])
    source.with_suffix(".json").write_text(json.dumps(
        {**side, "passes": ["depth", "motion", "ao"], "motion_previous_frame": 1}))
    before = exr.read_channels(str(target))

    new = add_motion_pass(target, source)
    assert new["passes"] == ["depth", "normal", "motion", "ao"]
    assert new["motion_previous_frame"] == 1
    after = exr.read_channels(str(target))
    for name, plane in before.items():
        np.testing.assert_array_equal(after[name], plane)
    g = aolab.load_gbuffer(target)
    np.testing.assert_array_equal(g.motion[1:], motion[1:])
    assert np.isnan(g.motion[0, 0]).all()

    # Another scene, or another depth, is refused before anything is written.
    source.with_suffix(".json").write_text(json.dumps(
        {**side, "scene_hash": "other", "passes": ["depth", "motion"],
         "motion_previous_frame": 1}))
    with pytest.raises(ValueError, match="source.exr is not a render of .*target.exr: their "
                                         "scene_hash differ"):
        add_motion_pass(target, source)
    source.with_suffix(".json").write_text(json.dumps(
        {**side, "passes": ["depth", "motion"], "motion_previous_frame": 1}))
    exr.write_multilayer(str(source), [("Depth", depth * 1.001, "float"),
                                       ("Motion", motion, "float")])
    with pytest.raises(ValueError, match="depths .* differ by 0.001"):
        add_motion_pass(target, source)


def test_a_sequence_asks_for_the_motion_pass():
    from aolab.bridge.passes import parse_passes, required_passes
    reads_normals = {"needs_normal": True, "needs_color": False}
    assert required_passes([reads_normals], []) == ["depth", "normal"]
    assert required_passes([reads_normals], [], sequence=True) == ["depth", "normal", "motion"]
    assert parse_passes("motion,normal") == ["depth", "normal", "motion"]


def test_the_committed_flythrough_moves_as_its_cameras_say():
    """The committed sequence (a static set, a camera that trucks and turns, motion up to
    28 px per frame): its Motion pass, from Cycles, and camera_motion agree within
    TOLERANCE_PX on every pixel both see (measured: median 2.4e-5 px, at most 4.3e-4 px)."""
    frames = ROOT / "reference_scenes" / "flythrough" / "frames"
    loaded = [aolab.load_gbuffer(frames / f"{f:04d}" / "reference.exr") for f in range(1, 9)]
    if any(g.motion is None for g in loaded):
        pytest.skip("the committed flythrough has no Motion pass (scripts/update_motion.sh)")
    for previous, current in zip(loaded, loaded[1:]):
        assert current.sidecar["motion_previous_frame"] == previous.sidecar["frame"]
        from_cameras = aolab.camera_motion(previous, current)
        both = np.isfinite(current.motion).all(-1) & np.isfinite(from_cameras).all(-1)
        assert both.sum() == np.count_nonzero(current.depth < 1e9)
        assert np.abs(current.motion - from_cameras)[both].max() < TOLERANCE_PX
    # Two frames cropped alike (the study's --crop): the motion is cropped with them, and the
    # cameras' motion, from the crops' own intrinsics, still agrees.
    from aolab import scenes
    crop = scenes.Crop(100, 60)
    previous, current = (scenes.load_cropped(frames / f"{f:04d}", crop)[0] for f in (4, 5))
    assert current.motion.shape == (60, 100, 2)
    from_cameras = aolab.camera_motion(previous, current)
    both = np.isfinite(current.motion).all(-1) & np.isfinite(from_cameras).all(-1)
    assert both.sum() > 5000
    assert np.abs(current.motion - from_cameras)[both].max() < TOLERANCE_PX
