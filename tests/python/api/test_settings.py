"""aolab.settings: the Python side of method settings that the command line, the study and
the add-on share: values from text (choices by name), defaults at stored precision."""
import numpy as np
import pytest

from aolab import settings


def test_text_values_follow_the_setting():
    # "off" is vao_pp culling's name, but the boolean false for filter.
    assert settings.parse_assignments(["culling=off", "samples=8", "filter=off",
                                       "filter_sigma=2.5"], "vao_pp") == {
        "culling": "off", "samples": 8, "filter": False, "filter_sigma": 2.5}
    # Without a method (or for an unknown name): numbers and bools, other text as it is.
    assert settings.parse_assignments(["a=1", "b=on", "c=1e3", "d=clipped"]) == {
        "a": 1, "b": True, "c": 1000.0, "d": "clipped"}
    with pytest.raises(ValueError, match="KEY=VALUE"):
        settings.parse_assignments(["directions"])


def test_changed_settings_compare_at_the_stored_precision():
    values = {"falloff": "rational", "sampling": "interpolate",
              "line_spacing": float(np.float32(1.64)), "directions": 16, "radius": 3.0}
    assert settings.changed_settings("lsao", values) == {"sampling": "interpolate"}
    assert settings.changed_settings("lsao", {"line_spacing": 2.0}) == {"line_spacing": 2.0}


def test_described_and_allowed_values():
    names = [s["name"] for s in settings.described("lsao")]
    assert "radius" not in names and "falloff" in names
    by_name = settings.by_name("lsao")
    assert settings.describe_value(by_name["falloff"]) == "one of rational, clipped, cutoff"
    assert settings.describe_value(by_name["line_spacing"]) == "range [1, 64] px"
