"""The scores of a small `aolab compare` study, bit for bit, against a stored digest.

A refactoring of the study (its runner, scorer, blur, regions, aggregation) must not move a
single score. The study is test_compare's: room and grille cropped to 160x90, room with
synthetic peers and limits and its mesh (so rtao runs). Every column of results.csv is kept
but the times (``*_ms*`` columns, and the BVH build time in an rtao row's settings and note):
a digest per row, so that a failure names the rows whose scores moved; and the report's
plotted values, bars and check verdicts (not its times) as one more digest. Regenerate the
stored digests only for a change that is meant to move scores, and say so in CHANGES.md:

    AOLAB_WRITE_DIGEST=1 pytest tests/python/study/test_score_digest.py
"""
from __future__ import annotations

import hashlib
import json
import os
import re

from aolab import cli
from compare_support import CROP, ROOT, make_scenes, parse_report, read_csv

DIGESTS = ROOT / "tests" / "data" / "compare_score_digests.json"
TIME_IN_NOTE = re.compile(r"\d+(\.\d+)? ms")


def score_columns(row: dict) -> dict:
    """``row`` without its times: what a change of the code that is not meant to move scores
    must leave bit for bit."""
    kept = {k: v for k, v in row.items() if "_ms" not in k}
    kept["note"] = TIME_IN_NOTE.sub("<time> ms", kept.get("note") or "")
    settings = json.loads(kept.get("settings") or "{}")
    kept["settings"] = {k: v for k, v in settings.items() if not k.endswith("_ms")}
    return kept


def row_digests(rows: list[dict]) -> dict[str, str]:
    return {r["key"]: hashlib.sha256(json.dumps(score_columns(r), sort_keys=True).encode())
            .hexdigest()[:20] for r in rows}


def report_digest(page) -> str:
    """The report's content that is not a time: every plotted point's key, metric and value
    (its x is a time), every horizontal line, bar and check verdict."""
    points = sorted((p["data-key"], p["data-metric"], str(p["data-y"])) for p in page.points)
    hlines = sorted((h["data-key"], h["data-metric"], str(h["data-y"])) for h in page.hlines)
    bars = sorted(json.dumps(b, sort_keys=True) for b in page.bars)
    checks = sorted(json.dumps(c, sort_keys=True) for c in page.checks)
    text = json.dumps([points, hlines, bars, checks])
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def test_compare_writes_the_stored_scores_bit_for_bit(tmp_path):
    scenes = make_scenes(tmp_path)
    out = tmp_path / "out"
    assert cli.main(["compare", "--scenes-dir", str(scenes), "--out", str(out), "--crop", CROP,
                     "--repeat", "2", "--warmup", "0", "--threads", "2", "--no-progress"]) == 0
    rows = read_csv(out / "results.csv")
    got = row_digests(rows)
    got["report.html"] = report_digest(parse_report(out / "report.html"))
    assert len(got) == len(rows) + 1, "a key names two rows"
    if os.environ.get("AOLAB_WRITE_DIGEST"):
        DIGESTS.write_text(json.dumps(got, indent=1, sort_keys=True) + "\n")
    want = json.loads(DIGESTS.read_text())
    assert sorted(got) == sorted(want), (sorted(set(got) ^ set(want)))
    moved = sorted(k for k in want if got[k] != want[k])
    assert not moved, f"{len(moved)} rows' scores moved: {moved[:10]}"
