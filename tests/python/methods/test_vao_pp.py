"""VAO++ (Bokšanský et al. 2017 §4) through the registry: the culled share, colour (the
setting-aware requirement, emission, RGB results and their refusal by metrics), the settings
whose constraints are more than a range. Open planes with every extension, threads (colour
bleeding too), range errors and the docs table: test_conformance.py."""
import numpy as np
import pytest

import aolab


def coloured(name="blocks", w=192, h=108, rgb=(0.8, 0.3, 0.2), emission=None):
    g = aolab.analytic_scene(name, w, h)
    color = np.empty((h, w, 3), np.float32)
    color[...] = rgb
    kw = {} if emission is None else {"emission": np.full((h, w, 3), emission, np.float32)}
    return aolab.GBuffer(g.depth, g.normal, color, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy, **kw)


def test_stats_report_the_culled_share():
    g = aolab.analytic_scene("blocks", 320, 180)
    ao, stats = aolab.vao_pp_with_stats(g, radius=0.25)
    assert ao.tobytes() == aolab.compute("vao_pp", g, radius=0.25).tobytes()
    assert stats["pixels"] == int(g.valid_mask().sum())
    assert 0 < stats["culled_share"] < 1
    assert stats["culled_share"] == stats["culled"] / stats["pixels"]
    assert 2 <= stats["mean_samples"] <= 16
    _, off = aolab.vao_pp_with_stats(g, radius=0.25, culling="off", adaptive_sampling=False)
    assert off["culled"] == 0 and off["mean_samples"] == 16 and off["prepass_pixels"] == 0


def test_colour_is_needed_only_by_the_settings_that_read_it():
    info = aolab.method_info("vao_pp")
    assert info["needs_color"] is True  # the bridge renders DiffCol/Emit for it
    g = aolab.analytic_scene("blocks", 64, 36)
    aolab.compute("vao_pp", g, radius=0.5)  # defaults read no colour
    for setting in ("color_bleeding", "luminance_sensitivity"):
        with pytest.raises(ValueError, match=f"color is required by vao_pp with {setting} on"):
            aolab.compute("vao_pp", g, radius=0.5, **{setting: True})


def test_colour_bleeding_returns_rgb_that_write_image_writes_and_metrics_refuses(tmp_path):
    g = coloured()
    rgb = aolab.compute("vao_pp", g, radius=0.5, color_bleeding=True)
    assert rgb.shape == (108, 192, 3) and rgb.dtype == np.float32
    assert np.isfinite(rgb).all() and rgb.min() >= 0 and rgb.max() <= 1
    ao = aolab.compute("vao_pp", g, radius=0.5)
    assert (rgb[..., 0] >= rgb[..., 1]).all() and (rgb[..., 0] <= ao + 1e-6).all()
    aolab.write_image(tmp_path / "bleed.exr", rgb)
    aolab.write_image(tmp_path / "bleed.png", rgb)
    if hasattr(aolab._core, "read_image"):
        back = aolab._core.read_image(str(tmp_path / "bleed.exr"))
        assert np.array_equal(back, rgb)
    reference = np.ones((108, 192), np.float32)
    with pytest.raises(ValueError, match="RGB image .*cannot be scored"):
        aolab.metrics(rgb, reference)
    with pytest.raises(ValueError, match="blur"):
        aolab.compute("vao_pp", g, radius=0.5, color_bleeding=True, blur=True)


def test_luminance_sensitivity_reads_colour_plus_emission():
    plain = aolab.compute("vao_pp", coloured(rgb=(0.5, 0.5, 0.5)), radius=0.5)
    assert plain.min() < 0.9
    dark = aolab.compute("vao_pp", coloured(rgb=(0.5, 0.5, 0.5)), radius=0.5,
                         luminance_sensitivity=True)
    assert dark.tobytes() == plain.tobytes()  # lum 0.5: under the default ramp [1, 1.6]
    lamp = aolab.compute("vao_pp", coloured(rgb=(0.5, 0.5, 0.5), emission=3.0), radius=0.5,
                         luminance_sensitivity=True)
    assert (lamp == 1).all()


def test_emission_survives_save_and_load(tmp_path):
    g = coloured(w=40, h=24, emission=2.5)
    aolab.save_gbuffer(tmp_path / "g.exr", g)
    back = aolab.load_gbuffer(tmp_path / "g.exr")
    assert back.emission is not None and back.emission.shape == (24, 40, 3)
    assert np.array_equal(back.emission, g.emission)  # 2.5 is exact in half
    assert "ViewLayer.Emit.R" in aolab._core.exr_channels(str(tmp_path / "g.exr"))
    assert "+emission" in repr(back)
    with pytest.raises(ValueError, match="emission"):
        aolab.GBuffer(g.depth, g.normal, emission=np.ones((24, 40), np.float32), fx=1, fy=1,
                      cx=0, cy=0)


@pytest.mark.parametrize("name, value", [
    ("samples", 12), ("filter_taps", 4), ("bleeding_sample_step", 3)])
def test_settings_within_range_but_not_allowed_are_valueerrors(name, value):
    # Powers of two, odd taps, a step of 1, 2 or 4: inside the range, refused all the same.
    g = aolab.analytic_scene("plane", 16, 9)
    with pytest.raises(ValueError, match=f"^{name}"):
        aolab.compute("vao_pp", g, radius=1.0, **{name: value})
