"""Hostile inputs at the Python boundary (the issue "Hostile inputs"): each is refused with a
ValueError naming the parameter (or file) and the value, or handled as documented.

Covered here: SSIM on any finite input, the ``blur`` switch of ``compute``, the dtypes and
shapes of G-buffer arrays, camera sidecars that are not clean UTF-8 JSON, paths that are not
regular files, and out-of-range settings whose value and bound must not print alike.
"""

import json
import os
import re
import signal

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import aolab
from aolab import _core


def plane(h=8, w=8, depth=2.0):
    d = np.full((h, w), depth, np.float32)
    n = np.zeros((h, w, 3), np.float32)
    n[..., 2] = 1
    return aolab.GBuffer(d, n, fx=8.0, fy=8.0, cx=w / 2, cy=h / 2)


# --- 1. SSIM is numerically stable for any finite input ----------------------------------

def test_ssim_of_opposite_huge_constants_is_not_one():
    a = np.full((16, 16), 1e20, np.float32)
    b = np.full((16, 16), -1e20, np.float32)
    ssim = aolab.metrics(a, b)["ssim"]
    assert ssim != 1.0
    assert ssim == pytest.approx(-1.0, abs=1e-12)
    assert np.allclose(_core.ssim_map(a, b), -1.0, atol=1e-6)
    assert aolab.metrics(a, a)["ssim"] == 1.0


finite_images = hnp.arrays(
    np.float32, st.tuples(st.integers(1, 14), st.integers(1, 14)),
    elements=st.floats(width=32, allow_nan=False, allow_infinity=False))


@settings(max_examples=200, deadline=None)
@given(data=st.data(), image=finite_images)
def test_ssim_of_random_finite_images_is_finite_and_in_range(data, image):
    other = data.draw(hnp.arrays(np.float32, image.shape,
                                 elements=st.floats(width=32, allow_nan=False,
                                                    allow_infinity=False)))
    m = aolab.metrics(image, other)
    assert np.isfinite(m["ssim"]) and -1.0 <= m["ssim"] <= 1.0, m
    for key in ("mae", "rmse", "bias"):
        assert np.isfinite(m[key]), m
    s = _core.ssim_map(image, other)
    assert np.all(np.isfinite(s)) and np.all(s >= -1) and np.all(s <= 1)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_ssim_of_non_finite_input_is_valueerror(bad):
    a = np.full((12, 12), 0.5, np.float32)
    b = a.copy()
    b[3, 4] = bad
    with pytest.raises(ValueError, match=r"reference must be finite"):
        aolab.metrics(a, b)
    with pytest.raises(ValueError, match=r"^b must be finite"):
        _core.ssim_map(a, b)


# --- 2. blur is a real bool ---------------------------------------------------------------

@pytest.mark.parametrize("blur", ["no", "yes", "", 1, 0, 1.0, np.float64(1), [True]])
def test_blur_must_be_a_bool(blur):
    with pytest.raises(ValueError, match=r"^blur must be a bool .*got " + re.escape(repr(blur))):
        aolab.compute("hbao", plane(), radius=1.0, blur=blur)


@pytest.mark.parametrize("blur", [True, False, None, np.bool_(True), np.bool_(False)])
def test_blur_accepts_bools_and_numpy_bools(blur):
    ao = aolab.compute("hbao", plane(), radius=1.0, blur=blur)
    assert ao.shape == (8, 8)


# --- 3. G-buffer arrays: real numeric dtypes, shapes as written ------------------------------

BAD_DTYPES = {
    "structured": lambda shape: np.zeros(shape, dtype=[("a", "<f4")]),
    "datetime64": lambda shape: np.zeros(shape, dtype="datetime64[s]"),
    "timedelta64": lambda shape: np.zeros(shape, dtype="timedelta64[s]"),
    "bytes": lambda shape: np.full(shape, b"2", dtype="S1"),
    "str": lambda shape: np.full(shape, "2", dtype="U1"),
    "bool": lambda shape: np.ones(shape, dtype=bool),
    "complex": lambda shape: np.full(shape, 2 + 0j, dtype=np.complex64),
    "object": lambda shape: np.full(shape, 2.0, dtype=object),
}


@pytest.mark.parametrize("kind", sorted(BAD_DTYPES))
def test_depth_of_a_non_numeric_dtype_is_refused(kind):
    depth = BAD_DTYPES[kind]((4, 4))
    with pytest.raises(ValueError, match=r"^depth must be .*real numbers.*got dtype") as e:
        aolab.GBuffer(depth, fx=1.0, fy=1.0, cx=2.0, cy=2.0)
    assert str(depth.dtype) in str(e.value)


@pytest.mark.parametrize("name", ["normal", "color", "emission"])
@pytest.mark.parametrize("kind", ["structured", "bool", "complex", "datetime64"])
def test_other_passes_of_a_non_numeric_dtype_are_refused(name, kind):
    depth = np.full((4, 4), 2.0, np.float32)
    args = {name: BAD_DTYPES[kind]((4, 4, 3))}
    with pytest.raises(ValueError, match=rf"^{name} must be .*got dtype"):
        aolab.GBuffer(depth, fx=1.0, fy=1.0, cx=2.0, cy=2.0, **args)


@pytest.mark.parametrize("dtype", [np.float16, np.float32, np.float64, np.int32, np.uint8,
                                   np.int64])
def test_real_numeric_dtypes_are_accepted(dtype):
    g = aolab.GBuffer(np.full((4, 4), 2, dtype), fx=1.0, fy=1.0, cx=2.0, cy=2.0)
    assert g.depth.dtype == np.float32 and np.all(g.depth == 2)


def test_float32_depth_is_still_used_in_place():
    depth = np.full((4, 4), 2.0, np.float32)
    g = aolab.GBuffer(depth, fx=1.0, fy=1.0, cx=2.0, cy=2.0)
    assert np.shares_memory(g.depth, depth)


def test_depth_none_says_none():
    with pytest.raises(ValueError, match=r"^depth must be an array \(H, W\), got None$"):
        aolab.GBuffer(None, fx=1.0, fy=1.0, cx=0.0, cy=0.0)


@pytest.mark.parametrize("shape", [(0, 5), (5, 0), (0, 0)])
def test_empty_depth_names_its_shape_as_written(shape):
    with pytest.raises(ValueError) as e:
        aolab.GBuffer(np.zeros(shape, np.float32), fx=1.0, fy=1.0, cx=0.0, cy=0.0)
    assert str(e.value).startswith("depth must not be empty")
    assert str(e.value).endswith(f"got {shape}")


# --- 4. Camera sidecars ---------------------------------------------------------------------

@pytest.fixture
def saved(tmp_path):
    """A saved G-buffer: (exr path, sidecar path, the sidecar as a dict)."""
    exr = tmp_path / "scene.exr"
    aolab.save_gbuffer(exr, plane(4, 6))
    side = tmp_path / "scene.json"
    return exr, side, json.loads(side.read_text())


def test_sidecar_with_a_latin1_byte_names_the_file_and_the_encoding(saved):
    exr, side, doc = saved
    doc["note"] = "caf\u00e9"
    side.write_bytes(json.dumps(doc, ensure_ascii=False).encode("latin-1"))
    with pytest.raises(ValueError) as e:
        aolab.load_gbuffer(exr)
    message = str(e.value)
    assert str(side) in message and "UTF-8" in message and "0xE9" in message, message


def test_sidecar_with_a_byte_order_mark_loads(saved):
    exr, side, doc = saved
    doc["note"] = "caf\u00e9"
    side.write_bytes(b"\xef\xbb\xbf" + json.dumps(doc, ensure_ascii=False).encode("utf-8"))
    g = aolab.load_gbuffer(exr)
    assert g.sidecar["note"] == "caf\u00e9" and g.width == 6


def test_sidecar_null_fx_is_called_null(saved):
    exr, side, doc = saved
    doc["fx"] = None
    side.write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=r'^sidecar key "fx" in .*scene\.json .*null, got null'):
        aolab.load_gbuffer(exr)


@pytest.mark.parametrize("key, value, shown", [("fx", 1e-50, "1e-50"), ("fy", 1e-46, "1e-46"),
                                               ("cx", 1e300, "1e+300")])
def test_sidecar_value_that_does_not_fit_a_float_is_shown_as_written(saved, key, value, shown):
    exr, side, doc = saved
    doc[key] = value
    side.write_text(json.dumps(doc))
    with pytest.raises(ValueError) as e:
        aolab.load_gbuffer(exr)
    message = str(e.value)
    assert f'"{key}"' in message and str(side) in message, message
    assert message.endswith(f"got {shown}"), message


def test_sidecar_nested_100000_deep_is_a_clear_valueerror(saved):
    exr, side, _ = saved
    side.write_text("[" * 100_000)
    with pytest.raises(ValueError, match=r"nests arrays and objects deeper than 64 levels"):
        aolab.load_gbuffer(exr)


def test_all_nan_ao_pass_is_loaded_as_nan(tmp_path):
    exr = tmp_path / "nan.exr"
    aolab.save_gbuffer(exr, plane(4, 6), reference=np.full((4, 6), np.nan, np.float32))
    g = aolab.load_gbuffer(exr)
    assert g.reference is not None and g.reference.shape == (4, 6)
    assert np.all(np.isnan(g.reference))


# --- 5. Paths that are not regular files ------------------------------------------------------

@pytest.fixture
def no_hang():
    """Fails a test that blocks (opening a FIFO) instead of hanging the suite."""
    def timeout(*_):
        raise TimeoutError("the call blocked")
    old = signal.signal(signal.SIGALRM, timeout)
    signal.alarm(10)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


def test_fifo_named_exr_is_refused_without_blocking(tmp_path, no_hang):
    fifo = tmp_path / "x.exr"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match=r"x\.exr is a FIFO \(named pipe\), not a regular file"):
        aolab.load_gbuffer(fifo)


def test_directory_named_exr_is_refused(tmp_path):
    (tmp_path / "d.exr").mkdir()
    with pytest.raises(ValueError, match=r"d\.exr is a directory, not a regular file"):
        aolab.load_gbuffer(tmp_path / "d.exr")


def test_fifo_sidecar_is_refused_without_blocking(saved, no_hang):
    exr, side, _ = saved
    side.unlink()
    os.mkfifo(side)
    with pytest.raises(ValueError, match=r"scene\.json is a FIFO"):
        aolab.load_gbuffer(exr)


def test_missing_file_is_still_filenotfound(tmp_path):
    with pytest.raises(FileNotFoundError):
        aolab.load_gbuffer(tmp_path / "absent.exr")


# --- 6. Out-of-range values and their bounds never print alike -------------------------------

def test_seed_beyond_the_bound_prints_both_exactly():
    with pytest.raises(ValueError) as e:
        aolab.compute("hbao", plane(), radius=1.0, seed=2**31)
    message = str(e.value)
    assert "2147483647]" in message and message.endswith("got 2147483648"), message
    assert "e+09" not in message


def test_float_just_past_a_bound_keeps_its_digits():
    info = {s["name"]: s for s in aolab.method_info("hbao")["settings"]}
    hi = info["radius"]["max"]
    value = float(np.nextafter(hi, np.inf))
    with pytest.raises(ValueError) as e:
        aolab.compute("hbao", plane(), radius=value)
    message = str(e.value)
    assert message.endswith(f"got {value!r}"), message


# --- 7. rtao: coordinates the ray tracer cannot represent (docs/conventions.md, "Ranges") ----
# Embree takes coordinates below 1.844e18 (its FLT_LARGE) in magnitude: it silently drops a
# triangle with a vertex beyond that, and a ray whose origin lies beyond it fails an assertion
# that ends the process (Blender with it, inside the add-on).

SCENE_HASH = "5ce1e" * 12 + "0000"


def saved_scene(folder, name="wall", width=32, height=18, scene_hash=SCENE_HASH):
    """An analytic scene saved as a G-buffer whose sidecar names ``scene_hash`` (as the bridge
    writes one), and its planes as world-space triangles (50 m squares)."""
    g = aolab.analytic_scene(name, width, height)
    path = folder / "reference.exr"
    aolab.save_gbuffer(path, g, reference=g.reference,
                       sidecar=dict(g.sidecar, scene_hash=scene_hash))
    v, t = aolab.analytic_scene_mesh(name, 50.0)
    return path, v, t


def write_scene_mesh(path, vertices, triangles, scene_hash=SCENE_HASH):
    from aolab.bridge import mesh as meshfile
    meshfile.write_mesh(path, vertices, triangles, {"space": "world", "scene_hash": scene_hash})
    return path


def with_triangle(vertices, triangles, corner, size=1.0):
    """The mesh plus one triangle of side ``size`` at ``corner``."""
    corner = np.asarray(corner, np.float64)
    extra = corner + np.array([[0, 0, 0], [size, 0, 0], [0, size, 0]])
    n = len(vertices)
    return (np.vstack([vertices, extra]).astype(np.float32),
            np.vstack([triangles, [[n, n + 1, n + 2]]]))


def run_aolab(*args):
    import subprocess
    import sys
    return subprocess.run([sys.executable, "-m", "aolab", *map(str, args)],
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("far", [1.9e18, 1e25, 3e38])
def test_a_vertex_beyond_the_ray_tracers_range_is_refused_naming_it(far):
    v = np.array([[0, 0, -2], [1, 0, -2], [0, 1, -2], [far, 0, -2]], np.float32)
    with pytest.raises(ValueError, match=r"^vertices must .*1\.844e\+18.*1 of 4 vertices.*"
                       r"vertex 3.*got "):
        aolab.RayScene(v, [[0, 1, 2], [1, 2, 3]], np.eye(4))


def test_a_camera_beyond_the_ray_tracers_range_moves_every_vertex_beyond_it():
    c2w = np.eye(4)
    c2w[0, 3] = 1e19
    v = np.array([[0, 0, -2], [1, 0, -2], [0, 1, -2]], np.float32)
    with pytest.raises(ValueError, match=r"^vertices must .*3 of 3 vertices.*vertex 0"):
        aolab.RayScene(v, [[0, 1, 2]], c2w)


def test_a_point_beyond_the_ray_tracers_range_is_refused_not_traced():
    """A depth of 1e19, geometry once background_depth is raised to infinity: its rays would
    start beyond Embree's range (an assertion, the process ended); ε stays below R = 1e30."""
    depth = np.full((2, 3), 2.0, np.float32)
    depth[1, 2] = 1e19
    normal = np.zeros((2, 3, 3), np.float32)
    normal[..., 2] = 1
    g = aolab.GBuffer(depth, normal, fx=3.0, fy=3.0, cx=1.5, cy=1.0,
                      background_depth=float("inf"))
    scene = aolab.RayScene(np.array([[0, 0, -3], [1, 0, -3], [0, 1, -3]], np.float32),
                           [[0, 1, 2]], np.eye(4))
    with pytest.raises(ValueError, match=r"^depth must put every point rays are traced from "
                       r"inside the ray tracer's range .*1\.844e\+18.*1 of 6 pixels are "
                       r"beyond it, the first at pixel \(2, 1\), got 1e\+19"):
        aolab.rtao(g, scene, radius=1e30, rays=1)


def test_rtao_with_a_mesh_beyond_the_range_exits_2_with_one_line(tmp_path):
    """Was: Embree's assertion `ray.valid()`, exit 134 (the ray offset scaled with the far
    vertex and pushed every ray origin out of Embree's range)."""
    exr, v, t = saved_scene(tmp_path)
    big = write_scene_mesh(tmp_path / "big.mesh", *with_triangle(v, t, (1e25, 0, 0)))
    r = run_aolab("rtao", exr, "--mesh", big, "--rays", "1", "--out", tmp_path / "ao")
    assert r.returncode == 2, (r.returncode, r.stderr[-800:])
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("aolab: vertices must"), r.stderr
    assert "1.844e+18" in lines[0] and f"vertex {len(v)} " in lines[0]


# --- 8. rtao: the ray offset against R (docs/conventions.md, "Ranges") ----------------------

def wall_scene(width=48, height=27):
    g = aolab.analytic_scene("wall", width, height)
    v, t = aolab.analytic_scene_mesh("wall", 50.0)
    return g, v, t


def scene_in(g, vertices, triangles, shift=(0.0, 0.0, 0.0)):
    """The triangles in ``g``'s view space, the world moved by ``shift``: the camera with it,
    so only the world coordinates (and their float32 rounding) change."""
    c2w = np.array(g.sidecar["camera_to_world"], np.float64)
    c2w[:3, 3] += shift
    moved = (np.asarray(vertices, np.float64) + shift).astype(np.float32)
    return aolab.RayScene(moved, triangles, c2w)


@pytest.mark.parametrize("corner", [(1e7, 1e7, 0.0), (1e17, 0.0, 0.0)])
def test_a_small_triangle_far_away_changes_nothing(corner):
    """Was: the offset scaled with the farthest vertex, so one triangle 1e7 away lifted every
    ray by 5 m and R = 0.5 found no occluder (AO 1 everywhere)."""
    g, v, t = wall_scene()
    near = aolab.rtao(g, scene_in(g, v, t), radius=0.5, rays=16)
    far = aolab.rtao(g, scene_in(g, *with_triangle(v, t, corner)), radius=0.5, rays=16)
    assert near[g.valid_mask()].mean() < 0.99
    np.testing.assert_array_equal(far, near)


def test_a_scene_far_from_the_world_origin_is_refused_with_the_numbers():
    g, v, t = wall_scene()
    scene = scene_in(g, v, t, shift=(1e7, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"^radius must exceed the ray offset ε") as e:
        aolab.rtao(g, scene, radius=0.5, rays=4)
    message = str(e.value)
    assert f"ε ≥ R on {int(g.valid_mask().sum())} of {int(g.valid_mask().sum())} pixels" \
        in message, message
    assert "camera from the world origin |c| = 1e+07" in message and "got 0.5" in message
    assert "move the scene and its camera nearer the world origin" in message
    assert aolab.rtao_range(g, scene, radius=0.5)["refusal"] == message


def test_a_triangle_as_long_as_the_range_is_refused_not_asserted():
    """A vertex just inside Embree's range on a triangle of the scene: its rounding reaches
    everywhere near it, so the offset is far beyond R; refused before any ray is traced."""
    g, v, t = wall_scene()
    n = len(v)
    v = np.vstack([v, [[1.8e18, 0, 0]]]).astype(np.float32)
    t = np.vstack([t, [[0, 1, n]]])
    with pytest.raises(ValueError, match=r"longest triangle edge D = 1\.8e\+18"):
        aolab.rtao(g, scene_in(g, v, t), radius=0.5, rays=4)


def test_an_offset_above_one_percent_of_r_warns_and_is_queryable():
    g, v, t = wall_scene()
    scene = scene_in(g, v, t, shift=(3e4, 0.0, 0.0))
    with pytest.warns(aolab.RtaoRangeWarning, match=r"^rtao: the ray offset ε exceeds 1 % of "
                      r"R = 0\.5 on \d+ of \d+ pixels"):
        ao = aolab.rtao(g, scene, radius=0.5, rays=4)
    assert ao[g.valid_mask()].mean() < 1.0
    r = aolab.rtao_range(g, scene, radius=0.5)
    assert r["pixels"] == g.valid_mask().sum() and r["warned"] > 0 and r["refused"] == 0
    assert 0.01 < r["largest_share_of_radius"] < 1 and r["refusal"] is None
    assert r["camera_distance"] == pytest.approx(np.linalg.norm(
        np.array(g.sidecar["camera_to_world"])[:3, 3] + (3e4, 0, 0)))
    quiet = aolab.rtao_range(g, scene_in(g, v, t), radius=0.5)
    assert quiet["warned"] == 0 and quiet["warning"] is None


def test_rtao_cli_refuses_an_offset_reaching_r_in_one_line_and_warns_in_one_line(tmp_path):
    r = run_aolab("rtao", "analytic:wall", "--radius", "1e-4", "--width", "16", "--height", "9",
                  "--rays", "1", "--out", tmp_path / "a")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert r.stderr.startswith("aolab: radius must exceed the ray offset ε"), r.stderr
    r = run_aolab("rtao", "analytic:wall", "--radius", "0.05", "--width", "16", "--height", "9",
                  "--rays", "1", "--out", tmp_path / "b")
    assert r.returncode == 0, r.stderr
    assert r.stderr.startswith("aolab: warning: rtao: the ray offset ε exceeds 1 % of R")
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr


# --- 9. A mesh and a G-buffer of different scenes (docs/file_formats.md, "Scene geometry") --
# Every path that traces a mesh for a G-buffer pairs them by one rule
# (aolab.bridge.mesh.check_pairing): the two scene hashes must agree; a mesh read from a file
# whose scene cannot be checked needs allow_unknown_scene; a mesh made in memory is the
# caller's own pairing.

OTHER_HASH = "07e5" * 15 + "1111"


def test_rtao_refuses_a_mesh_of_another_scene_naming_both(tmp_path):
    """Was: only the mesh found beside the G-buffer was checked; aolab.rtao(g, mesh) traced
    any mesh."""
    exr, v, t = saved_scene(tmp_path)
    other = write_scene_mesh(tmp_path / "other.mesh", v, t, OTHER_HASH)
    g, mesh = aolab.load_gbuffer(exr), aolab.load_mesh(other)
    built = aolab.ray_scene(mesh, camera_to_world=np.array(g.sidecar["camera_to_world"]))
    for call in (lambda: aolab.rtao(g, mesh, radius=1.0, rays=1),
                 lambda: aolab.rtao(g, built, radius=1.0, rays=1),
                 lambda: aolab.ray_scene(mesh, g),
                 lambda: aolab.rtao_range(g, mesh, radius=1.0),
                 lambda: aolab.rtao(g, mesh, radius=1.0, rays=1, allow_unknown_scene=True)):
        with pytest.raises(ValueError, match="is not the geometry of") as e:
            call()
        for part in (str(other), str(exr), repr(SCENE_HASH), repr(OTHER_HASH)):
            assert part in str(e.value), (part, str(e.value))
    same = aolab.load_mesh(write_scene_mesh(tmp_path / "same.mesh", v, t))
    assert aolab.rtao(g, same, radius=1.0, rays=1).shape == g.depth.shape


def test_rtao_command_refuses_a_mesh_of_another_scene(tmp_path):
    exr, v, t = saved_scene(tmp_path)
    other = write_scene_mesh(tmp_path / "other.mesh", v, t, OTHER_HASH)
    for extra in ([], ["--allow-unknown-scene"]):
        r = run_aolab("rtao", exr, "--mesh", other, "--rays", "1", "--out", tmp_path / "ao",
                      *extra)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert OTHER_HASH in r.stderr and SCENE_HASH in r.stderr and str(exr) in r.stderr
    same = write_scene_mesh(tmp_path / "same.mesh", v, t)
    r = run_aolab("rtao", exr, "--mesh", same, "--rays", "1", "--out", tmp_path / "ao")
    assert r.returncode == 0, r.stderr


def test_a_mesh_file_for_an_analytic_scene_needs_allow_unknown_scene(tmp_path):
    """Was: `aolab rtao analytic:wall --mesh some.mesh` traced it."""
    from types import SimpleNamespace
    _, v, t = saved_scene(tmp_path)
    some = write_scene_mesh(tmp_path / "some.mesh", v, t)
    args = ("rtao", "analytic:wall", "--mesh", some, "--width", "16", "--height", "9",
            "--rays", "1", "--out", tmp_path / "ao")
    r = run_aolab(*args)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "cannot be checked to be the geometry of analytic:wall" in r.stderr
    assert "the G-buffer carries no scene_hash" in r.stderr
    assert "--allow-unknown-scene" in r.stderr
    assert run_aolab(*args, "--allow-unknown-scene").returncode == 0
    g = aolab.analytic_scene("wall", 16, 9)
    with pytest.raises(ValueError, match="the G-buffer carries no scene_hash"):
        aolab.rtao(g, aolab.load_mesh(some), radius=1.0, rays=1)
    aolab.rtao(g, aolab.load_mesh(some), radius=1.0, rays=1, allow_unknown_scene=True)
    # arrays made in memory: the caller pairs them, nothing to check
    aolab.rtao(g, SimpleNamespace(vertices=v, triangles=t, info={}), radius=1.0, rays=1)


def test_a_mesh_file_without_its_json_needs_allow_unknown_scene(tmp_path):
    exr, v, t = saved_scene(tmp_path)
    bare = write_scene_mesh(tmp_path / "bare.mesh", v, t)
    (tmp_path / "bare.mesh.json").unlink()
    g, mesh = aolab.load_gbuffer(exr), aolab.load_mesh(bare)
    with pytest.raises(ValueError, match=r"the mesh carries no scene_hash \(the mesh's "
                       r"scene_hash None"):
        aolab.rtao(g, mesh, radius=1.0, rays=1)
    aolab.rtao(g, mesh, radius=1.0, rays=1, allow_unknown_scene=True)


def test_compare_names_a_mesh_of_another_scene_where_rtao_did_not_run(tmp_path):
    """Was: "no scene has a mesh beside its reference", while room had one, of another
    scene."""
    from compare_support import SCENES, copy_files
    from compare_support import run_compare
    room = tmp_path / "scenes" / "room"
    copy_files(SCENES / "room", room, ("reference.exr", "reference.json", "manifest.json"))
    copy_files(SCENES / "colored_room", room,   # colored_room's geometry
               ("reference.mesh", "reference.mesh.json"))
    out = tmp_path / "out"
    assert run_compare(tmp_path / "scenes", out, "--methods", "crytek_ssao", "--sweep",
                       "quick", "--rtao-rays", "1") == 0
    report = (out / "report.html").read_text(encoding="utf-8")
    assert "no scene has a mesh beside its reference" not in report
    assert "rtao not run on room:" in report and "is not the geometry of" in report
    results = __import__("json").loads((out / "results.json").read_text())
    assert "is not the geometry of" in results["scenes"]["room"]["rtao_not_run"]


def test_compare_notes_a_scene_rtao_refuses_and_goes_on(tmp_path):
    """The study's rtao rungs on a scene whose R is below the ray offset (room's sidecar with
    ao_distance 1e-5): noted, and the study goes on. Was: the ValueError ended the study."""
    import json
    from compare_support import SCENES, copy_files
    from compare_support import run_compare
    room = tmp_path / "scenes" / "room"
    copy_files(SCENES / "room", room,
               ("reference.exr", "manifest.json", "reference.mesh", "reference.mesh.json"))
    side = json.loads((SCENES / "room" / "reference.json").read_text())
    (room / "reference.json").write_text(json.dumps(dict(side, ao_distance=1e-5)))
    out = tmp_path / "out"
    assert run_compare(tmp_path / "scenes", out, "--methods", "crytek_ssao", "--sweep",
                       "quick", "--rtao-rays", "1") == 0
    results = json.loads((out / "results.json").read_text())
    assert results["scenes"]["room"]["rtao_not_run"].startswith(
        "radius must exceed the ray offset ε")
    assert not [r for r in results["rows"] if r["kind"] == "rtao"]
