"""A user's strings where they land (docs/conventions.md, "Files"): one encoder per place. JSON
inside report.html (report.json_for_html: "<", ">", "&", U+2028 and U+2029 as \\u escapes), HTML
text and attributes (html.escape), Markdown (util.markdown.text: one line, "|" and the rest
escaped) and file names (files.file_name_for: bounded, safe, one per name, checked before the
study starts). A study of scenes with a hostile and a 250-character name runs to its end and
its report draws every plot in headless Chromium, running nothing the names hold."""
from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aolab import cli
from aolab.study import report, report_files, results_doc
from aolab.util import files, markdown
from browser import Browser, poll
from compare_support import SCENES
from browser import need_chromium

#: A scene folder's name that is HTML, a comment opener, a table's cell separator and a line
#: break: each would break a page that put it in unescaped.
HOSTILE = "a|b\n<!--<script>c<img src=x onerror=window.pwned=1>"
#: A scene folder's name of 250 characters (ext4 takes 255 bytes).
LONG = ("a_long_scene_name-" * 14)[:250]
SMALL = "thin_balustrade"


def test_json_for_html_holds_nothing_html_acts_on():
    value = {"scene": "</script><!--<script>&amp;\u2028\u2029", "n": [1, 2.5, None]}
    text = report.json_for_html(value)
    assert not set(text) & set("<>&\u2028\u2029")
    assert json.loads(text) == value


@settings(max_examples=300, deadline=None)
@given(st.text())
def test_json_for_html_round_trips_any_string(s):
    text = report.json_for_html([s])
    assert not set(text) & set("<>&\u2028\u2029") and json.loads(text) == [s]


def test_a_safe_short_name_is_its_own_file_name():
    for name in ("room", "thin_balustrade", "tuned-100ms", "a.b"):
        assert files.file_name_for(name) == name


@pytest.mark.parametrize("name", [HOSTILE, LONG, "..", ".", ".hidden", "-rf", "a/b", "",
                                  "x\x00y", "é" * 200, "pan@0001", "\udcff"])
def test_a_file_name_from_a_users_name_is_bounded_and_safe(name):
    made = files.file_name_for(name)
    assert re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.-]*", made), made
    assert len(made) <= files.MAX_NAME_CHARS
    assert made.endswith(files.file_name_for(name)[-files.NAME_HASH_CHARS:])


@settings(max_examples=300, deadline=None)
@given(st.text(), st.text())
def test_two_names_never_share_a_file_name(a, b):
    if a != b:
        assert files.file_name_for(a) != files.file_name_for(b)


def test_markdown_text_is_one_line_and_shows_as_written():
    assert markdown.text(HOSTILE) == \
        "a\\|b \\<!--\\<script\\>c\\<img src=x onerror=window.pwned=1\\>"
    assert markdown.text("a\r\n\u2028b*[c]`d\\") == "a b\\*\\[c\\]\\`d\\\\"


def hostile_scenes(tmp_path: Path) -> Path:
    """Two copies of the smallest committed scene, named HOSTILE and LONG."""
    scenes = tmp_path / "scenes"
    for name in (HOSTILE, LONG):
        folder = scenes / name
        folder.mkdir(parents=True)
        for f in ("reference.exr", "reference.json", "manifest.json"):
            shutil.copyfile(SCENES / SMALL / f, folder / f)
    return scenes


def study(tmp_path: Path, out: Path) -> int:
    return cli.main(["compare", "--scenes-dir", str(hostile_scenes(tmp_path)), HOSTILE, LONG,
                     "--out", str(out), "--methods", "crytek_ssao", "hbao", "--crop", "64x36",
                     "--repeat", "1", "--warmup", "0", "--rtao-rays", "none",
                     "--no-progress"])


@pytest.fixture(scope="module")
def hostile_report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("hostile")
    out = tmp / "out"
    assert study(tmp, out) == 0
    return out


def test_hostile_and_long_scene_names_make_a_complete_study(hostile_report):
    """Was: a 250-character name ended the finished study in "File name too long", no
    report written."""
    results = json.loads((hostile_report / "results.json").read_text())
    assert results["meta"]["scenes"] == [HOSTILE, LONG] and not results["meta"]["partial"]
    names = [p.name for p in hostile_report.rglob("*")]
    assert len(names) > 10
    for name in names:
        assert re.fullmatch(r"[A-Za-z0-9_.-]+", name) and len(name) <= 100, name
    page = (hostile_report / "report.html").read_text(encoding="utf-8")
    assert "<!--<script>" not in page and "<img src=x" not in page
    assert "\\u003c!--\\u003cscript\\u003ec" in page           # in the JSON, escaped
    assert "&lt;!--&lt;script&gt;c&lt;img src=x" in page          # in the HTML, escaped


def test_the_hostile_report_draws_every_plot_and_runs_nothing_the_names_hold(hostile_report):
    """Was: `<!--<script>` left inside the page's JSON: headless Chromium drew 0 of 6 plots."""
    need_chromium()
    with Browser() as b:
        b.open(hostile_report / "report.html")
        assert poll(b, "document.title.startsWith('AO Lab report: ok')"), b.evaluate(
            "document.title")
        title = b.evaluate("document.title")
        assert re.search(r"\b9 plots\b", title), title    # all scenes, then each: 3 plots
        drawn = b.evaluate("""Array.from(document.querySelectorAll('div.plot')).map(gd =>
            (gd._fullData || []).reduce((n, t) => n + (t.meta && t.meta.role === 'series'
                                                        ? t.x.length : 0), 0))""")
        assert len(drawn) == 9 and all(n > 0 for n in drawn), drawn
        sections = b.evaluate("Array.from(document.querySelectorAll('div.plot'))"
                              ".map(gd => gd.dataset.section)")
        assert sections.count(HOSTILE) == 3 and sections.count(LONG) == 3, sections
        assert b.evaluate("typeof window.pwned") == "undefined"
        assert b.evaluate("document.querySelectorAll('img[src=x]').length") == 0
        assert b.errors == [], b.errors


def test_the_results_page_keeps_each_table_row_one_row(hostile_report):
    results = json.loads((hostile_report / "results.json").read_text())
    text = "\n".join(results_doc.pages(results).values())
    assert HOSTILE not in text and "\n<!--<script>" not in text
    assert f"## {markdown.text(HOSTILE)}\n" in text
    cells, header = (lambda line: len(re.findall(r"(?<!\\)\|", line))), None
    for line in text.splitlines():    # every row of a table has its header's cells
        header = (header or cells(line)) if line.startswith("|") else None
        assert header is None or cells(line) == header, line
    assert results_doc.accumulation_image(LONG) == \
        f"results_accumulation_{files.file_name_for(LONG)}.svg"


def test_a_file_system_with_short_names_is_refused_before_the_study(tmp_path, monkeypatch,
                                                                    capsys):
    """The output's longest file name is checked against the file system before any work."""
    monkeypatch.setattr(files.os, "pathconf", lambda path, name: 40)
    out = tmp_path / "out"
    assert study(tmp_path, out) == 2
    err = capsys.readouterr().err.strip().split("\n")
    longest = Path(report_files.name_for("x" * files.MAX_NAME_CHARS, ".min.js", b"")).name
    assert err == [f"aolab: --out {str(out)!r}: its file system takes file names of at most 40 "
                   f"bytes, and the output needs {longest!r}"]
    assert not out.exists() and not (tmp_path / "out.partial").exists()


def test_a_reference_names_its_cache_entry_and_out_folder_from_a_bounded_name(tmp_path):
    """A scene's name (a manifest's "name", a .blend's stem) made a path: was a name with
    "/" or ".." left the cache and --out; one of 250 characters, too long a file name."""
    from aolab.cycles.plan import BlenderScene, make_plan
    from aolab.cycles.run import output_folder
    for name in ("../../outside", LONG, HOSTILE):
        spec = BlenderScene(name, "script", tmp_path / "build.py", {}, "0" * 64)
        plan = make_plan(spec, passes=["depth", "normal"])
        assert plan.key_prefix() == f"{files.file_name_for(name)}-"
        assert output_folder(tmp_path / "out", plan, True) == \
            tmp_path / "out" / files.file_name_for(name)
