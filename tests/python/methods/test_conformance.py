"""What every method of aolab.methods() promises, checked for each one alike: its description
is complete (defaults, units, ranges or choices, meanings) and its docs page copies it; an
open plane is exactly 1; the same bits for any thread count; bad settings are ValueErrors
naming the parameter (unknown ones list the valid names); progress, cancel and the GIL.
Method-specific known answers stay in test_<method>.py; hard inputs are test_stability.py's.
"""
import math

import numpy as np
import pytest

import aolab
from aolab.settings import is_choice
from docs_settings import assert_docs_settings_table
from gil_support import ticks_while

METHODS = aolab.methods()
TYPES = ("float", "int", "bool", "choice")

# Settings each method is also run with where the suite runs it (open planes, threads):
# its switches that change what it computes, beside the defaults.
VARIANTS = {
    "alchemy": [dict(random_rotation=False, samples=31, turns=7),
                dict(falloff="smooth", contrast=3.0, bias=0.0, epsilon=0.0, seed=5)],
    "chebyshev": [dict(variance_bias=0.0), dict(kernel_mode="fixed", kernel_radius=12),
                  dict(range_check=False), dict(max_kernel_radius=1024)],
    "bitmask": [dict(random_rotation=False, jitter=False, slices=5, steps=12, sectors=64,
                     weighting="cosine"),
                dict(thickness=1e30, rounding="half", radius_clip="sphere", normalization="slices",
                     seed=3)],
    "gtao": [dict(random_rotation=False, jitter=False, slices=5, steps=12),
             dict(thickness=0.7, falloff=0.615, multi_bounce=True, albedo=0.9, seed=3)],
    "hbao": [dict(random_rotation=False, jitter=False, incremental_attenuation=True),
             dict(integral="cosine", attenuation="none")],
    "lsao": [dict(template_size=1, directions=8),
             dict(template_size=4, directions=32, line_spacing=3),
             dict(template_size=0, directions=10, step=1.5, sampling="interpolate", seed=4),
             dict(falloff="clipped", seed=99), dict(falloff="cutoff")],
    "pyramid_hbao": [dict(reduction=2), dict(gaussian_filter=False, reduction=3),
                     dict(attenuation="none")],
    "sao": [dict(normals="depth", filter=False), dict(max_mip_level=0, grid="reference"),
            dict(falloff="smooth", log_max_offset=0, samples=40, bias=0.0, seed=2),
            dict(edge_sharpness=0.0, filter_radius=10, filter_stride=1)],
    "crytek_ssao": [dict(hemisphere=True), dict(distribution="uniform", range_check="hard",
                                                rotation="per_pixel", samples=34, seed=4),
                    dict(rotation="none", range_check="off")],
    "screen_space_limit": [dict(rays=1), dict(rays=5, thickness=0.05, seed=3)],
    "vao": [dict(random_rotation=False, samples=32)],
    "vao_pp": [dict(culling="greedy"), dict(culling="off", adaptive_sampling=False, filter=False),
               dict(poisson_samples=False, samples=32), dict(range_check=False, filter_taps=7)],
}
# Variants exact on the plane facing the camera only: Chebyshev's eq. 2 (ignore_unoccluded
# off) also darkens pixels in front of the window's mean, which a tilted plane has.
FACING_VARIANTS = {"chebyshev": [dict(variance_bias=0.0, ignore_unoccluded=False),
                                 dict(ignore_unoccluded=False, kernel_mode="fixed",
                                      kernel_radius=20)]}
# Colour settings need the colour passes; the threads test runs them on a coloured G-buffer.
COLOUR_VARIANTS = {"vao_pp": [dict(color_bleeding=True, luminance_sensitivity=True,
                                   luminance_threshold=0.5)]}

# Open planes: facing the camera, and tilted up to grazing. LSAO's fixed tangent (the
# paper's strategy, docs/methods/lsao.md) over-occludes planes steeper than asin 0.85, so it
# is exact on the facing plane only; its tilted planes are test_lsao.py's (eq. 1 at the
# centre) and test_stability.py's (the bound).
PLANES = [dict(tilt=0, azimuth=0, fov=80), dict(tilt=45, azimuth=10, fov=60),
          dict(tilt=70, azimuth=90, fov=90), dict(tilt=85, azimuth=30, fov=60),
          dict(tilt=-85, azimuth=250, fov=120), dict(tilt=89.5, azimuth=200, fov=120)]
# Crytek SSAO reads the depth of the pixel a point falls in: on a tilted plane a point just
# above it can read a nearer depth (docs/methods/crytek_ssao.md); its tilted planes are
# test_crytek_ssao.py's (mean >= 0.995).
FACING_ONLY = ("lsao", "crytek_ssao")
RADII = (1e-3, 0.3, 1.0, 10.0, 1e9, 1e30)  # from under a pixel to beyond the screen


def info(method):
    return aolab.method_info(method)


# What the suite runs a method with instead of its defaults: a bound too slow at its
# defaults for a suite of many runs (the screen-space limit marches every pixel each of its
# 256 rays crosses, to the image border at the huge radii); the contract does not depend on
# the number of rays. Every variant is run on top of it.
SUITE_BASE = {"screen_space_limit": dict(rays=2)}


def variants(method):
    base = SUITE_BASE.get(method, {})
    return [dict(base)] + [{**base, **v} for v in VARIANTS.get(method, [])]


def plane_cases():
    for method in METHODS:
        planes = PLANES[:1] if method in FACING_ONLY else PLANES
        for plane in planes:
            facing = plane is PLANES[0]
            extra = FACING_VARIANTS.get(method, []) if facing else []
            for k, settings in enumerate(variants(method) + extra):
                yield pytest.param(method, plane, settings,
                                   id=f"{method}-tilt{plane['tilt']}-az{plane['azimuth']}-v{k}")


def coloured(name="blocks", w=320, h=180):
    """An analytic scene with a diffuse colour and some emission, for every method (those that
    read no colour ignore it)."""
    g = aolab.analytic_scene(name, w, h)
    color = np.empty((h, w, 3), np.float32)
    color[...] = (0.8, 0.3, 0.2)
    emission = np.zeros((h, w, 3), np.float32)
    emission[:, : w // 3] = 2.0
    return aolab.GBuffer(g.depth, g.normal, color, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy,
                         emission=emission)


# ---- the description ----

@pytest.mark.parametrize("method", METHODS)
def test_method_info_is_complete(method):
    d = info(method)
    assert d["name"] == method and d["title"] and d["paper"]
    assert isinstance(d["needs_normal"], bool) and isinstance(d["needs_color"], bool)
    names = [s["name"] for s in d["settings"]]
    assert len(set(names)) == len(names)
    assert names[0] == "radius"
    for s in d["settings"]:
        name = s["name"]
        assert s["type"] in TYPES, name
        assert isinstance(s["unit"], str), name
        assert isinstance(s["description"], str) and len(s["description"]) > 10, name
        if is_choice(s):
            choices = s["choices"]
            assert len(choices) >= 2 and len(set(choices)) == len(choices), name
            assert all(isinstance(c, str) and c.isidentifier() for c in choices), name
            assert s["default"] in choices, name
            continue
        assert s["min"] <= s["max"], name
        if s["type"] == "bool":
            assert isinstance(s["default"], bool) and (s["min"], s["max"]) == (0, 1), name
        elif s["type"] == "int":
            assert isinstance(s["default"], int) and not isinstance(s["default"], bool), name
            assert s["min"] == int(s["min"]) and s["max"] == int(s["max"]), name
        else:
            assert isinstance(s["default"], float) and math.isfinite(s["default"]), name
        assert s["min"] <= s["default"] <= s["max"], name
    radius = d["settings"][0]
    assert radius["type"] == "float" and radius["min"] > 0 and radius["unit"] == "view-space units"


@pytest.mark.parametrize("method", METHODS)
def test_docs_settings_table_is_the_field_table(method):
    # docs/methods/<method>.md copies the C++ field table; this keeps the copy exact.
    assert_docs_settings_table(method)


@pytest.mark.parametrize("method", METHODS)
def test_defaults_given_explicitly_change_nothing(method):
    g = coloured("blocks", 96, 54)
    defaults = {s["name"]: s["default"] for s in info(method)["settings"]
                if s["name"] != "radius"}
    a = aolab.compute(method, g, radius=0.5)
    b = aolab.compute(method, g, radius=0.5, **defaults)
    assert a.tobytes() == b.tobytes()


# ---- answers every method must give ----

@pytest.mark.parametrize("method, plane, settings", list(plane_cases()))
def test_open_plane_is_exactly_one(method, plane, settings):
    g = aolab.analytic_scene("plane", 192, 108, **plane)
    valid = g.valid_mask()
    for radius in RADII:
        ao = aolab.compute(method, g, radius=radius, **settings)
        assert ao[valid].min() == 1.0, radius


@pytest.mark.parametrize("method", METHODS)
def test_same_bits_for_any_thread_count(method):
    g = coloured()
    for settings in variants(method) + COLOUR_VARIANTS.get(method, []):
        a, b, c = (aolab.compute(method, g, radius=0.5, threads=t, **settings).tobytes()
                   for t in (1, 2, 7))
        assert a == b == c, settings


@pytest.mark.parametrize("method", METHODS)
def test_reads_normals_only_if_it_says_so(method):
    g = aolab.analytic_scene("blocks", 160, 90)
    depth_only = aolab.GBuffer(g.depth, None, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy)
    if info(method)["needs_normal"]:
        with pytest.raises(ValueError, match="normal"):
            aolab.compute(method, depth_only, radius=0.5)
    else:
        a = aolab.compute(method, depth_only, radius=0.5)
        assert a.tobytes() == aolab.compute(method, g, radius=0.5).tobytes()
        assert a.min() < 0.9


# ---- bad settings ----

def bad_values(s: dict) -> list:
    """Values of setting ``s`` that must be refused: outside its range, of the wrong kind."""
    if is_choice(s):
        return ["no_such_choice", s["default"].upper() + "_", 0]
    if s["type"] == "bool":
        return [2, 0.5, "yes"]
    lo, hi = s["min"], s["max"]
    out = [lo - max(1.0, abs(lo)), hi + max(1.0, abs(hi)), "many"]
    if s["type"] == "int":
        out += [int(lo) - 1, int(hi) + 1, lo + 0.5]
    else:
        out += [math.nan, math.inf]
    return out


def bad_cases():
    for method in METHODS:
        for s in info(method)["settings"]:
            for value in bad_values(s):
                yield pytest.param(method, s["name"], value, id=f"{method}-{s['name']}-{value!r}")


@pytest.mark.parametrize("method, name, value", list(bad_cases()))
def test_bad_setting_is_valueerror_naming_it(method, name, value):
    g = coloured("plane", 16, 9)  # so that a colour setting's value is what is refused
    settings = {"radius": 1.0, name: value}
    with pytest.raises(ValueError, match=rf"^{name} "):
        aolab.compute(method, g, **settings)


@pytest.mark.parametrize("method", METHODS)
def test_unknown_choice_lists_the_choices(method):
    g = aolab.analytic_scene("plane", 16, 9)
    for s in info(method)["settings"]:
        if is_choice(s):
            with pytest.raises(ValueError) as e:
                aolab.compute(method, g, radius=1.0, **{s["name"]: "no_such_choice"})
            assert all(c in str(e.value) for c in s["choices"]), str(e.value)


@pytest.mark.parametrize("method", METHODS)
def test_unknown_setting_lists_the_valid_ones(method):
    g = aolab.analytic_scene("plane", 16, 9)
    with pytest.raises(ValueError, match=f"unknown setting 'no_such_setting' for {method}; "
                                         "valid settings: ") as e:
        aolab.compute(method, g, radius=1.0, no_such_setting=3)
    listed = str(e.value).split("valid settings: ", 1)[1].split(", ")
    assert listed == [s["name"] for s in info(method)["settings"]]


# ---- running ----

@pytest.mark.parametrize("method", METHODS)
def test_progress_and_cancel(method):
    g = coloured()
    base = SUITE_BASE.get(method, {})
    p = aolab.Progress()
    aolab.compute(method, g, radius=0.5, progress=p, **base)
    assert p.total > 0 and p.done == p.total
    c = aolab.Progress()
    c.cancel()
    with pytest.raises(aolab.Cancelled):
        aolab.compute(method, g, radius=0.5, progress=c, **base)


@pytest.mark.parametrize("method", METHODS)
def test_gil_is_released_during_compute(method):
    # 1920x1080: long enough (tens of ms for the fastest method on one thread) that a main
    # thread starved by a loaded machine still gets its handful of turns when the GIL is free;
    # the screen-space limit, a bound, takes seconds at 1280x720 already
    size = (1280, 720) if method == "screen_space_limit" else (1920, 1080)
    g = aolab.analytic_scene("blocks", *size)
    ticks = ticks_while(
        lambda: aolab.compute(method, g, radius=0.5, threads=1, **SUITE_BASE.get(method, {})))
    assert ticks > 5  # the main thread ran while the computation did
