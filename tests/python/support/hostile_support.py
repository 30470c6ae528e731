"""What the tests of output folders share: small analytic scene folders, a quick
`aolab compare` over them and a snapshot of a folder's bytes."""
from __future__ import annotations

from pathlib import Path

import numpy as np

import aolab
from aolab import cli


FILES = ["report.html", "report_files", "results.csv", "results.json"]


def small_scenes(root: Path, names=("alpha", "beta")) -> Path:
    """Scene folders with a 64x36 analytic G-buffer as reference.exr, R 0.25."""
    for name in names:
        folder = root / name
        folder.mkdir(parents=True)
        g = aolab.analytic_scene("blocks", 64, 36, radius=0.25)
        ref = np.nan_to_num(np.asarray(g.reference, np.float32), nan=1.0)
        aolab.save_gbuffer(folder / "reference.exr", g, reference=ref,
                           sidecar={"ao_distance": 0.25})
    return root


def compare_cli(scenes: Path, out: Path, method: str = "lsao") -> int:
    """A quick `aolab compare` of ``method`` over ``scenes`` into ``out``: its exit status."""
    return cli.main(["compare", "--scenes-dir", str(scenes), "--out", str(out), "--methods",
                     method, "--repeat", "1", "--warmup", "0", "--threads", "2",
                     "--no-progress"])


def snapshot(folder: Path) -> dict:
    """Every file below ``folder`` (report_files/ too): relative path -> bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()}
