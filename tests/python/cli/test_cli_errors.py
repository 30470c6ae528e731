"""The aolab command never traces back on bad input: a bad option value is refused when the
command line is read (argparse: usage line, exit status 2), any error of a command is one line
``aolab: <message>`` on stderr with exit status 2, Ctrl-C exits with 130, and
``aolab --debug ...`` shows the traceback instead."""
import json
import math
import os

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

import aolab
from aolab import cli
from cli_support import aolab_cmd, assert_one_error_line, status_of, terminal_lines

TINY = ["--width", "8", "--height", "8", "--threads", "1"]


# --- the property: generated option values give 0 or 2, never a traceback --------------------

option_values = st.one_of(
    st.integers(),
    st.sampled_from([0, 1, -1, 2, 3, 4, 128, 129, 130, 1000, 1001, 4096, 4097, 16384, 16385,
                     100000, 2**31, 2**32, 2**63, -2**63, 10**40]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["nan", "inf", "-inf", "1e999", "0.0", "1e-300", "0x10", "1_000", " 7 ",
                     "", "-", "--", "8.5", "9" * 5000]),
    st.text(alphabet=st.characters(blacklist_categories=("Cs",), blacklist_characters="\x00"),
            max_size=12),
).map(str)

#: The commands run in-process on tiny analytic scenes: the options the property varies.
RUN_OPTIONS = ["--radius", "--width", "--height", "--threads", "--blur-sigma", "--blur-taps"]
BENCH_OPTIONS = ["--radius", "--width", "--height", "--threads", "--repeat", "--warmup"]
ANALYTIC_OPTIONS = ["--radius", "--width", "--height"]


def _check(argv, capsys):
    capsys.readouterr()
    code = status_of(argv)
    err = capsys.readouterr().err
    assert code in (0, 2), (argv, code, err)
    assert "Traceback" not in err
    if code == 2:
        assert err.strip(), argv
        last = terminal_lines(err)[-1]
        assert last.startswith("aolab: ") or "error: argument" in last, err


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(option=st.sampled_from(RUN_OPTIONS), value=option_values)
def test_run_options_never_trace_back(capsys, tmp_path_factory, option, value):
    out = tmp_path_factory.getbasetemp() / "prop_run" / "ao"
    _check(["run", "hbao", "analytic:plane", *TINY, "--blur", "--out", str(out),
            f"{option}={value}"], capsys)


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(option=st.sampled_from(BENCH_OPTIONS), value=option_values)
def test_bench_options_never_trace_back(capsys, option, value):
    _check(["bench", "hbao", "analytic:plane", *TINY, "--repeat", "1", "--warmup", "0",
            f"{option}={value}"], capsys)


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(option=st.sampled_from(ANALYTIC_OPTIONS), value=option_values)
def test_analytic_options_never_trace_back(capsys, tmp_path_factory, option, value):
    out = tmp_path_factory.getbasetemp() / "prop_analytic" / "plane.exr"
    _check(["analytic", "plane", str(out), "--width", "8", "--height", "8",
            f"{option}={value}"], capsys)


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(setting=st.sampled_from(["directions", "steps", "jitter", "integral", "power", "seed",
                                "radius", "bogus", ""]),
       value=option_values)
def test_run_settings_never_trace_back(capsys, tmp_path_factory, setting, value):
    out = tmp_path_factory.getbasetemp() / "prop_set" / "ao"
    _check(["run", "hbao", "analytic:plane", *TINY, "--out", str(out),
            "--set", f"{setting}={value}"], capsys)


def _integer(lo, hi=None, odd=False):
    return lambda v: (isinstance(v, int) and v >= lo and (hi is None or v <= hi)
                      and (not odd or v % 2 == 1))


def _positive(allow_inf=False):
    return lambda v: v > 0 and (math.isfinite(v) or (allow_inf and v == math.inf))


#: Commands that would run on real scenes (or Blender): only what argparse accepts is checked,
#: against the option's range.
PARSE_ONLY = {
    ("compare",): {"--repeat": _integer(1, 1000), "--warmup": _integer(0, 1000),
                   "--threads": _integer(0, 4096), "--budget-ms": _positive(),
                   "--max-ms": lambda v: v > 0 and not math.isnan(v),
                   "--image-width": _integer(1, 16384)},
    ("tune",): {"--trials": _integer(1), "--max-ms": _positive(),
                "--timeout": lambda v: math.isfinite(v) and v >= 0,
                "--repeat": _integer(1, 1000), "--warmup": _integer(0, 1000),
                "--threads": _integer(0, 4096), "--seed": _integer(0, 2**32 - 1)},
    ("limits",): {"--rays": _integer(1, 65536), "--threads": _integer(0, 4096),
                  "--thickness": lambda v: len(v) == 1 and _positive(True)(v[0])},
    ("reference", "scene"): {"--spp": _integer(1), "--gbuffer-samples": _integer(1),
                             "--radius": _positive()},
}
PARSE_CASES = [(cmd, opt) for cmd, opts in PARSE_ONLY.items() for opt in opts]


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(case=st.sampled_from(PARSE_CASES), value=option_values)
def test_study_options_are_checked_when_read(capsys, case, value):
    command, option = case
    capsys.readouterr()
    try:
        args = cli.build_parser().parse_args([*command, f"{option}={value}"])
    except SystemExit as e:
        err = capsys.readouterr().err
        assert e.code == 2 and "Traceback" not in err
        assert f"argument {option}" in err, err
        return
    assert PARSE_ONLY[command][option](getattr(args, option[2:].replace("-", "_"))), value


@settings(max_examples=20, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(command=st.sampled_from(["compare", "limits"]),
       option=st.sampled_from(["--repeat", "--warmup", "--threads", "--rays", "--budget-ms",
                               "--image-width"]),
       value=option_values)
def test_study_commands_without_scenes_exit_2(capsys, tmp_path_factory, command, option, value):
    # A scenes folder that does not exist: the command refuses the value or the scene, fast.
    if command == "limits" and option not in ("--rays", "--threads"):
        option = "--rays"
    if command == "compare" and option == "--rays":
        option = "--repeat"
    base = tmp_path_factory.getbasetemp()
    argv = [command, "nosuchscene", "--scenes-dir", str(base / "no_scenes_here"),
            f"{option}={value}"]
    if command == "compare":
        argv += ["--out", str(base / "prop_compare"), "--no-progress"]
    capsys.readouterr()
    assert status_of(argv) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.strip()


# --- one test per defect ---------------------------------------------------------------------

@pytest.mark.parametrize("text, said", [("directions=abc", "directions must be an integer, "
                                         "got 'abc'"),
                                        ("directions=", "directions must be an integer, got ''"),
                                        ("power=x", "power must be a number, got 'x'"),
                                        ("jitter=maybe", "jitter must be true or false")])
def test_set_text_that_is_no_value_names_the_setting(capsys, tmp_path, text, said):
    for command in ("run", "bench"):
        argv = [command, "hbao", "analytic:plane", *TINY, "--set", text]
        if command == "run":
            argv += ["--out", str(tmp_path / "ao")]
        assert status_of(argv) == 2
        assert_one_error_line(capsys.readouterr().err, said)


@pytest.mark.parametrize("key, option", [("radius", "--radius"), ("threads", "--threads"),
                                         ("blur", "--blur"), ("preset", "--preset")])
def test_set_of_an_option_says_which_option(capsys, tmp_path, key, option):
    assert status_of(["run", "hbao", "analytic:plane", *TINY, "--out", str(tmp_path / "ao"),
                      "--set", f"{key}=2"]) == 2
    assert_one_error_line(capsys.readouterr().err, f"--set {key}=", f"use {option}")
    assert not (tmp_path / "ao.exr").exists()


def test_missing_input_exits_2(capsys, tmp_path):
    assert status_of(["run", "hbao", str(tmp_path / "missing.exr")]) == 2
    assert_one_error_line(capsys.readouterr().err, "no such G-buffer file", "missing.exr")
    res = aolab_cmd("run", "hbao", str(tmp_path / "missing.exr"))
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert_one_error_line(res.stderr, "missing.exr")


def test_input_under_a_file_exits_2(capsys, tmp_path):
    (tmp_path / "file").write_text("x")
    assert status_of(["bench", "hbao", str(tmp_path / "file" / "x.exr")]) == 2
    assert_one_error_line(capsys.readouterr().err, "is a file, not a folder")


def test_folder_input_is_refused(capsys, tmp_path):
    folder = tmp_path / "scene.exr"
    folder.mkdir()
    assert status_of(["run", "hbao", str(folder), "--out", str(tmp_path / "ao")]) == 2
    assert_one_error_line(capsys.readouterr().err, "must be a regular file", "a folder")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_fifo_input_is_refused_without_opening_it(tmp_path):
    fifo = tmp_path / "x.exr"
    os.mkfifo(fifo)
    # Opening a FIFO for reading waits for a writer forever: the timeout catches a regression.
    res = aolab_cmd("run", "hbao", str(fifo), "--out", str(tmp_path / "ao"), timeout=60)
    assert res.returncode == 2
    assert_one_error_line(res.stderr, "must be a regular file", "FIFO")


@pytest.mark.parametrize("make_folder", [True, False])
def test_out_folder_gets_method_ao_inside(capsys, tmp_path, make_folder):
    folder = tmp_path / "results"
    if make_folder:
        folder.mkdir()
    out = str(folder) + ("" if make_folder else "/")
    assert status_of(["run", "gtao", "analytic:plane", *TINY, "--out", out]) == 0
    assert (folder / "gtao_ao.exr").is_file() and (folder / "gtao_ao.png").is_file()
    assert not (tmp_path / "results.exr").exists()


def test_out_with_another_suffix_is_refused(capsys, tmp_path):
    assert status_of(["run", "hbao", "analytic:plane", *TINY,
                      "--out", str(tmp_path / "x.txt")]) == 2
    assert_one_error_line(capsys.readouterr().err, "'.txt'", "--out")
    assert list(tmp_path.iterdir()) == []


def test_out_with_an_image_suffix_or_a_dot_in_the_name(capsys, tmp_path):
    assert status_of(["run", "hbao", "analytic:plane", *TINY,
                      "--out", str(tmp_path / "x.exr")]) == 0
    assert (tmp_path / "x.exr").is_file() and (tmp_path / "x.png").is_file()
    assert status_of(["run", "hbao", "analytic:plane", *TINY,
                      "--out", str(tmp_path / "v1.5")]) == 0
    assert (tmp_path / "v1.5.exr").is_file() and (tmp_path / "v1.5.png").is_file()


def test_out_under_a_file_exits_2(capsys, tmp_path):
    (tmp_path / "somefile").write_text("x")
    assert status_of(["run", "hbao", "analytic:plane", *TINY,
                      "--out", str(tmp_path / "somefile" / "x")]) == 2
    assert_one_error_line(capsys.readouterr().err, "is a file, not a folder")
    assert status_of(["analytic", "plane", str(tmp_path / "somefile" / "x.exr"),
                      "--width", "8", "--height", "8"]) == 2
    assert_one_error_line(capsys.readouterr().err, "is a file, not a folder")


@pytest.mark.parametrize("argv, option", [
    (["bench", "hbao", "--repeat", "0"], "--repeat"),
    (["bench", "hbao", "--warmup", "-1"], "--warmup"),
    (["run", "hbao", "analytic:plane", "--threads", "-1"], "--threads"),
    (["run", "hbao", "analytic:plane", "--blur-taps", "4"], "--blur-taps"),
    (["run", "hbao", "analytic:plane", "--blur-sigma", "0"], "--blur-sigma"),
    (["run", "hbao", "analytic:plane", "--radius", "nan"], "--radius"),
    (["compare", "--image-width", "0"], "--image-width"),
    (["compare", "--budget-ms", "-5"], "--budget-ms"),
    (["tune", "--trials", "0"], "--trials"),
    (["tune", "--max-ms", "inf"], "--max-ms"),
    (["tune", "--timeout", "-1"], "--timeout"),
    (["limits", "--rays", "0"], "--rays"),
    (["limits", "--thickness", "0.25", "-1"], "--thickness"),
])
def test_bad_values_are_refused_when_read(capsys, argv, option):
    assert cli.main(argv) == 2     # argparse's status, returned
    err = capsys.readouterr().err
    assert err.startswith("usage: ") and f"argument {option}: {option} must be" in err
    assert "Traceback" not in err


@pytest.mark.parametrize("command", [["run", "hbao", "analytic:plane"],
                                     ["analytic", "plane", "never_written.exr"]])
def test_huge_analytic_scene_is_refused_when_read(capsys, command):
    # 100000 x 100000 used to reach the library and raise MemoryError.
    assert cli.main([*command, "--width", "100000", "--height", "100000"]) == 2
    assert "--width must be an integer in [1, 16384], got 100000" in capsys.readouterr().err


@pytest.mark.parametrize("error, said", [
    (ValueError("two\nlines"), "aolab: two lines"),
    (KeyError("x"), "aolab: KeyError: 'x'"),
    (TypeError("bad type"), "aolab: TypeError: bad type"),
    (MemoryError(), "aolab: MemoryError"),
    (RecursionError(), "aolab: RecursionError"),
    (RuntimeError(""), "aolab: RuntimeError"),
    (ZeroDivisionError("division by zero"), "aolab: ZeroDivisionError: division by zero"),
    (FileNotFoundError(2, "No such file or directory", "a.exr"),
     "aolab: No such file or directory: 'a.exr'"),
    (IsADirectoryError(21, "Is a directory", "d"), "aolab: Is a directory: 'd'"),
    (NotADirectoryError(20, "Not a directory", "f/x"), "aolab: Not a directory: 'f/x'"),
    (UnicodeDecodeError("utf-8", b"\xff", 0, 1, "invalid start byte"),
     "aolab: UnicodeDecodeError: 'utf-8' codec can't decode"),
    (json.JSONDecodeError("Expecting value", "", 0), "aolab: JSONDecodeError: Expecting value"),
    (SystemExit("aolab: said before"), "aolab: said before"),
])
def test_any_exception_of_a_command_is_one_line_and_status_2(capsys, monkeypatch, tmp_path,
                                                             error, said):
    def fail(*args, **kwargs):
        raise error
    monkeypatch.setattr(aolab, "compute", fail)
    assert cli.main(["run", "hbao", "analytic:plane", *TINY,
                     "--out", str(tmp_path / "ao")]) == 2
    err = capsys.readouterr().err
    assert_one_error_line(err)
    assert err.startswith(said), err


def test_ctrl_c_exits_130_with_a_short_line(capsys, monkeypatch):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(aolab, "compute", interrupted)
    assert cli.main(["bench", "hbao", "analytic:plane", *TINY]) == 130
    assert capsys.readouterr().err == "aolab: interrupted\n"
    with pytest.raises(KeyboardInterrupt):
        cli.main(["--debug", "bench", "hbao", "analytic:plane", *TINY])


def test_debug_shows_the_traceback(capsys, tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.exr"):
        cli.main(["--debug", "run", "hbao", str(tmp_path / "missing.exr")])
    res = aolab_cmd("--debug", "run", "hbao", "analytic:plane", "--set", "directions=abc")
    assert res.returncode == 1
    assert "Traceback" in res.stderr and "directions must be an integer" in res.stderr
    res = aolab_cmd("run", "hbao", "analytic:plane", "--set", "directions=abc")
    assert res.returncode == 2 and "Traceback" not in res.stderr


def test_run_on_an_all_nan_ao_pass_says_so(capsys, tmp_path):
    """A G-buffer whose AO pass is all NaN is computed, and the output says why it is not
    scored (not that the input has no AO pass)."""
    import numpy as np
    g = aolab.analytic_scene("wall", 16, 9, radius=1.0)
    path = tmp_path / "nan.exr"
    aolab.save_gbuffer(path, g, reference=np.full((9, 16), np.nan, np.float32),
                       sidecar=g.sidecar)
    assert cli.main(["run", "hbao", str(path), "--out", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    assert "all NaN" in out and "no reference AO" not in out


@settings(max_examples=60, deadline=None)
@given(text=st.one_of(option_values, st.builds(lambda w, h: f"{w}x{h}", option_values,
                                               option_values)))
def test_resolution_text_is_in_range_or_named(text):
    """aolab reference --resolution (and batch.py's): a size Blender renders as asked, or a
    ValueError naming the option."""
    from aolab.util.arguments import MAX_RESOLUTION, MIN_RESOLUTION, parse_resolution
    try:
        w, h = parse_resolution(text)
    except ValueError as e:
        assert str(e).startswith("--resolution must be WxH"), e
        return
    assert MIN_RESOLUTION <= min(w, h) and max(w, h) <= MAX_RESOLUTION


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(names=st.lists(option_values, min_size=1, max_size=3))
def test_presets_and_methods_commands_never_trace_back(capsys, names):
    _check(["presets", *names], capsys)
    _check(["presets", "--json", *names], capsys)
    _check(["methods", *names], capsys)   # takes no arguments: argparse refuses, status 2


@pytest.mark.parametrize("argv", [["compare", "--repeat=--"], ["tune", "--trials=--"],
                                  ["run", "hbao", "analytic:wall", "--radius=--"],
                                  ["limits", "--rays=--"]])
def test_double_dash_as_a_value_is_refused(capsys, argv):
    """Python 3.11's argparse stores `--OPT=--` as an empty list without checking it."""
    assert status_of(argv) == 2
    assert "expected one value, got '--'" in capsys.readouterr().err


# --- every option that names a file or folder is checked before any work ----------------------

PATH_CASES = [
    # (command line, the one error line); {file} is a regular file, {dir} a folder, {md} a
    # Markdown file without the generated block. Blender is "missing" and no scene exists:
    # an error about either would mean the path was not checked first.
    (["run", "hbao", "analytic:plane", *TINY, "--json", "{dir}/new/"],
     "--json must name a file, got '{dir}/new/'"),
    (["rtao", "analytic:plane", *TINY, "--json", "{dir}"],
     "--json must be a file, got '{dir}', which is a folder"),
    (["reference", "no_scene", "--cache", "{file}"],
     "--cache must be a folder, got '{file}', which is a regular file"),
    (["mesh", "no_scene", "--cache", "{file}"],
     "--cache must be a folder, got '{file}', which is a regular file"),
    (["reference", "no_scene", "--out", "{file}/sub"],
     "--out '{file}/sub' cannot be made: {file} is a file, not a folder"),
    (["radius-study", "--out", "{file}"],
     "--out must be a folder, got '{file}', which is a regular file"),
    (["bridge-check", "no_scene", "--cache", "{file}"],
     "--cache must be a folder, got '{file}', which is a regular file"),
    (["bridge-check", "no_scene", "--update-doc", "{dir}"],
     "--update-doc must be a regular file, got '{dir}', which is a folder"),
    (["rtao-check", "no_scene", "--out", "{file}"],
     "--out must be a folder, got '{file}', which is a regular file"),
    (["rtao-check", "no_scene", "--update-doc", "{md}"],
     "{md} has no '<!-- BEGIN GENERATED by aolab rtao-check"),
    (["limits", "--scenes-dir", "{file}"],
     "--scenes-dir must be an existing folder, got '{file}', which is not a folder"),
]


@pytest.mark.parametrize("argv, said", PATH_CASES, ids=[" ".join(a[:1] + a[-2:-1])
                                                        for a, _ in PATH_CASES])
def test_paths_are_checked_before_any_work(capsys, tmp_path, monkeypatch, argv, said):
    """--cache FILE said "File exists: FILE" once the first render was stored, and --out,
    --json or --update-doc that could not be written failed after all the work."""
    monkeypatch.setenv("AOLAB_BLENDER", str(tmp_path / "no_blender"))
    (tmp_path / "file").write_text("x")
    (tmp_path / "dir").mkdir()
    (tmp_path / "doc.md").write_text("no generated block\n")
    where = {"file": tmp_path / "file", "dir": tmp_path / "dir", "md": tmp_path / "doc.md"}
    assert status_of([a.format(**where) for a in argv]) == 2
    err = capsys.readouterr().err
    assert_one_error_line(err)
    assert err.startswith("aolab: " + said.format(**where)), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir", "doc.md", "file"]
    assert (tmp_path / "file").read_text() == "x" and not list((tmp_path / "dir").iterdir())


@pytest.mark.parametrize("argv", [["methods", "\n0"],
                                  ["run", "hbao", "analytic:plane", "a\r\nb"]])
def test_an_unrecognized_argument_with_a_newline_stays_on_one_line(capsys, argv):
    """argparse echoed unrecognized arguments as typed, so the message took two lines
    (hypothesis found "\\n0")."""
    assert status_of(argv) == 2
    last = terminal_lines(capsys.readouterr().err)[-1]
    assert last.startswith("aolab") and "error: unrecognized arguments: " in last, last
    assert "\\n" in last
