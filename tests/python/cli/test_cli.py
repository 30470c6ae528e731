"""The aolab command: analytic scene -> EXR -> run -> EXR/PNG + metrics."""
import json
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
import pytest


def aolab_cmd(*args, check=True):
    return subprocess.run([sys.executable, "-m", "aolab", *args], capture_output=True,
                          text=True, check=check)


def test_analytic_then_run_writes_images_and_scores(tmp_path):
    exr = tmp_path / "wall.exr"
    aolab_cmd("analytic", "wall", str(exr), "--radius", "2", "--width", "160", "--height", "90")
    assert exr.exists() and exr.with_suffix(".json").exists()
    out = tmp_path / "wall_hbao"
    res = aolab_cmd("run", "hbao", str(exr), "--out", str(out), "--json", str(tmp_path / "r.json"),
                    "--set", "directions=12")
    assert "MAE" in res.stdout and "SSIM" in res.stdout
    result = json.loads((tmp_path / "r.json").read_text())
    assert result["radius"] == 2 and result["settings"] == {"directions": 12}
    assert 0 <= result["metrics"]["mae"] <= 1 and result["metrics"]["count"] > 0
    png = oiio.ImageBuf(str(out.with_suffix(".png")))
    exr_out = oiio.ImageBuf(str(out.with_suffix(".exr")))
    assert png.spec().width == 160 and exr_out.spec().height == 90
    ao = exr_out.get_pixels(oiio.FLOAT)
    assert np.isfinite(ao).all() and ao.min() >= 0 and ao.max() <= 1


def test_run_on_analytic_spec_and_methods_listing():
    res = aolab_cmd("run", "hbao", "analytic:plane", "--width", "64", "--height", "36",
                    "--out", "/tmp/aolab_cli_plane")
    assert "MAE 0.0000" in res.stdout  # an open plane against its exact reference
    listing = aolab_cmd("methods")
    assert "hbao" in listing.stdout and "directions" in listing.stdout


@pytest.mark.parametrize("args, text", [
    (["run", "hbao", "/nonexistent.exr"], "no such"),
    (["run", "hbao", "analytic:plane", "--radius", "-1"], "radius"),
    (["run", "hbao", "analytic:plane", "--set", "directions=0"], "directions"),
])
def test_errors_are_clear(args, text):
    res = aolab_cmd(*args, check=False)
    assert res.returncode != 0
    assert text in (res.stderr + res.stdout)


def test_choice_settings_are_given_by_name(tmp_path):
    # "off" is a choice's name here (vao_pp culling), not the boolean false.
    out = tmp_path / "vao_pp"
    aolab_cmd("run", "vao_pp", "analytic:blocks", "--width", "64", "--height", "36",
              "--set", "culling=off", "--set", "samples=8", "--out", str(out),
              "--json", str(tmp_path / "r.json"))
    result = json.loads((tmp_path / "r.json").read_text())
    assert result["settings"] == {"culling": "off", "samples": 8}
    bad = aolab_cmd("run", "lsao", "analytic:plane", "--width", "32", "--height", "18",
                    "--set", "falloff=steep", "--out", str(tmp_path / "bad"), check=False)
    assert bad.returncode == 2
    assert "falloff must be one of rational, clipped" in bad.stderr
    listing = aolab_cmd("methods").stdout
    assert "falloff" in listing and "one of rational, clipped" in listing


def test_help_lists_every_command():
    """`aolab --help`'s summary names every subcommand the parser has."""
    import argparse
    from aolab import cli
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    text = aolab_cmd("--help").stdout
    summary = text[:text.index("positional arguments")]
    missing = [name for name in sub.choices if f"aolab {name} " not in summary]
    assert not missing, f"aolab --help's summary leaves out {missing}"
