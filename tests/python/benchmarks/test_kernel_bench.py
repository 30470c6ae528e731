"""aolab bench-table's blocks table (core/python/aolab/benchmarks/kernel_bench.py): one row per
method with consistent columns, the shared blur's row, its options checked; timings themselves
are never asserted."""

import json
import subprocess
import sys

import pytest

import aolab
from aolab.benchmarks import kernel_bench

SMALL = (48, 27)


def test_rows_are_consistent():
    rows = kernel_bench.table(["hbao", "crytek_ssao"], repeat=1, size=SMALL, progress=None)
    assert [r["method"] for r in rows] == ["hbao", "crytek_ssao", kernel_bench.BLUR_ROW]
    for r in rows:
        assert r["size"] == list(SMALL)
        for key in ("scalar_ms", "simd_1t_ms", "simd_2t_ms", "speedup", "threads_ratio"):
            assert r[key] > 0
        assert r["speedup"] == pytest.approx(r["scalar_ms"] / r["simd_2t_ms"])
        assert r["threads_ratio"] == pytest.approx(r["simd_1t_ms"] / r["simd_2t_ms"])
    hbao = rows[0]
    assert hbao["simd_kernel"] is True
    assert hbao["settings"] == {"directions": 8, "steps": 8}   # medium, the blur left out
    spp = 8 * 8
    assert hbao["msamples_per_s"] == pytest.approx(
        SMALL[0] * SMALL[1] * spp / hbao["simd_2t_ms"] / 1000.0)


def test_scaling_and_radius_columns_keep_the_table_square():
    rows = kernel_bench.table(["alchemy"], repeat=1, size=SMALL, radii=True, progress=None)
    cells = kernel_bench.header(False, True).splitlines()[0].count("|")
    assert set(rows[0]["radius_ms"]) == {str(k) for k in kernel_bench.RADIUS_SCALES}
    ratio = rows[0]["radius_ms"]["8"] / rows[0]["simd_2t_ms"]
    assert rows[0]["radius_ratio"] == pytest.approx(ratio)
    for row in rows:
        assert kernel_bench.format_row(row).count("|") == cells


def test_peak_memory_counts_at_least_the_output():
    # HBAO holds its depth copy, the prepared normals and the output: well above the output's
    # own 640 x 360 floats, whatever the allocator keeps.
    output_mib = 640 * 360 * 4 / 2**20
    assert kernel_bench.peak_memory_mb("hbao", {}, size=(640, 360)) > 2 * output_mib


def test_samples_per_pixel_follow_the_settings():
    assert kernel_bench.samples_per_pixel("hbao", {"directions": 4, "steps": 3}) == 12
    assert kernel_bench.samples_per_pixel("gtao", {"slices": 2, "steps": 5}) == 20
    assert kernel_bench.samples_per_pixel("lsao", {}) is None


def test_simd_target_is_a_highway_name():
    assert aolab.simd_target() in {"AVX3_SPR", "AVX3_ZEN4", "AVX3_DL", "AVX3", "AVX2", "SSE4",
                                   "SSSE3", "SSE2", "EMU128", "SCALAR", "NEON", "SVE", "SVE2",
                                   "SVE_256", "SVE2_128", "PPC8", "WASM", "RVV"}


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "aolab", "bench-table", *args],
                          capture_output=True, text=True, timeout=300)


def test_cli_prints_the_table_and_writes_json(tmp_path):
    out = tmp_path / "rows.json"
    r = _cli("alchemy", "--size", "40x24", "--repeat", "1", "--json", str(out), "--no-scenes")
    assert r.returncode == 0, r.stderr
    lines = [line for line in r.stdout.splitlines() if line]
    assert lines[0].startswith("# aolab bench-table")
    assert "commit" in lines[0] and "SIMD target" in lines[0]
    assert lines[1].startswith("## Scalar code against SIMD kernel") and "40x24" in lines[1]
    assert lines[2].startswith("| method |")
    assert lines[4].startswith("| alchemy | medium |")
    assert lines[5].startswith(f"| {kernel_bench.BLUR_ROW} |")
    assert len(lines) == 6   # no scene timed, so no target either
    assert [row["method"] for row in json.loads(out.read_text())["blocks"]] == [
        "alchemy", kernel_bench.BLUR_ROW]


@pytest.mark.parametrize("args, needle", [
    (["--size", "0x5"], "--size must be WxH"),
    (["--size", "12"], "--size must be WxH"),
    (["--repeat", "0"], "--repeat"),
    (["no_such_method", "--size", "8x8"], "no_such_method"),
])
def test_cli_refuses_bad_options(args, needle):
    r = _cli(*args)
    assert r.returncode == 2
    assert needle in r.stderr


@pytest.mark.parametrize("args, said", [
    (["--preset", "nope"], "preset 'nope' of alchemy is not one of ['default', 'low', "
     "'medium'"),
    (["--preset", "Medium"], "preset 'Medium' of alchemy is not one of"),
    (["screen_space_limit", "--preset", "medium"],
     "preset 'medium' of screen_space_limit is not one of ['default']"),
])
def test_a_preset_is_checked_as_compute_checks_it_before_any_timing(args, said):
    """--preset nope timed the defaults under the label nope, and --preset Medium too."""
    r = _cli(*(args if args[0] == "screen_space_limit" else ["alchemy", *args]),
             "--size", "8x8", "--repeat", "1")
    assert r.returncode == 2 and r.stdout == "", r.stdout
    assert r.stderr.strip().startswith("aolab: " + said), r.stderr


def test_a_method_without_the_default_preset_is_labelled_with_what_ran():
    """screen_space_limit (a bound: only its defaults) was labelled medium."""
    rows = kernel_bench.table(["screen_space_limit", "alchemy"], repeat=1, size=(8, 8),
                              blur=False, progress=None)
    assert [(r["method"], r["preset"]) for r in rows] == [("screen_space_limit", "default"),
                                                          ("alchemy", "medium")]
    assert rows[1]["settings"] == {"samples": 8}


@pytest.mark.parametrize("option, path, said", [
    ("--json", "{tmp}", "--json must be a file, got '{tmp}', which is a folder"),
    ("--json", "{tmp}/no/rows.json", "--json '{tmp}/no/rows.json': the folder {tmp}/no does "
     "not exist"),
    ("--profile", "{tmp}/file", "--profile must be a folder, got '{tmp}/file', which is a "
     "regular file"),
])
def test_output_paths_are_checked_before_any_timing(tmp_path, option, path, said):
    """--json DIR and --profile FILE were refused only after the whole table."""
    (tmp_path / "file").write_text("x")
    r = _cli("alchemy", "--size", "8x8", "--repeat", "1", option, path.format(tmp=tmp_path))
    assert r.returncode == 2 and r.stdout == "", r.stdout
    assert r.stderr.strip() == "aolab: " + said.format(tmp=tmp_path), r.stderr
