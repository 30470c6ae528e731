"""Validation in the project's code, never left to pybind or numpy: every integer the API
passes to the compiled module is range-checked first (a ValueError naming the parameter, not
pybind's "incompatible function arguments" TypeError), every real number is checked before
its float32 conversion (the message quotes the value given, not the inf it would become), the
API has the command line's size caps, no numpy RuntimeWarning escapes, and an input with no
scoreable pixel or a NaN reference is refused rather than answered. On the command line each
is one line and exit status 2, and the user's files are unchanged."""
import subprocess
import sys
import time
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import aolab
from aolab import named_presets
from aolab.study import advise, limits
from aolab.util import values
from aolab.util.arguments import MAX_BUDGET_MS, parse_budget

K = dict(fx=20.0, fy=20.0, cx=8.0, cy=4.5)


@pytest.fixture(autouse=True)
def warnings_are_errors():
    """No numpy RuntimeWarning (nor any other) may reach the user."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


@pytest.fixture(scope="module")
def plane():
    return aolab.analytic_scene("plane", 16, 9)


def refused(call, *parts):
    """``call()`` raises a ValueError whose one-line message holds every part."""
    with pytest.raises(ValueError) as e:
        call()
    message = str(e.value)
    assert "\n" not in message, message
    for part in parts:
        assert part in message, message
    return message


def aolab_cmd(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "aolab", *map(str, args)], capture_output=True,
                          text=True, timeout=300, cwd=cwd)


def one_line_exit_2(res, *parts):
    lines = res.stderr.strip().split("\n")
    assert res.returncode == 2, res.stderr
    assert len(lines) == 1 and lines[0].startswith("aolab: "), res.stderr
    for part in parts:
        assert part in lines[0], res.stderr


def snapshot(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


# --- C: integers range-checked before they cross into C++ ---------------------------------

THREADS = "threads must be a whole number in [0, 2147483647] (0 = all cores), got "
FRAME = "frame must be a whole number in [0, 2147483647], got "


def int_calls(g):
    """Every public call that passes a whole number to the compiled module, as
    (name of the parameter, call taking the value)."""
    ao = np.ones((g.height, g.width), np.float32)
    still = np.zeros((g.height, g.width, 2), np.float32)
    mesh = SimpleNamespace(**dict(zip(("vertices", "triangles"),
                                      aolab.analytic_scene_mesh("plane"))))
    tri = (np.array([[0, 0, -3], [1, 0, -3], [0, 1, -3]], np.float32), [[0, 1, 2]], np.eye(4))
    return [
        ("threads", lambda v: aolab.compute("sao", g, radius=1.0, threads=v)),
        ("frame", lambda v: aolab.compute("sao", g, radius=1.0, frame=v)),
        ("frame", lambda v: aolab.compute("chebyshev", g, radius=1.0, frame=v)),
        ("blur_taps", lambda v: aolab.compute("sao", g, radius=1.0, blur=True, blur_taps=v)),
        ("threads", lambda v: aolab.accumulate(ao, g, still, aolab.TemporalHistory(), threads=v)),
        ("threads", lambda v: aolab.metrics(ao, ao, threads=v)),
        ("threads", lambda v: aolab.gaussian_blur(ao, g, threads=v)),
        ("taps", lambda v: aolab.gaussian_blur(ao, g, taps=v)),
        ("threads", lambda v: aolab.vao_pp_with_stats(g, radius=1.0, threads=v)),
        ("threads", lambda v: g.view_positions(threads=v)),
        ("threads", lambda v: g.prepared_normals(threads=v)),
        ("width", lambda v: aolab.analytic_scene("plane", v, 1)),
        ("height", lambda v: aolab.analytic_scene("plane", 1, v)),
        ("seed", lambda v: aolab.frame_seed(v, 0)),
        ("frame", lambda v: aolab.frame_seed(0, v)),
        ("threads", lambda v: aolab.RayScene(*tri, threads=v)),
        ("threads", lambda v: aolab.ray_scene(mesh, camera_to_world=np.eye(4), threads=v)),
        ("threads", lambda v: aolab.rtao(g, mesh, radius=1.0, rays=1, threads=v)),
        ("threads", lambda v: aolab.rtao_range(g, mesh, radius=1.0, threads=v)),
        ("threads", lambda v: named_presets.shared_blur(ao, g, threads=v)),
    ]


@pytest.mark.parametrize("value, shown", [
    (2**63, "9223372036854775808"), (np.uint64(2**64 - 1), "18446744073709551615"),
    (2**31, "2147483648"), (2**40, "1099511627776"), (-2**63, "-9223372036854775808"),
    (10**400, "1" + "0" * 56 + "..."),
])
def test_an_int_beyond_the_cpp_range_is_a_value_error_naming_the_parameter(plane, value, shown):
    for name, call in int_calls(plane):
        message = refused(lambda: call(value), name, f"got {shown}")
        assert message.startswith(name), message
        assert "incompatible" not in message and "array(" not in message


@pytest.mark.parametrize("value, shown", [(True, "True (bool)"), (np.bool_(False), "False (bool"),
                                          (2.0, "2.0 (float)"), ("3", "'3' (str)")])
def test_a_bool_float_or_text_is_no_whole_number(plane, value, shown):
    for name, call in int_calls(plane):
        refused(lambda: call(value), name, shown)


def test_the_issues_cases_word_for_word(plane):
    refused(lambda: aolab.compute("sao", plane, radius=1.0, frame=2**63),
            FRAME + "9223372036854775808")
    refused(lambda: aolab.compute("sao", plane, radius=1.0, frame=np.uint64(2**64 - 1)),
            FRAME + "18446744073709551615")
    refused(lambda: aolab.compute("sao", plane, radius=1.0, threads=2**31), THREADS + "2147483648")
    refused(lambda: aolab.analytic_scene("plane", 2**31, 1),
            "width must be a whole number in [1, 16384], got 2147483648")
    ao = np.ones((9, 16), np.float32)
    refused(lambda: aolab.metrics(ao, ao, threads=2**40), THREADS + "1099511627776")


def test_numpy_integers_in_range_are_taken(plane):
    a = aolab.compute("sao", plane, radius=1.0, threads=np.int64(1), frame=np.uint8(3),
                      blur=True, blur_taps=np.int16(3))
    b = aolab.compute("sao", plane, radius=1.0, threads=1, frame=3, blur=True, blur_taps=3)
    assert np.array_equal(a, b)
    assert aolab.analytic_scene("plane", np.int32(4), np.uint16(3)).depth.shape == (3, 4)


def test_a_negative_thread_count_keeps_its_documented_message(plane):
    refused(lambda: aolab.compute("sao", plane, radius=1.0, threads=-1),
            "threads must be >= 0 (0 = all cores), got -1")


@settings(max_examples=60, deadline=None)
@given(st.one_of(st.integers(max_value=-1), st.integers(min_value=2**31)))
def test_any_int_outside_the_range_is_a_value_error_never_a_type_error(value):
    g = aolab.analytic_scene("plane", 4, 3)
    for name, call in int_calls(g):
        with pytest.raises(ValueError, match=f"^{name} must be"):
            call(value)


def test_a_setting_beyond_a_double_is_quoted_as_given(plane):
    """Settings cross as doubles: 2**63 would be printed as 9.223372036854776e+18."""
    still = np.zeros((9, 16, 2), np.float32)
    ao = np.ones((9, 16), np.float32)
    refused(lambda: aolab.compute("sao", plane, radius=1.0, seed=2**63),
            "seed must be in [0, 2147483647], got 9223372036854775808")
    refused(lambda: aolab.accumulate(ao, plane, still, aolab.TemporalHistory(),
                                     max_history=2**64), "max_history must be in [1, ",
            "got 18446744073709551616")
    refused(lambda: aolab.rtao(plane, aolab.RayScene(np.eye(3, dtype=np.float32), [[0, 1, 2]],
                                                     np.eye(4)), radius=1.0, rays=2**64),
            "rays must be in [1, ", "got 18446744073709551616")
    refused(lambda: aolab.vao_pp_with_stats(plane, radius=1.0, seed=-2**70),
            "seed must be in [0, 2147483647], got -1180591620717411303424")


def test_even_blur_taps_are_named_as_given(plane):
    refused(lambda: aolab.compute("sao", plane, radius=1.0, blur=True, blur_taps=4),
            "blur_taps must be odd, got 4")


# --- G: the API has the command line's size caps ------------------------------------------

def test_an_analytic_scene_beyond_16384_is_refused_at_once():
    t0 = time.perf_counter()
    refused(lambda: aolab.analytic_scene("plane", 20000, 20000),
            "width must be a whole number in [1, 16384], got 20000")
    refused(lambda: aolab.analytic_scene("plane", 16, 16385),
            "height must be a whole number in [1, 16384], got 16385")
    assert time.perf_counter() - t0 < 5   # not 19 s and 7.8 GB: nothing was allocated


# --- D: floats checked before float32, the message quoting the value given -----------------

ABOVE = "above float32's largest, 3.4028235e+38"


@pytest.mark.parametrize("name", ["fx", "fy", "cx", "cy", "background_depth"])
@pytest.mark.parametrize("value, shown", [(1e39, "1e+39"), (np.float64(1e300), "1e+300"),
                                          (10**39, "1000000000000000000000000000000000000000")])
def test_a_gbuffer_float_beyond_float32_is_refused_not_made_inf(plane, name, value, shown):
    args = {**K, name: value}
    message = refused(lambda: aolab.GBuffer(plane.depth, **args), f"got {shown}, {ABOVE}")
    assert message.startswith(f"{name} must be") and "got inf" not in message


def test_the_gbuffer_names_each_bad_intrinsic_as_given(plane):
    focal = "fx must be a finite focal length > 0 px, got "
    for value, shown in ((0, "0"), (-1.0, "-1.0"), ("1", "'1' (str)"), (True, "True (bool)"),
                         (float("nan"), "nan"), (float("inf"), "inf"),
                         (1e-45, "1e-45, below float32's smallest normal number, 1.1754944e-38")):
        refused(lambda: aolab.GBuffer(plane.depth, **{**K, "fx": value}), focal + shown)
    refused(lambda: aolab.GBuffer(plane.depth, **{**K, "cy": -1e39}),
            "cy must be finite, got -1e+39, below float32's lowest, -3.4028235e+38")


def test_an_infinite_background_depth_given_as_inf_is_still_taken(plane):
    g = aolab.GBuffer(plane.depth, plane.normal, **K, background_depth=float("inf"))
    assert g.background_depth == float("inf") and isinstance(g, aolab.GBuffer)
    refused(lambda: aolab.GBuffer(plane.depth, **K, background_depth=1e39),
            "background_depth must be a finite number > 0, got 1e+39, " + ABOVE)


def test_a_gbuffer_is_still_what_every_call_takes(plane):
    g = aolab.GBuffer(plane.depth, plane.normal, **K)
    assert repr(g).startswith("<aolab.GBuffer 16x9")
    assert aolab.compute("hbao", g, radius=1.0).shape == (9, 16)
    assert g.view_positions().shape == (9, 16, 3)


@pytest.mark.parametrize("name, call", [
    ("blur_sigma", lambda g, v: aolab.compute("sao", g, radius=1.0, blur=True, blur_sigma=v)),
    ("sigma", lambda g, v: aolab.gaussian_blur(np.ones((9, 16), np.float32), g, sigma=v)),
    ("radius", lambda g, v: aolab.rtao_range(g, SimpleNamespace(vertices=0, triangles=0),
                                             radius=v)),
    ("extent", lambda g, v: aolab.analytic_scene_mesh("plane", extent=v)),
    ("distance", lambda g, v: aolab.analytic_scene_mesh("plane", distance=v)),
    ("distance", lambda g, v: aolab.analytic_scene("plane", 4, 4, distance=v)),
    ("radius", lambda g, v: aolab.analytic_scene("plane", 4, 4, radius=v)),
])
def test_sibling_floats_are_checked_before_float32(plane, name, call):
    message = refused(lambda: call(plane, 1e300), f"{name} must be", f"got 1e+300, {ABOVE}")
    assert message.startswith(name)


def test_a_radius_out_of_the_methods_range_is_quoted_as_given(plane):
    refused(lambda: aolab.compute("sao", plane, radius=1e300),
            "radius must be in [1e-12, 1e+30] view-space units, got 1e+300")


# --- B: camera_motion and accumulate -----------------------------------------------------

@pytest.mark.parametrize("key, value, shown", [
    ("fx", 0, "fx must be a finite focal length > 0 px, got 0"),
    ("fx", 1e-45, "fx must be a finite focal length > 0 px, got 1e-45, below float32's"),
    ("fx", "1", "fx must be a finite focal length > 0 px, got '1' (str)"),
    ("fy", True, "fy must be a finite focal length > 0 px, got True (bool)"),
    ("cx", 1e39, "cx must be finite, got 1e+39, " + ABOVE),
])
def test_camera_motion_checks_the_intrinsics_as_the_gbuffer_does(plane, key, value, shown):
    refused(lambda: aolab.camera_motion({**plane.sidecar, key: value}, plane), "previous: " + shown)
    with pytest.raises(ValueError, match=key):
        aolab.GBuffer(plane.depth, **{**K, key: value})


@pytest.mark.parametrize("axis", [0, 1, 2])
@pytest.mark.parametrize("move", [1e300, -1e300, 1e308, 1e38])
def test_camera_motion_is_finite_or_nan_without_a_warning(plane, axis, move):
    c2w = np.array(plane.sidecar["camera_to_world"])
    c2w[axis, 3] += move
    motion = aolab.camera_motion({**plane.sidecar, "camera_to_world": c2w.tolist()}, plane)
    assert motion.dtype == np.float32 and not np.isinf(motion).any()
    # A pixel is NaN in both components or in neither.
    assert np.array_equal(np.isnan(motion[..., 0]), np.isnan(motion[..., 1]))


def test_camera_motion_at_rest_is_still_zero(plane):
    assert np.abs(aolab.camera_motion(plane, plane)).max() < 1e-4


@pytest.mark.parametrize("bad, shown", [(7.0, "7.0"), (-0.5, "-0.5"), (np.inf, "inf"),
                                        (1.0000001, "1.0000001")])
def test_accumulate_refuses_ao_outside_zero_one(plane, bad, shown):
    ao = np.ones((9, 16), np.float32)
    ao[2, 5] = bad
    history = aolab.TemporalHistory()
    still = np.zeros((9, 16, 2), np.float32)
    refused(lambda: aolab.accumulate(ao, plane, still, history),
            f"ao must be in [0, 1] (ambient accessibility), got {shown} at pixel (x=5, y=2)")
    assert history.empty   # left as it was
    ao[2, 5] = 0.25
    assert aolab.accumulate(ao, plane, still, history)[0][2, 5] == np.float32(0.25)


def test_accumulate_leaves_nan_to_the_step_s_own_rule(plane):
    ao = np.ones((9, 16), np.float32)
    ao[4, 8] = np.nan
    refused(lambda: aolab.accumulate(ao, plane, np.zeros((9, 16, 2), np.float32),
                                     aolab.TemporalHistory()),
            "ao must be finite on geometry pixels (at 8, 4)")


# --- B: nothing to score is refused, never answered --------------------------------------

def test_metrics_refuses_an_empty_mask_and_a_nan_reference():
    ao = np.ones((4, 5), np.float32)
    refused(lambda: aolab.metrics(ao, ao, np.zeros((4, 5), bool)), "mask must select")
    refused(lambda: aolab.metrics(ao, np.full_like(ao, np.nan)), "reference must be finite")


@pytest.fixture
def gbuffers(tmp_path):
    """An analytic G-buffer whose AO pass is all NaN (blocks) and one with no geometry."""
    blocks = aolab.analytic_scene("blocks", 32, 18)
    assert np.isnan(blocks.reference[blocks.valid_mask()]).all()
    aolab.save_gbuffer(tmp_path / "blocks.exr", blocks, reference=blocks.reference,
                       sidecar=blocks.sidecar)
    empty = aolab.GBuffer(np.full((9, 16), np.inf, np.float32), **K)
    aolab.save_gbuffer(tmp_path / "empty.exr", empty, reference=np.ones((9, 16), np.float32),
                       sidecar={**K, "width": 16, "height": 9, "ao_distance": 1.0})
    return tmp_path


def test_advise_refuses_an_all_nan_ao_pass_before_the_work(gbuffers):
    before = snapshot(gbuffers)
    res = aolab_cmd("advise", gbuffers / "blocks.exr", "--json", gbuffers / "out.json")
    one_line_exit_2(res, f"the AO pass of {gbuffers / 'blocks.exr'} has no finite value on any "
                    "geometry pixel", "--reference quick")
    assert "RuntimeWarning" not in res.stderr and not res.stdout
    assert snapshot(gbuffers) == before


def test_advise_refuses_a_frame_with_no_geometry_before_the_work(gbuffers):
    before = snapshot(gbuffers)
    res = aolab_cmd("advise", gbuffers / "empty.exr")
    one_line_exit_2(res, f"{gbuffers / 'empty.exr'} has no geometry pixel", "nothing to score")
    assert not res.stdout and snapshot(gbuffers) == before


def test_advise_run_refuses_nothing_to_score_too(gbuffers):
    """The add-on's Advise calls advise.run itself."""
    g = aolab.load_gbuffer(gbuffers / "blocks.exr")
    ref = advise.quick_reference.cycles(g)
    refused(lambda: advise.run(g, ref, 1.0, name="blocks"), "the AO pass of blocks")


def test_an_ao_pass_without_recorded_samples_is_not_called_a_0_spp_cycles_render():
    """An analytic plane's closed-form AO pass has no samples in its sidecar: the advice says
    what it scores against, not "Cycles 0 spp"."""
    plane = aolab.analytic_scene("plane", 32, 18)
    ref = advise.quick_reference.cycles(plane)
    assert ref.samples == 0 and ref.label == "the G-buffer's AO pass (samples unknown)"
    assert advise.quick_reference.label("cycles", 1024) == "Cycles 1024 spp"


# --- D: the command line's floats, budget and limits folder ------------------------------

@pytest.mark.parametrize("command", [["analytic", "plane", "{tmp}/a.exr"],
                                     ["run", "sao", "analytic:plane", "--out", "{tmp}/o"],
                                     ["rtao", "analytic:plane", "--out", "{tmp}/o"]])
def test_radius_beyond_float32_is_refused_quoting_the_text(tmp_path, command):
    res = aolab_cmd(*[c.format(tmp=tmp_path) for c in command], "--radius", "1e300")
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert ("argument --radius: --radius must be a number > 0 view-space units, got '1e300', "
            + ABOVE) in res.stderr
    assert "got inf" not in res.stderr and not list(tmp_path.iterdir())


def test_the_bridge_checks_its_radius_alike():
    from aolab.util.arguments import float_option
    parse = float_option("--radius", unit="scene units", float32=True)
    with pytest.raises(Exception, match=r"got '1e39', above float32's largest"):
        parse("1e39")
    assert parse("3.4028235e38") == 3.4028235e38


def test_a_budget_at_its_bound_is_taken_and_one_beyond_names_the_bound():
    assert parse_budget("1e6") == 1e6 == MAX_BUDGET_MS
    assert parse_budget("16ms") == parse_budget("1.6e1 ms") == 16.0
    for text in ("2e6", "1000001", "0", "nan", "inf", "1e", "16 s"):
        refused(lambda: parse_budget(text), "--budget must be", "at most 1000000",
                f"got {text!r}")


def test_the_budget_on_the_command_line(gbuffers):
    res = aolab_cmd("advise", gbuffers / "blocks.exr", "--budget", "2e6")
    one_line_exit_2(res, "--budget must be a time per 1280x720 frame in ms, more than 0 and at "
                    "most 1000000", "got '2e6'")


def test_a_limits_entry_that_is_a_file_is_named(tmp_path):
    folder = tmp_path / "scene"
    folder.mkdir()
    g = aolab.analytic_scene("crease", 24, 14, radius=0.5)
    ref = np.where(np.isfinite(g.reference), g.reference, 1.0).astype(np.float32)
    aolab.save_gbuffer(folder / "reference.exr", g, reference=ref, sidecar=g.sidecar)
    (folder / "limits").write_text("mine\n")
    before = snapshot(folder)
    res = aolab_cmd("limits", folder, "--thickness", "1", "--rays", "4", "--threads", "1")
    one_line_exit_2(res, "the limits folder of a scene must be a folder, got "
                    f"'{folder / 'limits'}', which is a regular file")
    assert "File exists" not in res.stderr and snapshot(folder) == before
    refused(lambda: limits.compute_scene(folder, (1.0,), 4, 2**31, False),
            THREADS + "2147483648")


# --- the shared helpers ------------------------------------------------------------------

@settings(max_examples=200, deadline=None)
@given(st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers()))
def test_float32_number_is_the_float_or_a_value_error_never_inf(value):
    try:
        got = values.float32_number("x", value)
    except ValueError as e:
        assert str(e).startswith("x must be a finite number, got ")
    else:
        assert np.isfinite(np.float32(got)) and got == float(value)
