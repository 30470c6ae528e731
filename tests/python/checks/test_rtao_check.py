"""rtao against Cycles: the cross-check of the references. Without Blender: `aolab
rtao-check`'s numbers on a committed scene (cached or traced at few rays), the coincident-
face and silhouette analysis. With Blender (skipped without it): a tiny scene rendered with
the mesh pass, rtao at the reference's samples within the combined noise, and Cycles'
behaviour on coincident faces (docs/conventions.md) re-verified."""
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import aolab
from aolab.checks import rtao_check

from blender_support import ROOT, TINY, needs_blender

COINCIDENT = ROOT / "tests" / "data" / "coincident_faces.py"


def reference(scene, cache, *args):
    res = subprocess.run([sys.executable, "-m", "aolab", "reference", "--quiet", str(scene),
                          "--cache", str(cache), *args], capture_output=True, text=True,
                         timeout=900)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    return aolab.load_gbuffer(next(Path(cache).glob("*/reference.exr")))


def test_faces_on_points_counts_coincident_faces():
    # Two unit squares in the plane z = -2 (view space = world space), overlapping on x in
    # [0, 1]; a third square 1 mm above.
    quads = [(-1, 1, 0.0), (0, 2, 0.0), (5, 6, 1e-3)]
    v, t = [], []
    for x0, x1, dz in quads:
        b = len(v)
        v += [(x0, -1, -2 + dz), (x1, -1, -2 + dz), (x1, 1, -2 + dz), (x0, 1, -2 + dz)]
        t += [(b, b + 1, b + 2), (b, b + 2, b + 3)]
    mesh = SimpleNamespace(vertices=np.array(v, np.float32), triangles=np.array(t))
    points = np.array([[-0.5, 0, -2], [0.5, 0, -2], [1.5, 0, -2], [5.5, 0, -2], [9, 0, -2]])
    counts = rtao_check.faces_on_points(points, mesh, np.eye(4))
    assert counts.tolist() == [1, 2, 1, 0, 0]


def test_check_of_a_committed_scene_agrees_at_few_rays(tmp_path, monkeypatch):
    """At 16 rays rtao is noisier than the reference, so only the bias is held to the
    reference (its standard error grows as 1/sqrt(rays)); the numbers and files are all
    there."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.delenv("AOLAB_CACHE", raising=False)
    folder = ROOT / "reference_scenes" / "colored_room"
    r = rtao_check.check_scene(folder, 16, 0, 0, tmp_path / "out")
    assert r["scene"] == "colored_room" and r["pixels"] == 1280 * 720
    assert abs(r["bias"]) < 4 * r["bias_se"] + rtao_check.BIAS_SLACK
    assert r["outliers"]["share"] < 0.01
    assert {"occluded", "creases"} <= set(r["regions"])
    assert (tmp_path / "out" / "colored_room_difference.png").exists()
    cached = list((tmp_path / "cache" / "aolab" / "references" / "rtao").glob(
        "colored_room-*.exr"))
    assert len(cached) == 1
    again = rtao_check.check_scene(folder, 16, 0, 0, None)   # from the cache, same numbers
    assert again["mae"] == r["mae"] and again["rtao"] == r["rtao"]


def test_the_cache_lives_under_aolab_cache(tmp_path, monkeypatch):
    """It went to the parent of $AOLAB_CACHE, beside the folder the user chose."""
    monkeypatch.setenv("AOLAB_CACHE", str(tmp_path / "mine"))
    assert rtao_check.cache_dir() == tmp_path / "mine" / "rtao"
    monkeypatch.delenv("AOLAB_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert rtao_check.cache_dir() == tmp_path / "xdg" / "aolab" / "references" / "rtao"


def test_the_table_names_the_rays_traced():
    """--rays 4 printed the header "rtao 1024 vs Cycles 1024"."""
    row = {"scene": "s", "pixels": 1, "mae": 0.1, "bias": 0.0, "bias_se": 0.0,
           "noise_floor": 0.1, "noise_floor_source": "x", "mae_over_floor": 1.0,
           "agrees": True, "rtao": {"rays": 4},
           "worst_block": {"x": 0, "y": 0, "mean_difference": 0.0},
           "outliers": {"pixels": 0, "share": 0.0, "on_coincident_faces": 0, "examined": 0,
                        "on_silhouettes": 0, "bias_without": 0.0, "bias_without_se": 0.0},
           "regions": {}}
    header = rtao_check.markdown([row]).splitlines()[0]
    assert "| rtao 4 vs Cycles 1024: MAE |" in header, header
    assert "rtao 1024 vs" in rtao_check.markdown([]).splitlines()[0]


def test_update_doc_replaces_only_the_generated_block(tmp_path):
    doc = tmp_path / "d.md"
    doc.write_text(f"intro\n{rtao_check.DOC_BEGIN}\nold\n{rtao_check.DOC_END}\noutro\n")
    rtao_check.update_doc(doc, "| table |", "meta")
    text = doc.read_text()
    assert text.startswith("intro\n") and text.endswith("outro\n")
    assert "| table |" in text and "old" not in text
    other = tmp_path / "e.md"
    other.write_text("nothing generated here\n")
    with pytest.raises(ValueError, match="no .* block"):
        rtao_check.update_doc(other, "x", "y")


@needs_blender
def test_rtao_matches_a_cycles_reference_rendered_with_the_mesh_pass(tmp_path):
    g = reference(TINY, tmp_path / "cache", "--spp", "256", "--passes", "depth,normal,mesh")
    assert "mesh" in g.sidecar["passes"]
    mesh = aolab.mesh_for_gbuffer(g)
    ao = aolab.rtao(g, mesh, radius=g.sidecar["ao_distance"], rays=256)
    valid = np.asarray(g.valid_mask(), bool)
    d = ao[valid].astype(np.float64) - g.reference[valid]
    # Two 256-sample estimates: each pixel's difference has std at most sqrt(2 * 0.25 / 256)
    # = 0.044; the mean of ~5000 pixels is within 4 of its standard errors plus the half
    # float's 2e-4, and the MAE within that per-pixel bound.
    assert abs(d.mean()) < 4 * d.std() / np.sqrt(d.size) + 2e-4, d.mean()
    assert np.abs(d).mean() < 0.044
    assert np.mean(np.abs(d) > 0.3) < 0.01     # outliers only on silhouettes


@needs_blender
def test_cycles_darkens_coincident_faces_and_rtao_does_not(tmp_path):
    """docs/conventions.md, "Coincident faces": where two faces coincide, Cycles' AO rays
    leave one face and meet the other at a distance of float rounding, so the reference is
    dark there (0 or 1 per sample), while the same floor beside it is exactly 1; rtao's
    offset lifts every ray off both faces, so it gives 1 on the whole floor."""
    g = reference(COINCIDENT, tmp_path / "cache", "--spp", "64", "--passes",
                  "depth,normal,mesh")
    valid = np.asarray(g.valid_mask(), bool)
    assert valid.all()
    x = (np.arange(g.width) + 0.5 - g.cx) / g.fx * 3.0          # world x of each column
    slab = np.broadcast_to((x > 0.1) & (x < 1.0), g.depth.shape)  # over the slab, off its edges
    open_floor = np.broadcast_to(x < -0.1, g.depth.shape)
    assert np.all(g.reference[open_floor] == 1.0)
    assert g.reference[slab].mean() < 0.9, g.reference[slab].mean()
    mesh = aolab.mesh_for_gbuffer(g)
    ao = aolab.rtao(g, mesh, radius=g.sidecar["ao_distance"], rays=64)
    assert np.all(ao[open_floor | slab] == 1.0)
    # The check finds those pixels on coincident faces.
    points = np.asarray(g.view_positions())[slab]
    assert np.all(rtao_check.faces_on_points(points, mesh, g.sidecar["camera_to_world"]) >= 2)
