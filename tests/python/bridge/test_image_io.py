"""Image files through the public aolab API: G-buffer EXR + sidecar round trips, Blender's
channel layout (checked with OpenImageIO's own Python module), world-space normals, errors,
and AO images written as EXR and PNG."""

import json
import os

import numpy as np
import OpenImageIO as oiio
import pytest

import aolab
from aolab import _core

# Half floats keep 11 significant bits: relative error 2**-11 ~ 4.9e-4, so 1e-3 bounds the
# error of values in [-1, 1].
HALF_TOL = 1e-3
CYCLES_BACKGROUND = np.float32(1e10)


def make_gbuffer(with_color=True):
    """A 7x5 tilted plane with a background corner, per-pixel unit normals, a colour ramp."""
    h, w = 5, 7
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    depth = (2.0 + 0.123457 * x + 0.0713 * y).astype(np.float32)
    depth[0, 0] = depth[0, 1] = depth[4, 6] = CYCLES_BACKGROUND
    n = np.stack([0.1 * (x - 3), 0.15 * (y - 2), np.ones_like(x)], axis=-1)
    normal = (n / np.linalg.norm(n, axis=-1, keepdims=True)).astype(np.float32)
    color = np.stack([(x + y + c) / 16.0 for c in range(3)], axis=-1).astype(np.float32)
    g = aolab.GBuffer(depth, normal, color if with_color else None,
                      fx=6.5, fy=6.25, cx=3.5, cy=2.5)
    ao = ((x * h + y) / (w * h)).astype(np.float32)
    return g, ao


def read_oiio(path):
    """(pixels as float32 (H, W, C), channel names, channel formats) via OpenImageIO."""
    inp = oiio.ImageInput.open(str(path))
    assert inp is not None, oiio.geterror()
    spec = inp.spec()
    pixels = inp.read_image("float")
    formats = [str(t) for t in spec.channelformats] or [str(spec.format)] * spec.nchannels
    inp.close()
    return pixels, list(spec.channelnames), formats


def write_oiio(path, channels):
    """Writes an EXR in Blender's layout: `channels` is a list of (name, format, (H, W) array)."""
    h, w = channels[0][2].shape
    spec = oiio.ImageSpec(w, h, len(channels), "float")
    spec.channelnames = tuple(name for name, _, _ in channels)
    spec.channelformats = tuple(oiio.TypeDesc(fmt) for _, fmt, _ in channels)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(np.stack([a for _, _, a in channels], axis=-1).astype(np.float32))
    out.close()


def test_save_load_round_trip(tmp_path):
    g, ao = make_gbuffer()
    path = tmp_path / "scene.exr"
    aolab.save_gbuffer(path, g, reference=ao,
                       sidecar={"ao_distance": 1.25, "samples": 1024, "bridge": {"hash": "abc"}})
    assert sorted(os.listdir(tmp_path)) == ["scene.exr", "scene.json"]

    back = aolab.load_gbuffer(path)
    assert back.depth.dtype == np.float32
    np.testing.assert_array_equal(back.depth, g.depth)  # float32: exact, background included
    np.testing.assert_allclose(back.normal, g.normal, atol=HALF_TOL)
    np.testing.assert_allclose(back.color, g.color, atol=HALF_TOL)
    assert back.reference.shape == (5, 7)
    np.testing.assert_allclose(back.reference, ao, atol=HALF_TOL)
    assert (back.fx, back.fy, back.cx, back.cy) == (6.5, 6.25, 3.5, 2.5)
    assert back.background_depth == g.background_depth
    side = back.sidecar
    assert side["width"] == 7 and side["height"] == 5
    assert side["normal_space"] == "view"
    assert side["ao_distance"] == 1.25 and side["samples"] == 1024
    assert side["bridge"] == {"hash": "abc"}  # keys AO Lab does not interpret are kept
    assert back.path == str(path)
    np.testing.assert_array_equal(back.valid_mask(), g.valid_mask())


def test_saved_file_has_blender_channel_layout(tmp_path):
    g, ao = make_gbuffer()
    path = tmp_path / "scene.exr"
    aolab.save_gbuffer(path, g, reference=ao)
    pixels, names, formats = read_oiio(path)
    fmt = dict(zip(names, formats))
    assert set(names) == {f"ViewLayer.{p}" for p in (
        "Depth.Z", "Normal.X", "Normal.Y", "Normal.Z", "AO.R", "AO.G", "AO.B",
        "DiffCol.R", "DiffCol.G", "DiffCol.B")}
    assert fmt["ViewLayer.Depth.Z"] == "float"
    assert all(f == "half" for n, f in fmt.items() if n != "ViewLayer.Depth.Z")
    # Row 0 of the file is row 0 of the array (the top), and AO is R = G = B.
    np.testing.assert_array_equal(pixels[..., names.index("ViewLayer.Depth.Z")], g.depth)
    for c in "RGB":
        np.testing.assert_allclose(pixels[..., names.index(f"ViewLayer.AO.{c}")], ao,
                                   atol=HALF_TOL)
    assert aolab._core.exr_channels(str(path)) == names


def test_no_reference_and_no_colour(tmp_path):
    g, _ = make_gbuffer(with_color=False)
    aolab.save_gbuffer(tmp_path / "g.exr", g)
    back = aolab.load_gbuffer(tmp_path / "g.exr")
    assert back.reference is None
    assert back.color is None
    assert back.normal.shape == (5, 7, 3)


def test_blender_exr_with_world_normals(tmp_path):
    """An EXR as Blender writes it (world-space normals, a layer with a custom name, passes
    AO Lab does not read) plus a sidecar with camera_to_world: normals come out in view space,
    Nv = Nw @ R with R the column-normalised rotation (docs/blender_facts.md, "Passes in a
    multilayer EXR")."""
    h, w = 4, 6
    rng = np.random.default_rng(7)
    depth = rng.uniform(1, 10, (h, w)).astype(np.float32)
    depth[0, 0] = CYCLES_BACKGROUND
    nw = rng.normal(size=(h, w, 3))
    nw = (nw / np.linalg.norm(nw, axis=-1, keepdims=True)).astype(np.float32)
    nw[0, 0] = 0  # Blender's background normal
    ao = rng.uniform(0, 1, (h, w)).astype(np.float32)
    a = np.radians(30)
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]])  # 90 degrees about x
    rot = rz @ rx
    cam = np.eye(4)
    cam[:3, :3] = 2.0 * rot  # a scaled camera: R must be normalised
    cam[:3, 3] = [1, -6, 2]
    layer = "View Layer.001"
    write_oiio(tmp_path / "blender.exr", [
        (f"{layer}.Combined.R", "half", ao), (f"{layer}.Depth.Z", "float", depth),
        (f"{layer}.Normal.X", "half", nw[..., 0]), (f"{layer}.Normal.Y", "half", nw[..., 1]),
        (f"{layer}.Normal.Z", "half", nw[..., 2]), (f"{layer}.AO.R", "half", ao),
        (f"{layer}.AO.G", "half", ao), (f"{layer}.AO.B", "half", ao)])
    (tmp_path / "blender.json").write_text(json.dumps({
        "width": w, "height": h, "fx": 5.0, "fy": 5.0, "cx": 3.0, "cy": 2.0,
        "camera_to_world": cam.tolist(), "ao_distance": 0.5, "clip_start": 0.1}))

    data = _core.load_gbuffer_arrays(str(tmp_path / "blender.exr"))
    assert data["depth"].shape == (h, w) and data["depth"].dtype == np.float32
    np.testing.assert_array_equal(data["depth"], depth)
    np.testing.assert_allclose(data["normal"], nw @ rot, atol=HALF_TOL)
    np.testing.assert_array_equal(data["normal"][0, 0], 0)  # background stays (0, 0, 0)
    np.testing.assert_allclose(data["ao"], ao, atol=HALF_TOL)
    assert data["color"] is None
    assert data["sidecar"]["clip_start"] == 0.1
    assert f"{layer}.Combined.R" in data["channels"]

    g = aolab.load_gbuffer(tmp_path / "blender.exr")
    assert "normal_space" not in g.sidecar  # the file's document, as written: "world" default
    np.testing.assert_allclose(g.normal, nw @ rot, atol=HALF_TOL)


def test_missing_file_raises_file_not_found(tmp_path):
    missing = tmp_path / "absent.exr"
    with pytest.raises(FileNotFoundError) as err:
        aolab.load_gbuffer(missing)
    assert err.value.filename == str(missing)
    assert str(missing) in str(err.value)
    with pytest.raises(FileNotFoundError):
        _core.exr_channels(str(missing))


def test_missing_sidecar_raises_file_not_found(tmp_path):
    g, _ = make_gbuffer()
    aolab.save_gbuffer(tmp_path / "s.exr", g)
    (tmp_path / "s.json").unlink()
    with pytest.raises(FileNotFoundError) as err:
        aolab.load_gbuffer(tmp_path / "s.exr")
    assert err.value.filename == str(tmp_path / "s.json")


def test_missing_depth_names_the_channels(tmp_path):
    plane = np.full((3, 4), 0.5, np.float32)
    write_oiio(tmp_path / "beauty.exr", [("ViewLayer.Combined.R", "half", plane),
                                         ("ViewLayer.Combined.G", "half", plane)])
    channels = r"ViewLayer\.Combined\.R, ViewLayer\.Combined\.G"
    with pytest.raises(ValueError, match=r"Depth\.Z.*" + channels):
        aolab.load_gbuffer(tmp_path / "beauty.exr")


def test_bad_sidecar_names_the_key_and_file(tmp_path):
    g, _ = make_gbuffer()
    aolab.save_gbuffer(tmp_path / "s.exr", g)
    (tmp_path / "s.json").write_text(json.dumps({"width": 7, "height": 5, "fx": 6.5,
                                                 "cx": 3.5, "cy": 2.5}))
    with pytest.raises(ValueError, match=r'"fy".*s\.json|s\.json.*"fy"'):
        aolab.load_gbuffer(tmp_path / "s.exr")
    (tmp_path / "s.json").write_text('{"width": 7,')
    with pytest.raises(ValueError, match="not valid JSON"):
        aolab.load_gbuffer(tmp_path / "s.exr")
    (tmp_path / "s.json").write_text(json.dumps({"width": 9, "height": 5, "fx": 6.5, "fy": 6.5,
                                                 "cx": 3.5, "cy": 2.5, "normal_space": "view"}))
    with pytest.raises(ValueError, match="9x5.*7x5"):
        aolab.load_gbuffer(tmp_path / "s.exr")


def test_sidecar_accepts_numpy_values_and_rejects_nan(tmp_path):
    g, _ = make_gbuffer()
    cam = np.eye(4)
    cam[:3, 3] = [1, 2, 3]
    aolab.save_gbuffer(tmp_path / "g.exr", g,
                       sidecar={"camera_to_world": cam, "samples": np.int64(64)})
    side = aolab.load_gbuffer(tmp_path / "g.exr").sidecar
    assert side["camera_to_world"] == cam.tolist()
    assert side["samples"] == 64
    with pytest.raises(ValueError, match="sidecar.*NaN"):  # NaN is not JSON
        aolab.save_gbuffer(tmp_path / "n.exr", g, sidecar={"ao_distance": float("nan")})
    with pytest.raises(ValueError, match="samples"):
        aolab.save_gbuffer(tmp_path / "n.exr", g, sidecar={"samples": -1})
    assert sorted(os.listdir(tmp_path)) == ["g.exr", "g.json"]


def test_reference_of_another_size_is_rejected(tmp_path):
    g, _ = make_gbuffer()
    with pytest.raises(ValueError, match="reference"):
        aolab.save_gbuffer(tmp_path / "g.exr", g, reference=np.zeros((3, 3), np.float32))
    assert os.listdir(tmp_path) == []


def test_write_image_exr_is_float32(tmp_path):
    ao = np.random.default_rng(1).uniform(0, 1, (5, 7)).astype(np.float32)
    aolab.write_image(tmp_path / "ao.exr", ao)
    pixels, names, formats = read_oiio(tmp_path / "ao.exr")
    assert names == ["Y"] and formats == ["float"]
    np.testing.assert_array_equal(pixels[..., 0], ao)

    rgb = np.random.default_rng(2).uniform(0, 1, (5, 7, 3)).astype(np.float32)
    aolab.write_image(tmp_path / "rgb.exr", rgb)
    pixels, names, _ = read_oiio(tmp_path / "rgb.exr")
    assert names == ["R", "G", "B"]
    np.testing.assert_array_equal(pixels, rgb)


def test_write_image_png_is_value_times_255(tmp_path):
    values = np.array([[0.0, 0.5, 1.0, 1.7, -0.2, np.nan, 0.25]], np.float32)
    aolab.write_image(tmp_path / "ao.png", values)
    inp = oiio.ImageInput.open(str(tmp_path / "ao.png"))
    assert str(inp.spec().format) == "uint8"
    raw = inp.read_image("uint8")
    inp.close()
    np.testing.assert_array_equal(raw.reshape(-1), [0, 128, 255, 255, 0, 0, 64])
    # No transfer-curve or colour-space chunk: the bytes are the values, nothing else.
    png = (tmp_path / "ao.png").read_bytes()
    assert b"gAMA" not in png and b"sRGB" not in png and b"iCCP" not in png


def test_write_image_accepts_non_contiguous_and_float64(tmp_path):
    big = np.arange(48, dtype=np.float64).reshape(6, 8) / 48
    view = big[1:4, 2:7]  # strided, float64: converted once at the boundary
    aolab.write_image(tmp_path / "v.exr", view)
    pixels, _, _ = read_oiio(tmp_path / "v.exr")
    np.testing.assert_allclose(pixels[..., 0], view, rtol=1e-7)


def test_write_image_rejects_bad_input(tmp_path):
    img = np.zeros((4, 4), np.float32)
    with pytest.raises(ValueError, match=r"must end in \.exr or \.png"):
        aolab.write_image(tmp_path / "ao.jpg", img)
    with pytest.raises(ValueError, match="image"):
        aolab.write_image(tmp_path / "ao.exr", np.zeros((4, 4, 2), np.float32))
    with pytest.raises(FileNotFoundError):
        aolab.write_image(tmp_path / "no" / "dir" / "ao.png", img)
    assert os.listdir(tmp_path) == []


def test_writes_leave_no_temporary_files(tmp_path):
    g, ao = make_gbuffer()
    for _ in range(2):  # the second pass replaces existing files
        aolab.write_image(tmp_path / "ao.png", ao)
        aolab.write_image(tmp_path / "ao.exr", ao)
        aolab.save_gbuffer(tmp_path / "g.exr", g, reference=ao)
    assert sorted(os.listdir(tmp_path)) == ["ao.exr", "ao.png", "g.exr", "g.json"]
