"""The named presets: `aolab.presets(method)`, `aolab.compute(..., preset=NAME)` and
`aolab run --preset NAME` (README, Use; docs/tuning.md)."""
from __future__ import annotations

import json
import re
import subprocess
import sys

import numpy as np
import pytest

import aolab
from aolab import scenes
from aolab import cli
from aolab import named_presets as presets

TUNED = {"samples": 6, "view_ray_pipes": False, "blur": True}


@pytest.fixture
def g():
    return aolab.analytic_scene("blocks", 64, 36, radius=0.5)


@pytest.fixture
def tuned_file(tmp_path, monkeypatch):
    path = tmp_path / "tuned.json"
    path.write_text(json.dumps({"methods": {"vao": {"presets": {
        "tuned-200ms": {**TUNED, "samples": 12}, "tuned-50ms": TUNED}}}}))
    monkeypatch.setenv("AOLAB_TUNED_PRESETS", str(path))
    return path


def test_every_method_has_its_defaults_and_the_studys_presets():
    for method in aolab.methods():
        named = aolab.presets(method)
        assert list(named)[0] == "default"
        defaults = {s["name"]: s["default"] for s in aolab.method_info(method)["settings"]
                    if s["name"] != "radius"}
        assert named["default"] == {**defaults, "blur": False}
        assert list(named)[1:1 + len(presets.preset_names(method))] == \
            presets.preset_names(method)
        assert all("blur" in values for values in named.values())
    assert aolab.presets("hbao")["low"] == {"directions": 4, "steps": 4, "blur": True}
    # the study's form: Pyramid HBAO's own Gaussian off, the shared blur on
    want = {"directions": 4, "samples": 2, "gaussian_filter": False, "blur": True}
    assert aolab.presets("pyramid_hbao")["low"] == want


def test_compute_with_a_preset_equals_its_settings(g):
    for method in ("hbao", "pyramid_hbao", "lsao"):
        for name, values in aolab.presets(method).items():
            want = aolab.compute(method, g, radius=0.5, **values)
            np.testing.assert_array_equal(aolab.compute(method, g, radius=0.5, preset=name),
                                          want, err_msg=f"{method} {name}")


def test_explicit_settings_and_blur_override_the_preset(g):
    got = aolab.compute("hbao", g, radius=0.5, preset="low", steps=8, blur=False)
    np.testing.assert_array_equal(got, aolab.compute("hbao", g, radius=0.5, directions=4,
                                                     steps=8))
    got = aolab.compute("vao", g, radius=0.5, preset="default", blur=True)
    want = aolab.compute("vao", g, radius=0.5, blur=True)
    np.testing.assert_array_equal(got, want)


def test_unknown_preset_or_method_is_a_value_error_naming_the_choices(g):
    with pytest.raises(ValueError, match=r"preset 'best' of hbao is not one of "
                       r"\['default', 'low', 'medium', 'high', 'ultra'"):
        aolab.compute("hbao", g, radius=0.5, preset="best")
    with pytest.raises(ValueError, match="method 'nope' is not one of"):
        aolab.presets("nope")


def test_tuned_presets_come_from_the_json(g, tuned_file):
    named = aolab.presets("vao")
    assert [n for n in named if n.startswith("tuned-")] == ["tuned-50ms", "tuned-200ms"]
    assert named["tuned-50ms"] == TUNED
    assert presets.names("vao")[-2:] == ["tuned-50ms", "tuned-200ms"]
    assert presets.preset_values("vao", "tuned-50ms") == ({"samples": 6,
                                                           "view_ray_pipes": False}, True)
    np.testing.assert_array_equal(aolab.compute("vao", g, radius=0.5, preset="tuned-50ms"),
                                  aolab.compute("vao", g, radius=0.5, **TUNED))
    assert "tuned-50ms" not in aolab.presets("hbao")
    tuned_file.write_text("{broken")
    with pytest.raises(ValueError, match="unreadable"):
        aolab.presets("vao")


def test_the_command_line_offers_the_same_presets(tmp_path, tuned_file, capsys):
    out = tmp_path / "run"
    assert cli.main(["run", "vao", "analytic:blocks", "--width", "64", "--height", "36",
                     "--radius", "0.5", "--preset", "tuned-50ms", "--out", str(out),
                     "--json", str(tmp_path / "r.json")]) == 0
    result = json.loads((tmp_path / "r.json").read_text())
    assert result["preset"] == "tuned-50ms"
    ao = scenes.read_y_exr(out.with_suffix(".exr"))
    want = aolab.compute("vao", aolab.analytic_scene("blocks", 64, 36, radius=0.5),
                         radius=0.5, preset="tuned-50ms")
    np.testing.assert_array_equal(ao, want)
    capsys.readouterr()
    assert cli.main(["presets", "vao", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["vao"] == aolab.presets("vao")
    res = subprocess.run([sys.executable, "-m", "aolab", "run", "hbao", "analytic:blocks",
                          "--width", "32", "--height", "18", "--preset", "best", "--out",
                          str(tmp_path / "x")], capture_output=True, text=True)
    assert res.returncode == 2 and "'best'" in res.stderr and "ultra" in res.stderr


# --- one check of a preset name; a bad tuned-presets file named ------------------------------

BAD_TUNED = {
    "a list": ([1, 2], "the file must be a JSON object, got a list"),
    "methods a list": ({"methods": [1]}, '"methods" must be a JSON object, got a list'),
    "presets a list": ({"methods": {"hbao": {"presets": ["x"]}}},
                       "\"presets\" of 'hbao' must be a JSON object, got a list"),
    "a budget that is no number": ({"methods": {"hbao": {"presets": {"tuned-xms": {}}}}},
                                   "preset name 'tuned-xms' of 'hbao' must be tuned-<ms>ms"),
    "a setting that is a list": (
        {"methods": {"hbao": {"presets": {"tuned-50ms": {"directions": [4]}}}}},
        "setting 'directions' of preset 'tuned-50ms' of 'hbao' must be a number, true, false "
        "or a name, got a list"),
    "an unknown setting": ({"methods": {"hbao": {"presets": {"tuned-50ms": {"nope": 1}}}}},
                           "preset 'tuned-50ms' of 'hbao' sets 'nope', which is not a setting "
                           "of hbao"),
    "blur that is no bool": ({"methods": {"hbao": {"presets": {"tuned-50ms": {"blur": 1}}}}},
                             "setting 'blur' of preset 'tuned-50ms' of 'hbao' must be true or "
                             "false, got a number, 1"),
    "not JSON": ("{x", "is unreadable: not JSON"),
}


@pytest.fixture(params=sorted(BAD_TUNED))
def bad_tuned(request, tmp_path, monkeypatch):
    data, said = BAD_TUNED[request.param]
    path = tmp_path / "tuned.json"
    path.write_text(data if isinstance(data, str) else json.dumps(data))
    monkeypatch.setenv("AOLAB_TUNED_PRESETS", str(path))
    return path, said


def test_a_bad_tuned_file_is_one_error_naming_the_file(g, bad_tuned):
    """It was AttributeError: 'list' object has no attribute 'get', or could not convert
    string to float: 'x', naming no file."""
    path, said = bad_tuned
    where = f"tuned presets file {path}"
    for call in (lambda: aolab.presets("hbao"), lambda: presets.names("hbao"),
                 lambda: aolab.compute("hbao", g, radius=0.5, preset="tuned-50ms")):
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value).startswith(where) and said in str(e.value), str(e.value)
    # The built-in presets do not read the file: they work as without it.
    np.testing.assert_array_equal(aolab.compute("hbao", g, radius=0.5, preset="low"),
                                  aolab.compute("hbao", g, radius=0.5, directions=4, steps=4,
                                                blur=True))
    # A mistyped built-in name is the first problem, the file's the second.
    with pytest.raises(ValueError, match=r"^preset 'Medium' of hbao is not one of \['default', "
                       r"'low', 'medium', 'high', 'ultra'\] \(the tuned presets are left out: "
                       + re.escape(where)):
        aolab.compute("hbao", g, radius=0.5, preset="Medium")


def test_a_bad_tuned_file_on_the_command_line(tmp_path, bad_tuned, capsys):
    path, said = bad_tuned
    assert cli.main(["presets", "hbao"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith(f"aolab: tuned presets file {path}") and said in err
    assert cli.main(["run", "hbao", "analytic:blocks", "--width", "32", "--height", "18",
                     "--preset", "low", "--out", str(tmp_path / "low")]) == 0
    assert cli.main(["run", "hbao", "analytic:blocks", "--width", "32", "--height", "18",
                     "--preset", "tuned-50ms", "--out", str(tmp_path / "t")]) == 2
    assert f"tuned presets file {path}" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["medium", "Medium", "nope", "", "tuned-50ms"])
def test_preset_values_checks_the_name_as_compute_does(name, tmp_path, monkeypatch):
    """preset_values (bench-table, the add-on's menu) gave the defaults for any name the
    method lacks; it now refuses what compute refuses."""
    monkeypatch.setenv("AOLAB_TUNED_PRESETS", str(tmp_path / "none.json"))   # no tuned ones
    if name == "medium":
        assert presets.preset_values("hbao", name) == ({"directions": 8, "steps": 8}, True)
        with pytest.raises(ValueError, match=r"preset 'medium' of screen_space_limit is not "
                           r"one of \['default'\]"):
            presets.preset_values("screen_space_limit", name)
        return
    with pytest.raises(ValueError, match=f"^preset {re.escape(repr(name))} of hbao is not one"):
        presets.preset_values("hbao", name)
