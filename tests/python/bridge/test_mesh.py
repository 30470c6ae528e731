"""The bridge's `mesh` pass: the .mesh file (bpy-free), the export inside Blender (geometry as
rendered, the skipped objects, the scene restored), its agreement with the Depth pass, `aolab
mesh` and the committed scenes' meshes. Blender runs for real, headless; those tests skip
where it is absent."""
import hashlib
import itertools
import json
import os
import struct
import subprocess
import sys

import numpy as np
import pytest

import aolab
from aolab.bridge import mesh as meshfile
from aolab.bridge.passes import parse_passes, required_passes
from blender_support import ROOT, TINY, blender_check, blender_spy, needs_blender

SCENES = ROOT / "reference_scenes"
MESH_SCENE = ROOT / "tests" / "data" / "mesh_scene.py"
MESH_SCENE_TRIANGLES = 620   # as rendered (tests/data/mesh_scene.py)


# ---- the file format (no bpy) ----

def small_mesh():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float64) + 0.25
    t = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1]], np.int64)
    return v, t


def test_write_read_round_trip(tmp_path):
    v, t = small_mesh()
    path = tmp_path / "scene.mesh"
    info = meshfile.write_mesh(path, v, t, {"space": "world", "scene_hash": "abc",
                                            "objects": [{"name": "A", "first_triangle": 0,
                                                         "triangles": 3}]})
    data = path.read_bytes()
    assert data[:8] == b"AOLABMSH" and struct.unpack("<4I", data[8:24]) == (1, 4, 3, 0)
    assert len(data) == 24 + 4 * 12 + 3 * 12
    side = json.loads((tmp_path / "scene.mesh.json").read_text())
    assert side == info
    assert list(side)[:7] == ["format", "version", "file", "sha256", "vertices", "triangles",
                              "space"]
    assert side["file"] == "scene.mesh" and side["sha256"] == hashlib.sha256(data).hexdigest()
    m = aolab.load_mesh(path)
    assert m.vertices.dtype == np.float32 and m.vertices.shape == (4, 3)
    assert m.triangles.dtype == np.uint32 and m.triangles.shape == (3, 3)
    np.testing.assert_array_equal(m.vertices, v.astype(np.float32))
    np.testing.assert_array_equal(m.triangles, t)
    assert m.info == info
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.mesh", "scene.mesh.json"]
    (tmp_path / "scene.mesh.json").unlink()   # without its JSON: info {}
    assert aolab.load_mesh(path).info == {}
    empty = tmp_path / "empty.mesh"
    meshfile.write_mesh(empty, np.zeros((0, 3)), np.zeros((0, 3), int), {})
    m = aolab.load_mesh(empty)
    assert m.vertices.shape == (0, 3) and m.triangles.shape == (0, 3)


def corrupt(data: bytes, case: str) -> bytes:
    header = bytearray(data)
    if case == "magic":
        return b"AOLABMSX" + data[8:]
    if case == "version":
        return data[:8] + struct.pack("<I", 2) + data[12:]
    if case == "reserved":
        return data[:20] + struct.pack("<I", 7) + data[24:]
    if case == "truncated":
        return data[:-4]
    if case == "extra":
        return data + b"\0\0\0\0"
    if case == "short":
        return data[:10]
    if case == "index":
        header[-4:] = struct.pack("<I", 4)   # the last index of the last triangle: V
        return bytes(header)
    if case == "nan":
        header[24:28] = struct.pack("<f", float("nan"))
        return bytes(header)
    if case == "inf":
        header[28:32] = struct.pack("<f", float("inf"))
        return bytes(header)
    raise AssertionError(case)


@pytest.mark.parametrize("case, said", [
    ("magic", "not an AO Lab mesh"), ("version", "version 2 is unknown"),
    ("reserved", "reserved field must be 0, got 7"), ("truncated", "truncated"),
    ("extra", "has extra bytes"), ("short", "shorter than the 24-byte header"),
    ("index", "indexes vertex 4, but the file has 4 vertices"),
    ("nan", "vertex 0 is not finite"), ("inf", "vertex 0 is not finite"),
])
def test_each_corruption_is_a_value_error_naming_the_file(tmp_path, case, said):
    v, t = small_mesh()
    path = tmp_path / "bad.mesh"
    meshfile.write_mesh(path, v, t, {})
    (tmp_path / "bad.mesh.json").unlink()   # the bytes themselves are checked
    path.write_bytes(corrupt(path.read_bytes(), case))
    with pytest.raises(ValueError, match=said) as e:
        aolab.load_mesh(path)
    assert str(path) in str(e.value)


def test_a_json_that_does_not_describe_the_bytes_is_refused(tmp_path):
    v, t = small_mesh()
    path = tmp_path / "a.mesh"
    meshfile.write_mesh(path, v, t, {})
    side = tmp_path / "a.mesh.json"
    good = json.loads(side.read_text())
    data = bytearray(path.read_bytes())
    data[24] ^= 1                              # a vertex changed after the export
    path.write_bytes(bytes(data))
    with pytest.raises(ValueError, match="sha256 .* does not match") as e:
        aolab.load_mesh(path)
    assert str(side) in str(e.value)
    meshfile.write_mesh(path, v, t, {})
    for key, value, said in [("triangles", 9, '"triangles" is 9, the .mesh has 3'),
                             ("format", "other", "not an AO Lab mesh JSON")]:
        side.write_text(json.dumps({**good, key: value}))
        with pytest.raises(ValueError, match=said):
            aolab.load_mesh(path)
    side.write_text("{not json")
    with pytest.raises(ValueError, match="not valid UTF-8 JSON"):
        aolab.load_mesh(path)


def test_missing_file_and_non_regular_files(tmp_path):
    with pytest.raises(FileNotFoundError):
        aolab.load_mesh(tmp_path / "none.mesh")
    (tmp_path / "dir.mesh").mkdir()
    with pytest.raises(ValueError, match="must be a regular file, got .*which is a folder"):
        aolab.load_mesh(tmp_path / "dir.mesh")


@pytest.mark.parametrize("vertices, triangles, said", [
    (np.zeros((3, 2)), np.zeros((1, 3), int), "vertices must be a float"),
    (np.zeros((3, 3)), np.zeros((1, 3)), "triangles must be an integer"),
    (np.zeros((3, 3)), np.array([[0, 1, 3]]), r"index vertices in \[0, 3\)"),
    (np.zeros((3, 3)), np.array([[0, -1, 2]]), r"index vertices in \[0, 3\)"),
    (np.array([[0, 0, 0], [1e39, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]),
     "vertex 1 is"),
])
def test_write_refuses_what_it_could_not_read_back(tmp_path, vertices, triangles, said):
    with pytest.raises(ValueError, match=said):
        meshfile.write_mesh(tmp_path / "x.mesh", vertices, triangles, {})
    assert not list(tmp_path.iterdir())


def test_mesh_is_a_pass_but_never_required():
    assert parse_passes("normal,mesh") == ["depth", "normal", "mesh"]
    assert parse_passes("mesh") == ["depth", "mesh"]
    with pytest.raises(ValueError, match="mesh"):   # the message lists it among the passes
        parse_passes("meshes")
    kinds = [{"needs_normal": n, "needs_color": c} for n in (False, True) for c in (False, True)]
    effects = ["color_bleeding", "luminance_sensitivity"]
    for k in range(len(kinds) + 1):
        for methods in itertools.combinations(kinds, k):
            for e in range(3):
                for chosen in itertools.combinations(effects, e):
                    assert "mesh" not in required_passes(list(methods), list(chosen))


def tiny_gbuffer(tmp_path, scene_hash):
    g = aolab.GBuffer(np.full((4, 6), 2.0, np.float32), fx=5.0, fy=5.0, cx=3.0, cy=2.0)
    aolab.save_gbuffer(tmp_path / "shot.exr", g, sidecar={"scene_hash": scene_hash})
    return aolab.load_gbuffer(tmp_path / "shot.exr")


def test_mesh_for_gbuffer_matches_the_scene_hash(tmp_path):
    g = tiny_gbuffer(tmp_path, "h1")
    with pytest.raises(FileNotFoundError, match="aolab mesh"):
        aolab.mesh_for_gbuffer(g)
    v, t = small_mesh()
    meshfile.write_mesh(tmp_path / "shot.mesh", v, t, {"scene_hash": "h1"})
    assert aolab.mesh_for_gbuffer(g).triangles.shape == (3, 3)
    meshfile.write_mesh(tmp_path / "shot.mesh", v, t, {"scene_hash": "h2"})
    with pytest.raises(ValueError, match="scene_hash 'h2' differs .* 'h1'.*aolab mesh"):
        aolab.mesh_for_gbuffer(g)
    (tmp_path / "shot.mesh.json").unlink()
    with pytest.raises(ValueError, match="scene_hash None"):
        aolab.mesh_for_gbuffer(g)
    with pytest.raises(ValueError, match="load_gbuffer"):
        aolab.mesh_for_gbuffer(aolab.GBuffer(np.ones((2, 2), np.float32), fx=1, fy=1, cx=1,
                                             cy=1))


# ---- ray casting against the exported triangles ----

def planar_depth(mesh, side: dict, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Planar depth of the nearest triangle along the pinhole ray through each pixel centre
    (docs/conventions.md), inf where none is hit: Moller-Trumbore in view space (float64)."""
    c2w = np.asarray(side["camera_to_world"], np.float64)
    view = (mesh.vertices.astype(np.float64) - c2w[:3, 3]) @ c2w[:3, :3]   # R^T (p - t)
    tri = view[mesh.triangles.astype(np.int64)]
    a, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    s = -a                                      # ray origin (the camera) minus a
    q = np.cross(s, e1)
    t_num = np.einsum("ij,ij->i", e2, q)
    dirs = np.stack([(cols + 0.5 - side["cx"]) / side["fx"],
                     -(rows + 0.5 - side["cy"]) / side["fy"], -np.ones(len(rows))], -1)
    out = np.full(len(rows), np.inf)
    chunk = max(1, 2_000_000 // max(len(tri), 1))
    for i in range(0, len(dirs), chunk):
        d = dirs[i:i + chunk, None, :]
        p = np.cross(d, e2[None])
        det = np.einsum("rtj,tj->rt", p, e1)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            u = np.einsum("rtj,tj->rt", p, s) * inv
            v = np.einsum("rj,tj->rt", dirs[i:i + chunk], q) * inv
            t = t_num[None] * inv
        hit = (np.abs(det) > 1e-300) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
        out[i:i + chunk] = np.where(hit, t, np.inf).min(axis=1)
    return out   # the direction has z = -1, so the ray parameter is the planar depth


def depth_agreement(mesh, g, rows, cols):
    """(geometry pixels, relative error on them, pixels where only one side sees geometry)."""
    depth = g.depth[rows, cols].astype(np.float64)
    geometry = depth < g.sidecar.get("background_depth", 1e9)
    cast = planar_depth(mesh, g.sidecar, rows, cols)
    rel = np.abs(cast[geometry] - depth[geometry]) / depth[geometry]
    return geometry, rel, int(np.sum(np.isfinite(cast) != geometry))


@pytest.mark.parametrize("name", ["analytic", "colored_room", "engine", "grille", "room",
                                  "street"])
def test_committed_meshes_match_their_references(name):
    """The committed geometry is that of the committed reference: same scene_hash, and on a
    grid of pixels its ray-cast depth is the Depth pass."""
    folder = SCENES / name
    g = aolab.load_gbuffer(folder / "reference.exr")
    mesh = aolab.mesh_for_gbuffer(g)
    assert mesh.info["scene_hash"] == g.sidecar["scene_hash"]
    assert mesh.info["camera_to_world"] == g.sidecar["camera_to_world"]
    stride = 48 if len(mesh.triangles) > 20000 else 16
    rows, cols = (a.ravel() for a in np.mgrid[stride // 2:g.height:stride,
                                              stride // 3:g.width:stride])
    geometry, rel, disagree = depth_agreement(mesh, g, rows, cols)
    assert geometry.sum() > 100 and disagree == 0
    assert rel.max() < 1e-4, (name, rel.max())


# ---- inside Blender ----

def allowed(diff: list[str]) -> list[str]:
    """An object hidden in the viewport was never evaluated before the export, so Blender
    showed its dimensions from a unit box; evaluating it fills in the real ones. That cache is
    not a setting and cannot be put back (its scale, which dimensions derive from, is)."""
    return [d for d in diff if not d.endswith("ViewportHidden.object.dimensions: [1.0, 1.0, "
                                              "1.0] -> [0.30000001192092896, 0.30000001192092896"
                                              ", 0.30000001192092896]")]


@needs_blender
def test_export_gives_the_render_geometry_and_restores_the_scene():
    r = blender_check("mesh_check.py", str(MESH_SCENE))
    objects = [(o["name"], o["triangles"], o["instance"]) for o in r["info"]["objects"]]
    # Render levels and modifiers, not the viewport's: Smooth 192 (48 in the viewport), Row
    # 36 (12); the viewport-hidden and eye-hidden objects; both collection instances.
    # The curve and the metaball at their render resolutions, as mesh instances of
    # themselves; all 10 particles (5 shown in the viewport), but not their emitter.
    assert objects == [("Floor", 12, False), ("Smooth", 192, False), ("Row", 36, False),
                       ("Prop", 12, True), ("Prop", 12, True), ("ViewportHidden", 12, False),
                       ("EyeHidden", 12, False), ("Tube", 72, True), ("Blob", 140, True),
                       *[("Prop", 12, True)] * 10]
    assert r["info"]["triangles"] == 620 == MESH_SCENE_TRIANGLES
    first = [o["first_triangle"] for o in r["info"]["objects"]]
    assert first == [0, 12, 204, 240, 252, 264, 276, 288, 360, *range(500, 620, 12)]
    assert {s["name"]: s["why"] for s in r["info"]["skipped"]} == {
        "NoShadow": "NoShadow has Ray Visibility > Shadow off (visible_shadow): Cycles' AO "
                    "rays ignore it",
        "RenderHidden": "hidden from render (Disable in Renders, hide_render)",
        "Emitter": "an instancer whose own faces are not rendered "
                   "(show_instancer_for_render off)"}
    assert r["stages"] == ["prepare", "mesh", "done"]
    # What Blender evaluates for a real render: the same surfaces (but for the one Cycles' AO
    # ignores), the same triangle counts and the same world-space vertices.
    rendered = [o for o in r["render_depsgraph"] if o["visible_shadow"]]
    assert [(o["name"], o["triangles"], o["instance"]) for o in rendered] == objects
    np.testing.assert_allclose(r["exported_vertex_sums"], [o["vertex_sum"] for o in rendered],
                               rtol=1e-6, atol=1e-5)
    for case in ("export", "failed", "reference_with_mesh", "cancel_mesh"):
        assert allowed(r[case]["diff"]) == [], (case, r[case]["diff"][:10])
    assert r["export"]["outcome"] == "ok" and r["failed"]["outcome"].startswith("failed")
    assert r["cancel_mesh"]["outcome"] == "cancelled"
    assert not any(name.startswith("cancelled") for name in r["cancel_mesh"]["left"])
    assert r["sidecar"]["passes"] == ["depth", "mesh", "ao"]
    assert r["sidecar"]["mesh_file"] == "reference.mesh"
    assert r["reference_mesh_hash"] == r["sidecar"]["scene_hash"] == r["info"]["scene_hash"]


def aolab_cmd(*args, env=None):
    return subprocess.run([sys.executable, "-m", "aolab", *args], capture_output=True, text=True,
                          env=env, timeout=900)


@needs_blender
def test_mesh_pass_agrees_with_the_depth_pass(tmp_path):
    """Rays through every pixel centre of a 64x48 reference hit the exported triangles at the
    Depth pass's planar depth, and miss exactly where Cycles saw background."""
    res = aolab_cmd("reference", "--quiet", str(MESH_SCENE), "--spp", "1", "--passes",
                    "depth,normal,mesh", "--cache", str(tmp_path / "cache"))
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    folder = next((tmp_path / "cache").iterdir())
    assert sorted(p.name for p in folder.iterdir()) == [   # SHA256SUMS: the entry's checksums
        "SHA256SUMS", "reference.exr", "reference.json", "reference.mesh", "reference.mesh.json"]
    g = aolab.load_gbuffer(folder / "reference.exr")
    assert g.sidecar["passes"] == ["depth", "normal", "mesh", "ao"]
    assert g.sidecar["mesh_file"] == "reference.mesh"
    mesh = aolab.mesh_for_gbuffer(g)
    assert (g.width, g.height) == (64, 48) and len(mesh.triangles) == MESH_SCENE_TRIANGLES
    rows, cols = (a.ravel() for a in np.mgrid[0:g.height, 0:g.width])
    geometry, rel, disagree = depth_agreement(mesh, g, rows, cols)
    assert 0.2 < geometry.mean() < 1 and disagree == 0
    assert rel.max() < 1e-4, rel.max()


@needs_blender
def test_aolab_mesh_is_cached_and_its_errors_name_the_option(tmp_path):
    cache = tmp_path / "cache"
    res = aolab_cmd("mesh", "--quiet", str(TINY), "--cache", str(cache), "--out",
                    str(tmp_path / "out"), "--resolution", "80x60")
    assert res.returncode == 0 and "exported" in res.stdout, res.stdout + res.stderr
    folder = next(cache.iterdir())
    assert folder.name.startswith("tiny_scene-mesh-")
    before = {p.name: p.stat().st_mtime_ns for p in folder.iterdir()}
    assert sorted(before) == ["SHA256SUMS", "reference.mesh", "reference.mesh.json"]
    spy, mark = blender_spy(tmp_path)
    res = aolab_cmd("mesh", "--quiet", str(TINY), "--cache", str(cache), "--resolution", "80x60",
                    env=dict(os.environ, AOLAB_BLENDER=str(spy)))
    assert res.returncode == 0 and "cached" in res.stdout, res.stdout + res.stderr
    assert not mark.exists()
    assert {p.name: p.stat().st_mtime_ns for p in folder.iterdir()} == before
    m = aolab.load_mesh(tmp_path / "out" / "reference.mesh")
    assert len(m.triangles) == 36 and m.info["width"] == 80 and m.info["height"] == 60
    assert [o["name"] for o in m.info["objects"]] == ["Floor", "Wall", "Box"]
    for args, said in [(["--resolution", "2x2"], "--resolution must be WxH"),
                       (["--resolution", "wide"], "--resolution must be WxH"),
                       (["--camera", "Nope"], "camera 'Nope' not found"),
                       ([], "no such scene")]:
        scene = str(tmp_path / "missing.py") if not args else str(TINY)
        res = aolab_cmd("mesh", "--quiet", scene, "--cache", str(cache), *args)
        lines = res.stderr.strip().splitlines()
        assert res.returncode == 2 and len(lines) == 1 and lines[0].startswith("aolab: "), res
        assert said in lines[0], lines
