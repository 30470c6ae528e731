"""rtao through the Python API and the command line: the closed forms of the analytic scenes
traced against their planes, exactly 1 on an open plane, the same bits on any thread count,
the GIL released while rays are traced, bad meshes and settings as ValueErrors naming them,
random G-buffers and meshes giving finite AO in [0, 1] or the offset rule's refusal
(hypothesis). The C++ known answers are tests/cpp/raytracing/rtao_test.cpp's; the check
against the Cycles references is test_rtao_check.py's; the ranges (docs/conventions.md) are
test_hostile_inputs.py's."""
import subprocess
import sys
import threading
import time
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import aolab


def traced(name, width=96, height=54, **params):
    """An analytic scene's G-buffer and its planes as a mesh (1 km squares)."""
    g = aolab.analytic_scene(name, width, height, **params)
    v, t = aolab.analytic_scene_mesh(name, **params)
    return g, SimpleNamespace(vertices=v, triangles=t, info={})


def scored(g, depth_limit=400.0):
    ref = g.reference
    return np.isfinite(ref) & np.asarray(g.valid_mask(), bool) & (g.depth < depth_limit)


@pytest.mark.parametrize("name, radius", [("ceiling", 2.0), ("wall", 0.5), ("crease", 1.0)])
def test_closed_forms_within_monte_carlo_error(name, radius):
    g, mesh = traced(name, radius=radius)
    rays = 256
    ao = aolab.rtao(g, mesh, radius=radius, rays=rays)
    m = scored(g)
    ref = g.reference[m].astype(np.float64)
    assert m.sum() > 2000
    # The mean of M pixels has binomial std at most sqrt(sum p(1-p)/N)/M; 4 of them + 1e-4.
    sigma = np.sqrt(np.sum(ref * (1 - ref) / rays)) / m.sum()
    assert abs(ao[m].mean() - ref.mean()) < 4 * sigma + 1e-4
    assert ref.mean() < 0.97   # the scene shows occlusion


def test_open_plane_is_exactly_one_and_background_is_one():
    g, mesh = traced("plane", tilt=75.0, azimuth=20.0)
    ao = aolab.rtao(g, mesh, radius=3.0, rays=32)
    assert ao.dtype == np.float32 and ao.shape == g.depth.shape
    assert np.all(ao == 1.0)


def test_same_bits_for_any_thread_count_and_a_prebuilt_scene():
    g, mesh = traced("blocks", 64, 36)
    scene = aolab.ray_scene(mesh, g, threads=1)
    assert scene.triangles == len(mesh.triangles) and scene.build_seconds >= 0
    one = aolab.rtao(g, scene, radius=1.0, rays=16, threads=1)
    assert np.array_equal(one, aolab.rtao(g, scene, radius=1.0, rays=16, threads=2))
    assert np.array_equal(one, aolab.rtao(g, mesh, radius=1.0, rays=16, threads=3))


def test_the_gil_is_released_while_rays_are_traced():
    g, mesh = traced("blocks", 320, 180)
    scene = aolab.ray_scene(mesh, g)
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        t0 = time.perf_counter()
        aolab.rtao(g, scene, radius=1.0, rays=64, threads=1)
        t1 = time.perf_counter()
    finally:
        stop.set()
        t.join()
    during = [x for x in ticks if t0 < x < t1]
    assert t1 - t0 > 0.05 and len(during) >= 5, (t1 - t0, len(during))


def test_settings_meshes_and_cameras_are_checked_by_name():
    g, mesh = traced("blocks", 16, 9)
    with pytest.raises(ValueError, match="rays"):
        aolab.rtao(g, mesh, radius=1.0, rays=0)
    with pytest.raises(ValueError, match="radius"):
        aolab.rtao(g, mesh, radius=float("nan"))
    with pytest.raises(ValueError, match="seed"):
        aolab.rtao(g, mesh, radius=1.0, seed=-1)
    c2w = np.eye(4)
    v = np.zeros((3, 3), np.float32)
    with pytest.raises(ValueError, match="triangles"):
        aolab.RayScene(v, np.array([[0, 1, 3]]), c2w)
    with pytest.raises(ValueError, match="triangles"):
        aolab.RayScene(v, np.array([[0, 1, -1]]), c2w)
    with pytest.raises(ValueError, match="triangles"):
        aolab.RayScene(v, np.array([[0.0, 1.0, 2.0]]), c2w)   # float indices
    with pytest.raises(ValueError, match="vertices"):
        aolab.RayScene(np.zeros((3, 2)), np.array([[0, 1, 2]]), c2w)
    with pytest.raises(ValueError, match="vertices"):
        aolab.RayScene(np.array([[0, 0, np.nan]] * 3), np.array([[0, 1, 2]]), c2w)
    with pytest.raises(ValueError, match="camera_to_world"):
        aolab.RayScene(v, np.array([[0, 1, 2]]), np.eye(3))
    with pytest.raises(ValueError, match="camera_to_world"):
        aolab.RayScene(v, np.array([[0, 1, 2]]), 2 * np.eye(4))
    no_camera = aolab.GBuffer(g.depth, g.normal, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy)
    with pytest.raises(ValueError, match="camera_to_world"):
        aolab.rtao(no_camera, SimpleNamespace(vertices=v, triangles=np.array([[0, 1, 2]]),
                                              info={}), radius=1.0)
    no_normal = aolab.GBuffer(g.depth, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy)
    no_normal.sidecar = g.sidecar
    with pytest.raises(ValueError, match="normal"):
        aolab.rtao(no_normal, mesh, radius=1.0)


def test_settings_are_described():
    described = {s["name"]: s for s in aolab.rtao_settings()}
    assert set(described) == {"radius", "rays", "seed"}
    assert described["rays"]["default"] == 1024
    assert described["rays"]["min"] == 1 and described["rays"]["max"] == 65536


@settings(max_examples=40, deadline=None)
@pytest.mark.filterwarnings("ignore::aolab.RtaoRangeWarning")
@given(seed=st.integers(0, 2**31 - 1), size=st.tuples(st.integers(1, 9), st.integers(1, 9)),
       triangles=st.integers(0, 12), radius=st.floats(1e-4, 1e4), data=st.data())
def test_random_gbuffers_and_meshes_give_finite_ao_in_unit_range(seed, size, triangles,
                                                                 radius, data):
    rng = np.random.default_rng(seed)
    w, h = size
    depth = rng.uniform(0.1, 20.0, (h, w)).astype(np.float32)
    # Hostile depths on some pixels: NaN, inf, 0, negative, background.
    bad = rng.random((h, w)) < 0.25
    depth[bad] = rng.choice(np.array([np.nan, np.inf, 0.0, -1.0, 1e10], np.float32),
                            int(bad.sum()))
    normal = rng.normal(size=(h, w, 3)).astype(np.float32)   # non-unit, any direction
    if data.draw(st.booleans()):
        normal[rng.random((h, w)) < 0.3] = 0.0               # zero normals: estimated
    g = aolab.GBuffer(depth, normal, fx=float(rng.uniform(0.5, 1e3)),
                      fy=float(rng.uniform(0.5, 1e3)), cx=w / 2, cy=h / 2)
    v = rng.uniform(-30, 30, (max(3, 3 * triangles), 3)).astype(np.float32)
    t = rng.integers(0, len(v), (triangles, 3))
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    c2w = np.eye(4)
    c2w[:3, :3] = q * np.sign(np.linalg.det(q))
    c2w[:3, 3] = rng.uniform(-10, 10, 3)
    scene = aolab.RayScene(v, t.reshape(-1, 3), c2w)
    rays = int(rng.integers(1, 9))
    refusal = aolab.rtao_range(g, scene, radius=radius)["refusal"]
    if refusal:   # the ray offset reaches R somewhere (docs/conventions.md, "Ranges")
        with pytest.raises(ValueError) as e:
            aolab.rtao(g, scene, radius=radius, rays=rays, seed=seed % 1000)
        assert str(e.value) == refusal
        return
    ao = aolab.rtao(g, scene, radius=radius, rays=rays, seed=seed % 1000)
    assert ao.shape == (h, w) and np.all(np.isfinite(ao))
    assert np.all((ao >= 0) & (ao <= 1))
    assert np.all(ao[~np.asarray(g.valid_mask(), bool)] == 1.0)


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "aolab", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=300)


def test_cli_on_an_analytic_scene_writes_and_scores(tmp_path):
    r = run_cli("rtao", "analytic:ceiling", "--radius", "2", "--width", "64", "--height", "36",
                "--rays", "64", "--threads", "2", "--out", str(tmp_path / "c"), "--json",
                str(tmp_path / "c.json"))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "c.exr").exists() and (tmp_path / "c.png").exists()
    assert "against the reference" in r.stdout and "BVH" in r.stdout
    import json
    result = json.loads((tmp_path / "c.json").read_text())
    assert result["rays"] == 64 and result["triangles"] > 0 and result["metrics"]["mae"] < 0.05


@pytest.mark.parametrize("args, message", [
    (["--rays", "0"], "--rays"),
    (["--rays", "70000"], "--rays"),
    (["--seed", "-1"], "--seed"),
    (["--radius", "nan"], "--radius"),
    (["--mesh", "/nonexistent.mesh"], "mesh"),
])
def test_cli_errors_are_one_line_naming_the_option(args, message, tmp_path):
    r = run_cli("rtao", "analytic:plane", "--width", "8", "--height", "8",
                "--out", str(tmp_path / "x"), *args)
    assert r.returncode == 2
    assert message in r.stderr and "Traceback" not in r.stderr
