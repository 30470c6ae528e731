"""Temporal accumulation in the comparison study (docs/comparison.md, "Temporal
accumulation"): on sequences with motion vectors every configuration runs at frame=k and is
accumulated too. Synthetic sequences cut from room's reference (compare_support.make_sequence
with motion: a window panned 4 px a frame, and one at rest), a still beside them, and the
committed flythrough cropped small."""
from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import aolab
from aolab import cli, scenes
from aolab.cli.options import crop_of
from aolab.scoring import digest
from aolab.study import findings, results_doc, runner, temporal
from browser import Browser, chromium, poll
from compare_support import SCENES, link_scene, make_sequence, parse_report, read_csv

SUFFIX = findings.ACCUMULATED_SUFFIX
PAN_FRAMES = {"start": 1, "end": 6, "step": 1}
PAN_SHIFT = 4
REST_FRAMES = {"start": 1, "end": 12, "step": 1}


def run(scenes_dir: Path, out: Path, *args) -> int:
    return cli.main(["compare", *args, "--scenes-dir", str(scenes_dir), "--out", str(out),
                     "--repeat", "1", "--warmup", "0", "--threads", "2", "--no-progress"])


def load(out: Path) -> dict:
    return {"out": out, "rows": read_csv(out / "results.csv"),
            "json": json.loads((out / "results.json").read_text()),
            "html": (out / "report.html").read_text(encoding="utf-8")}


@pytest.fixture(scope="module")
def pan(tmp_path_factory):
    """A 6-frame pan with motion vectors and room (a still) cropped to 160x90, hbao and lsao."""
    tmp = tmp_path_factory.mktemp("accumulation")
    where = tmp / "scenes"
    folder = make_sequence(where, "mpan", motion=True, frames=PAN_FRAMES, shift=PAN_SHIFT)
    link_scene(SCENES / "room", where / "room")
    assert run(where, tmp / "out", "mpan", "room", "--crop", "160x90",
               "--methods", "hbao", "lsao") == 0
    return {**load(tmp / "out"), "folder": folder}


@pytest.fixture(scope="module")
def rest(tmp_path_factory):
    """12 frames of one window (motion 0 everywhere), Alchemy AO."""
    tmp = tmp_path_factory.mktemp("rest")
    make_sequence(tmp / "scenes", "rest", motion=True, frames=REST_FRAMES, shift=0)
    assert run(tmp / "scenes", tmp / "out", "rest", "--methods", "alchemy") == 0
    return load(tmp / "out")


def frame_numbers(spec: dict) -> list[int]:
    return list(range(spec["start"], spec["end"] + 1, spec["step"]))


def method_rows(rows: list[dict], scene: str) -> list[dict]:
    return [r for r in rows if r["scene"] == scene and r["kind"] == "method"]


def test_every_configuration_has_an_accumulated_row_on_every_frame(pan):
    rows = pan["rows"]
    frames = frame_numbers(PAN_FRAMES)
    singles = {r["label"] for r in method_rows(rows, "mpan") if r["accumulated"] == "False"}
    assert singles and {r["label"] for r in method_rows(rows, "mpan")} == \
        singles | {label + SUFFIX for label in singles}
    for index, frame in enumerate(frames):
        mine = method_rows(rows, scenes.frame_scene_name("mpan", frame))
        labels = {(r["method"], r["label"]) for r in mine}
        for r in mine:
            assert int(r["frame_index"]) == index
            base = r["label"][:-len(SUFFIX)] if r["label"].endswith(SUFFIX) else r["label"]
            assert (r["method"], base) in labels and (r["method"], base + SUFFIX) in labels
            assert r["accumulated"] == str(r["label"].endswith(SUFFIX))
            total = float(r["method_ms"]) + float(r["blur_ms"] or 0)
            if r["accumulated"] == "True":    # the step's time, added
                total += float(r["accumulate_ms"])
                assert float(r["accumulate_ms"]) > 0
            else:
                assert r["accumulate_ms"] == ""
            assert float(r["total_ms"]) == pytest.approx(total)
            assert r["all_mae"] and r["disoccluded_count"]
        # one step time per frame, the same for every configuration
        assert len({r["accumulate_ms"] for r in mine if r["accumulated"] == "True"}) == 1
    # the sequence's rows: both kinds, with the converged and disoccluded errors
    for r in method_rows(rows, "mpan"):
        assert r["converged_mae"] and r["disoccluded_mae"] and r["flicker"]


def test_frames_run_at_their_index_and_accumulate_as_the_step_does(pan):
    """hbao at its defaults recomputed: compute(frame=k) and aolab.accumulate over the frames
    give each frame row's MAE, and the disoccluded region is the scored pixels whose history
    holds fewer than 4 frames; for this integer pan that is exactly the step's masks of this
    frame and the two before, carried along by the pan: the 3 x 4 entering columns."""
    by_key = {r["key"]: r for r in pan["rows"]}
    info = pan["json"]["scenes"]["mpan"]["accumulation"]
    assert info["disoccluded_below"] == temporal.DISOCCLUDED_BELOW == 4
    assert info["at_rest"] is False and info["largest_motion_px"] == PAN_SHIFT
    history = aolab.TemporalHistory()
    masks, pooled = [], []
    for index, frame in enumerate(frame_numbers(PAN_FRAMES)):
        g = aolab.load_gbuffer(scenes.frame_folder(pan["folder"], frame) / "reference.exr")
        ref = np.asarray(g.reference, np.float64)
        scored = g.valid_mask() & np.isfinite(ref)
        ao = aolab.compute("hbao", g, radius=0.5, frame=index)
        acc, mask = aolab.accumulate(ao, g, g.motion, history)
        masks.append(mask)
        name = scenes.frame_scene_name("mpan", frame)
        single, accumulated = by_key[f"{name}/hbao/default"], by_key[f"{name}/hbao/default{SUFFIX}"]
        for row, image in ((single, ao), (accumulated, acc)):
            assert float(row["all_mae"]) == pytest.approx(
                np.mean(np.abs(image[scored] - ref[scored])), rel=1e-9)
        region = scored & (history.length < 4)
        # the step's masks: this frame's, and those of the one and two before shifted by the
        # pan (a pixel's history is the pixel PAN_SHIFT to its right the frame before)
        expected = masks[-1].copy()
        for back in (1, 2):
            if index - back >= 0:
                shifted = np.zeros_like(mask)
                shifted[:, :-back * PAN_SHIFT] = masks[-1 - back][:, back * PAN_SHIFT:]
                expected |= shifted
        if index <= 2:   # frame 0 is all disoccluded: no pixel has 4 frames yet
            expected |= g.valid_mask()
        assert np.array_equal(region, scored & expected), index
        if index >= 3:
            columns = np.zeros_like(region)
            columns[:, -3 * PAN_SHIFT:] = True
            assert np.array_equal(region, scored & columns)
            pooled.append((np.abs(acc[region] - ref[region]).sum(), region.sum()))
        for row, image in ((single, ao), (accumulated, acc)):
            assert int(row["disoccluded_count"]) == region.sum()
            assert float(row["disoccluded_mae"]) == pytest.approx(
                np.mean(np.abs(image[region] - ref[region])), rel=1e-9)
        assert info["region_pixels"][str(frame)] == region.sum()
    seq = by_key[f"mpan/hbao/default{SUFFIX}"]
    assert float(seq["disoccluded_mae"]) == pytest.approx(
        sum(s for s, _ in pooled) / sum(n for _, n in pooled), rel=1e-9)
    # 6 frames: none of index 8, so the converged error is the last frame's
    assert info["converged_frames"] == [PAN_FRAMES["end"]] and info["converged_history"] == [6]
    last = scenes.frame_scene_name("mpan", PAN_FRAMES["end"])
    assert float(seq["converged_mae"]) == float(by_key[f"{last}/hbao/default{SUFFIX}"]["all_mae"])


def test_the_converged_frames_follow_the_rule():
    assert temporal.converged_frames(list(range(24)), at_rest=False) == list(range(8, 24))
    assert temporal.converged_frames(list(range(24)), at_rest=True) == [23]
    assert temporal.converged_frames(list(range(8)), at_rest=False) == [7]
    assert temporal.converged_frames(list(range(9)), at_rest=False) == [8]


def test_at_rest_the_accumulated_error_falls_and_ends_below_one_frame(rest):
    rows = {r["key"]: r for r in rest["rows"]}
    frames = frame_numbers(REST_FRAMES)
    info = rest["json"]["scenes"]["rest"]["accumulation"]
    assert info["at_rest"] is True and info["converged_frames"] == [frames[-1]]
    names = [scenes.frame_scene_name("rest", f) for f in frames]
    acc = [float(rows[f"{n}/alchemy/default{SUFFIX}"]["all_mae"]) for n in names]
    one = [float(rows[f"{n}/alchemy/default"]["all_mae"]) for n in names]
    assert acc[0] == one[0]    # frame 0: the history is empty, the step returns the frame
    assert all(b <= a + 1e-6 for a, b in zip(acc, acc[1:])), acc
    assert acc[-1] < 0.85 * min(one), (acc, one)
    seq = rows[f"rest/alchemy/default{SUFFIX}"]
    assert float(seq["converged_mae"]) == acc[-1]
    # the frames differ only in their seeds: nothing is disoccluded after the first frames
    assert all(int(rows[f"{n}/alchemy/default"]["disoccluded_count"]) == 0 for n in names[3:])
    assert seq["disoccluded_mae"] == ""


def brute_force_pairs(entries: list[dict]) -> dict:
    """accumulation_pairs' rule by enumeration: every (X, Y) of a method with Y dearer in one
    frame than X accumulated, X accumulated below Y in one frame and X in one frame not below
    Y; the cheapest X (then its error, label), the most accurate Y (then the dearer, label)."""
    out = {}
    for m in {e["method"] for e in entries}:
        valid = [(x, y) for x in entries for y in entries
                 if x["method"] == y["method"] == m
                 and None not in (x["acc_ms"], x["acc_converged"], x["single_converged"],
                                  y["single_ms"], y["single_converged"])
                 and y["single_ms"] > x["acc_ms"] and x["acc_converged"] < y["single_converged"]
                 and x["single_converged"] >= y["single_converged"]]
        if not valid:
            out[m] = (None, None)
            continue
        x = min((x for x, _ in valid), key=lambda e: (e["acc_ms"], e["acc_converged"],
                                                      e["label"]))
        y = min((y for xx, y in valid if xx is x),
                key=lambda e: (e["single_converged"], -e["single_ms"], e["label"]))
        out[m] = (x["label"], y["label"])
    return out


def entry(method, label, single_ms, acc_ms, single, acc):
    return {"method": method, "label": label, "single_ms": single_ms, "acc_ms": acc_ms,
            "single_converged": single, "acc_converged": acc, "single_key": label,
            "acc_key": label + SUFFIX, "step_ms": acc_ms - single_ms}


def test_the_pairing_picks_by_the_stated_rule(pan, rest):
    hand = [entry("m", "low", 1.0, 2.0, 0.30, 0.20),      # beats medium and high
            entry("m", "cheap", 0.5, 1.5, 0.10, 0.09),    # beats them in one frame already
            entry("m", "medium", 3.0, 4.0, 0.25, 0.15),
            entry("m", "high", 6.0, 7.0, 0.22, 0.12),
            entry("m", "slow", 1.9, 2.9, 0.40, 0.35),     # no dearer one it beats
            entry("n", "only", 1.0, 2.0, 0.30, 0.20)]     # nothing dearer
    pairs = {p["method"]: p for p in findings.accumulation_pairs(hand)}
    assert (pairs["m"]["x"]["label"], pairs["m"]["y"]["label"]) == ("low", "high")
    assert pairs["n"]["x"] is None and pairs["n"]["y"] is None
    rng = np.random.default_rng(5)
    for trial in range(200):
        entries = [entry("m", f"c{i}", *(lambda s, a: (s, s + a))(
            float(rng.integers(1, 8)), float(rng.integers(0, 3))),
            float(rng.integers(1, 9)) / 10, float(rng.integers(1, 9)) / 10)
            for i in range(int(rng.integers(1, 7)))]
        got = {p["method"]: (p["x"] and p["x"]["label"], p["y"] and p["y"]["label"])
               for p in findings.accumulation_pairs(entries)}
        assert got == brute_force_pairs(entries), (trial, entries)
    for study, name in ((pan, "mpan"), (rest, "rest")):
        entries = findings.accumulation_entries(study["json"]["rows"], name)
        assert len(entries) == len([r for r in method_rows(study["rows"], name)
                                    if r["accumulated"] == "False"])
        got = {p["method"]: (p["x"] and p["x"]["label"], p["y"] and p["y"]["label"])
               for p in findings.accumulation_pairs(entries)}
        assert got == brute_force_pairs(entries)
        # the report's table shows each pair by its rows' keys
        table = study["html"][study["html"].index('class="check pairs"'):]
        table = table[:table.index("</table>")]
        for p in findings.accumulation_pairs(entries):
            if p["x"] is not None:
                assert (f'data-x="{p["x"]["acc_key"]}" data-y="{p["y"]["single_key"]}"'
                        in table)


def test_stills_and_sequences_without_motion_are_unchanged(pan, tmp_path):
    """A still's rows carry none of the temporal fields and score compute() without a frame;
    a sequence without motion vectors is run as before (test_sequences.py checks its rows
    against compute() without a frame)."""
    new = {"frame_index", "accumulated", "accumulate_ms", "disoccluded_mae",
           "disoccluded_count", "converged_mae"}
    room = [r for r in pan["json"]["rows"] if r["scene"] in ("room", "ALL")]
    assert room and not any(new & set(r) for r in room)
    assert not any(r["label"].endswith(SUFFIX) for r in room)
    scene = scenes.load_scene(SCENES / "room", crop_of("160x90"))
    by_key = {r["key"]: r for r in room}
    ao = aolab.compute("hbao", scene.g, radius=scene.radius)
    assert by_key["room/hbao/default"]["metrics"] == runner.score(ao, scene)["regions"]
    make_sequence(tmp_path / "scenes", "still_pan")     # no motion vectors
    assert run(tmp_path / "scenes", tmp_path / "out", "--methods", "lsao") == 0
    rows = json.loads((tmp_path / "out" / "results.json").read_text())["rows"]
    assert rows and not any(new & set(r) for r in rows)
    assert "accumulation" not in json.loads(
        (tmp_path / "out" / "results.json").read_text())["scenes"]["still_pan"]


def test_a_worker_scores_the_frame_the_study_times(pan):
    """The cluster's runner.score_remotely runs the frame's seed too: the same bits as here."""
    folder = scenes.frame_folder(pan["folder"], 3)
    got = runner.score_remotely(str(folder), None, "mpan@0003", "hbao", {}, [False], frame=2)
    g = aolab.load_gbuffer(folder / "reference.exr")
    assert got[False]["digest"] == digest(aolab.compute("hbao", g, radius=0.5, frame=2))
    assert got[False]["digest"] != digest(aolab.compute("hbao", g, radius=0.5))


def test_the_report_plots_the_error_against_the_frame_one_frame_and_accumulated(pan):
    report = parse_report(pan["out"] / "report.html")
    fig = report.figures["plot-mpan-frames"]
    series = [t for t in fig["data"] if t["meta"]["role"] == "series"]
    methods = sorted({r["method"] for r in method_rows(pan["rows"], "mpan")})
    assert [t["name"] for t in series] == [n for m in methods for n in (m, m + SUFFIX)]
    rows = {r["key"]: r for r in pan["rows"]}
    for t in series:
        accumulated = t["name"].endswith(SUFFIX)
        assert t["meta"]["accumulated"] is accumulated
        assert t["line"]["dash"] == ("solid" if accumulated else "4px,3px")
        assert t["x"] == frame_numbers(PAN_FRAMES)
        for key, x, y in zip(t["customdata"], t["x"], t["y"]):
            r = rows[key]
            assert r["label"] == findings.FRAMES_PRESET + (SUFFIX if accumulated else "")
            assert int(r["frame"]) == x and float(r["all_mae"]) == y
    assert 'id="accumulation-mpan"' in pan["html"] and "Converged error" in pan["html"]


def test_without_plotly_js_the_frames_plot_is_static(pan, tmp_path, monkeypatch):
    from aolab.study import report, report_files
    results = json.loads((pan["out"] / "results.json").read_text())
    monkeypatch.setattr(report_files, "plotly_js", lambda: None)
    report.write_report(tmp_path / "report.html", results, {})
    html = (tmp_path / "report.html").read_text(encoding="utf-8")
    svg = html[html.index('id="plot-mpan-frames"'):]
    svg = svg[:svg.index("</svg>")]
    assert svg.count("<polyline") == 4 and svg.count('stroke-dasharray="4 3"') == 4  # + legend
    assert len(re.findall(r'class="point"', svg)) == 4 * len(frame_numbers(PAN_FRAMES))


def test_the_frames_plot_in_chromium(pan):
    if chromium() is None:
        pytest.skip("Chromium is not installed (scripts/install-deps.sh installs it)")
    with Browser() as b:
        b.open(pan["out"] / "report.html")
        assert poll(b, "document.title.startsWith('AO Lab report: ok')"), b.evaluate(
            "document.title")
        traces = b.evaluate("""document.getElementById('plot-mpan-frames')._fullData.map(
            t => ({name: t.name, dash: t.line.dash, n: t.x.length}))""")
        assert b.errors == [], b.errors
    assert [t["name"] for t in traces] == ["hbao", "hbao" + SUFFIX, "lsao", "lsao" + SUFFIX]
    assert [t["dash"] for t in traces] == ["4px,3px", "solid"] * 2
    assert all(t["n"] == len(frame_numbers(PAN_FRAMES)) for t in traces)


def test_results_md_has_an_accumulation_section_only_with_accumulated_rows(pan, tmp_path):
    text = "\n".join(results_doc.pages(pan["json"]).values())
    part = text[text.index("## Temporal accumulation"):]
    assert "### mpan" in part and "results_accumulation_mpan.svg" in part
    entries = findings.accumulation_entries(pan["json"]["rows"], "mpan")
    for e in entries:
        assert f'| {e["method"]} | {e["label"]} | {e["single_ms"]:.1f} |' in part
    for p in findings.accumulation_pairs(entries):
        if p["x"] is not None:
            assert f'| {p["method"]} | {p["x"]["label"]}{SUFFIX} |' in part
        else:
            assert f'| {p["method"]} | — |' in part
    still = {**pan["json"], "rows": [r for r in pan["json"]["rows"]
                                     if not r.get("accumulated")]}
    assert "## Temporal accumulation" not in "\n".join(results_doc.pages(still).values())
    # the generator writes the plot beside results.md
    (tmp_path / "results.json").write_text(json.dumps(pan["json"]))
    results_doc.write(tmp_path / "results.json", tmp_path / "docs")
    svg = (tmp_path / "docs" / "images" / "results_accumulation_mpan.svg").read_text()
    assert svg.startswith("<svg") and svg.count('class="point"') == 4 * len(
        frame_numbers(PAN_FRAMES))
    assert "## Temporal accumulation" in \
        (tmp_path / "docs" / results_doc.SEQUENCES_PAGE).read_text()
    assert "## Temporal accumulation" not in (tmp_path / "docs" / "results.md").read_text()


def test_flythrough_cropped_accumulates_every_configuration(tmp_path):
    """The committed flythrough (motion vectors in every frame, EEVEE's peer per frame),
    cropped to 64x36."""
    where = SCENES
    if not (where / "flythrough" / "frames").exists():
        pytest.skip("the flythrough is not rendered")
    assert run(where, tmp_path / "out", "flythrough", "--crop", "64x36",
               "--methods", "gtao") == 0
    data = json.loads((tmp_path / "out" / "results.json").read_text())
    frames = scenes.frame_numbers(where / "flythrough")
    info = data["scenes"]["flythrough"]["accumulation"]
    assert info["at_rest"] is False and info["converged_frames"] == [frames[-1]]
    labels = {r["label"] for r in data["rows"] if r["scene"] == "flythrough"
              and r["kind"] == "method" and r.get("accumulated") is False}
    for index, frame in enumerate(frames):
        mine = {(r["label"], r["accumulated"], r["frame_index"]) for r in data["rows"]
                if r["scene"] == scenes.frame_scene_name("flythrough", frame)
                and r["kind"] == "method"}
        assert mine == {(label, False, index) for label in labels} | \
            {(label + SUFFIX, True, index) for label in labels}
    assert all(math.isfinite(r["metrics"]["all"]["mae"]) for r in data["rows"]
               if r.get("accumulated"))
    # EEVEE's peer of each frame (frames/NNNN/peers/): a row per frame, and over the sequence
    # its converged error (the configurations' frames), flicker and the accumulation tables
    eevee = [r for r in data["rows"] if r["kind"] == "eevee"]
    names = [scenes.frame_scene_name("flythrough", f) for f in frames]
    assert {r["scene"] for r in eevee} == set(names) | {"flythrough"}
    (mean,) = [r for r in eevee if r["scene"] == "flythrough"]
    last = next(r for r in eevee if r["scene"] == names[-1])
    assert mean["converged_mae"] == last["metrics"]["all"]["mae"]
    assert mean["flicker"] > 0 and mean["disoccluded_mae"] is not None
    (peer,) = findings.peer_sequence_entries(data["rows"], "flythrough")
    assert peer["converged"] == mean["converged_mae"]
    text = "\n".join(results_doc.pages(data).values())
    assert (f'| {mean["label"]} | {mean["total_ms"]:.0f} | {mean["converged_mae"]:.4f} |'
            in text[text.index("## Temporal accumulation"):])
    html_ = (tmp_path / "out" / "report.html").read_text(encoding="utf-8")
    assert '<table class="check peers"><tr><th>peer</th>' in html_


def test_long_sequences_say_their_frames_briefly():
    """results.md's tables of MAE per frame keep to MAX_FRAME_COLUMNS evenly spaced frames,
    first and last included; a run of frames is said as a range; rtao's "not run" names a
    sequence once, not each of its frames."""
    frames = list(range(1, 25))
    shown = results_doc.shown_frames(frames)
    assert len(shown) == results_doc.MAX_FRAME_COLUMNS
    assert shown[0] == 1 and shown[-1] == 24 and shown == sorted(set(shown))
    assert results_doc.shown_frames(frames[:8]) == frames[:8]
    assert results_doc.frames_text(frames) == "Frames 1–24"
    assert results_doc.frames_text([1, 3, 5]) == "Frames 1, 3, 5"
    why = "no reference.mesh"
    names = [scenes.frame_scene_name("seq", f) for f in (1, 2, 3)]
    results = {"scenes": {"room": {"rtao_not_run": why},
                          **{n: {"rtao_not_run": why} for n in names},
                          "seq": {"sequence": True, "frame_scenes": names}}}
    assert findings.rtao_not_run(results) == f"room, seq (its 3 frames): {why}"
