"""`power`, the post-step shared by every method (AO^power after the method, applied by the
registry; docs/conventions.md): listed by method_info, bit-identical at 1, the square at 2,
background kept at 1, out-of-range values a ValueError naming it, and the command's
``--set power=2``."""
import json
import subprocess
import sys

import numpy as np
import pytest

import aolab

METHODS = aolab.methods()


@pytest.mark.parametrize("method", METHODS)
def test_method_info_lists_power_last(method):
    settings = aolab.method_info(method)["settings"]
    power = settings[-1]
    assert power["name"] == "power" and [s["name"] for s in settings].count("power") == 1
    assert (power["type"], power["default"], power["min"], power["max"], power["unit"]) == (
        "float", 1.0, pytest.approx(0.1), 10.0, "")


@pytest.mark.parametrize("method", METHODS)
def test_power_one_is_bit_identical_and_two_squares(method):
    g = aolab.analytic_scene("blocks", 96, 54)
    depth = g.depth.copy()
    depth[:, :8] = np.inf  # background
    g = aolab.GBuffer(depth, g.normal, fx=g.fx, fy=g.fy, cx=g.cx, cy=g.cy)
    ao = aolab.compute(method, g, radius=0.5)
    assert aolab.compute(method, g, radius=0.5, power=1).tobytes() == ao.tobytes()
    squared = aolab.compute(method, g, radius=0.5, power=2)
    assert ao.min() < 0.9
    assert squared.tobytes() == (ao * ao).tobytes()  # float32 products
    assert (squared[:, :8] == 1.0).all()


@pytest.mark.parametrize("value", [0.05, 10.5, float("nan"), float("inf"), -1])
def test_out_of_range_power_is_valueerror_naming_it(value):
    g = aolab.analytic_scene("plane", 16, 9)
    with pytest.raises(ValueError, match=r"^power must be in \[0\.1, 10\]"):
        aolab.compute("hbao", g, radius=1.0, power=value)


def test_vao_pp_with_stats_applies_power_too():
    g = aolab.analytic_scene("blocks", 96, 54)
    ao = aolab.compute("vao_pp", g, radius=0.5, power=2)
    with_stats, stats = aolab.vao_pp_with_stats(g, radius=0.5, power=2)
    assert with_stats.tobytes() == ao.tobytes() and stats["pixels"] > 0


def test_command_line_sets_power(tmp_path):
    out = tmp_path / "hbao"
    results = {}
    for p in (1, 2):
        subprocess.run([sys.executable, "-m", "aolab", "run", "hbao", "analytic:wall", "--width",
                        "64", "--height", "36", "--set", f"power={p}", "--out", str(out),
                        "--json", str(tmp_path / f"r{p}.json")],
                       capture_output=True, text=True, check=True)
        results[p] = json.loads((tmp_path / f"r{p}.json").read_text())
    assert results[2]["settings"] == {"power": 2}
    # Squaring darkens: the bias against the exact reference drops.
    assert results[2]["metrics"]["bias"] < results[1]["metrics"]["bias"]


def test_power_gives_the_same_bits_for_any_thread_count():
    """The power step runs over rows in parallel: its bits must not depend on it."""
    g = aolab.analytic_scene("blocks", 160, 90)
    one = aolab.compute("hbao", g, radius=0.25, power=2.3, threads=1)
    plain = aolab.compute("hbao", g, radius=0.25, threads=1)
    for threads in (2, 3, 7):
        np.testing.assert_array_equal(
            aolab.compute("hbao", g, radius=0.25, power=2.3, threads=threads), one)
    # One rounding from double: the float of (double AO)^p.
    expected = (plain.astype(np.float64) ** np.float64(np.float32(2.3))).astype(np.float32)
    np.testing.assert_array_equal(one, expected)
