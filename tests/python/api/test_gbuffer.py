"""aolab.GBuffer and the array boundary: zero-copy input, conversions, errors that name
the parameter, validity mask and reconstruction."""
import subprocess
import sys

import numpy as np
import pytest

import aolab

K = dict(fx=100.0, fy=100.0, cx=8.0, cy=6.0)


def plane(h=12, w=16, d=2.0):
    depth = np.full((h, w), d, np.float32)
    normal = np.zeros((h, w, 3), np.float32)
    normal[..., 2] = 1
    return depth, normal


def test_float32_arrays_are_used_without_copy():
    depth, normal = plane()
    g = aolab.GBuffer(depth, normal, **K)
    assert np.shares_memory(g.depth, depth)
    assert np.shares_memory(g.normal, normal)


def test_other_dtypes_are_converted_once():
    depth, normal = plane()
    g = aolab.GBuffer(depth.astype(np.float64), normal.astype(np.float16), **K)
    assert g.depth.dtype == np.float32 and g.normal.dtype == np.float32
    ao = aolab.compute("hbao", g, radius=1.0)
    assert ao.dtype == np.float32 and ao.shape == depth.shape and ao.flags.c_contiguous


@pytest.mark.parametrize("kwargs, name", [
    (dict(depth=np.zeros((3,), np.float32)), "depth"),
    (dict(depth=np.zeros((0, 4), np.float32)), "depth"),
    (dict(normal=np.zeros((12, 16, 2), np.float32)), "normal"),
    (dict(normal=np.zeros((12, 15, 3), np.float32)), "normal"),
    (dict(color=np.zeros((12, 16, 5), np.float32)), "color"),
    (dict(fx=0.0), "fx"), (dict(fy=-1.0), "fy"), (dict(cx=float("nan")), "cx"),
    (dict(cy=float("inf")), "cy"), (dict(background_depth=0.0), "background_depth"),
])
def test_bad_input_raises_valueerror_naming_parameter(kwargs, name):
    depth, normal = plane()
    args = dict(depth=depth, normal=normal, **K)
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        aolab.GBuffer(args.pop("depth"), args.pop("normal"), args.pop("color", None), **args)


def test_valid_mask_follows_background_rule():
    depth, normal = plane()
    depth[0, :5] = [1e10, 65504, np.inf, np.nan, -1]
    depth[1, 0] = 0
    mask = aolab.GBuffer(depth, normal, **K).valid_mask()
    assert mask.dtype == bool
    assert list(mask[0, :5]) == [False, True, False, False, False]
    assert not mask[1, 0]
    eevee = aolab.GBuffer(depth, normal, background_depth=65504, **K).valid_mask()
    assert not eevee[0, 1]


def test_view_positions_follow_convention():
    depth, normal = plane(d=5.0)
    p = aolab.GBuffer(depth, normal, **K).view_positions()
    assert p.shape == (12, 16, 3)
    np.testing.assert_allclose(p[..., 2], -5.0)
    # Pixel (i, j) centre at (i + 0.5, j + 0.5): x = (i + 0.5 - cx)/fx * d, y up.
    np.testing.assert_allclose(p[0, 15, 0], (15.5 - 8) / 100 * 5, rtol=1e-6)
    np.testing.assert_allclose(p[0, 0, 1], -(0.5 - 6) / 100 * 5, rtol=1e-6)


def test_method_registry_describes_settings():
    assert "hbao" in aolab.methods()
    info = aolab.method_info("hbao")
    assert info["needs_normal"]
    names = {s["name"]: s for s in info["settings"]}
    assert names["directions"]["default"] == 8 and names["steps"]["default"] == 8
    assert names["radius"]["unit"]
    with pytest.raises(ValueError, match="method"):
        aolab.method_info("nope")


@pytest.mark.parametrize("settings, name", [
    (dict(radius=0.0), "radius"), (dict(radius=-1.0), "radius"), (dict(radius=np.nan), "radius"),
    (dict(radius=1.0, directions=0), "directions"), (dict(radius=1.0, steps=1.5), "steps"),
    (dict(radius=1.0, bogus=3), "bogus"), (dict(radius=1.0, jitter="yes"), "jitter"),
    (dict(radius=1.0, threads=-1), "threads"),
])
def test_compute_errors_name_parameter(settings, name):
    depth, normal = plane()
    g = aolab.GBuffer(depth, normal, **K)
    with pytest.raises(ValueError, match=name):
        aolab.compute("hbao", g, **settings)


def test_compute_needs_normals_for_hbao_and_says_how_to_estimate_them():
    depth, _ = plane()
    g = aolab.GBuffer(depth, **K)
    with pytest.raises(ValueError, match="normal.*prepared_normals"):
        aolab.compute("hbao", g, radius=1.0)
    estimated = aolab.GBuffer(depth, g.prepared_normals(), **K)
    assert (aolab.compute("hbao", estimated, radius=1.0) == 1).all()


def test_import_from_any_folder(tmp_path):
    # The package is found through the path the test command sets (a .pth after setup),
    # not through the working directory.
    out = subprocess.run([sys.executable, "-c", "import aolab; print(aolab.methods())"],
                         cwd=tmp_path, capture_output=True, text=True, check=True)
    assert "hbao" in out.stdout
