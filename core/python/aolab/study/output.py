"""The output folder of ``aolab compare``: where its files are staged while it runs
(``<out>.partial``), how they are checked before any work, and how a complete study's files
are published into the folder, each with an atomic rename, so that an interrupted run leaves
an earlier complete one untouched (docs/conventions.md, "Output folders").
"""

from __future__ import annotations

import os
from pathlib import Path

from . import report_files

#: The files a study writes, in the order publish() moves them (results.json, which says
#: whether the study is complete, last).
OUTPUT_FILES = ("results.csv", "report.html", "results.json")
#: The suffix of the staging folder beside the output folder (staging_folder).
STAGING_SUFFIX = ".partial"


def staging_folder(out: Path) -> Path:
    """``<out>.partial``, beside the output folder: the study writes its files there while it
    runs (after every scene) and moves them into ``out`` only when it is complete, so an
    interrupted or failed run leaves the complete results of an earlier run in ``out``
    untouched and its own partial results in the staging folder."""
    out = Path(out)
    if out.name in ("", ".", ".."):    # name it by its absolute path
        out = Path(os.path.abspath(out))
    return out.with_name(out.name + STAGING_SUFFIX)


def check_out(out: Path) -> None:
    """A ValueError unless ``out`` and its staging folder can be folders: neither, nor any
    folder above them, is an existing file (or anything else that is not a folder)."""
    out = Path(out)
    if out.resolve() == Path(out.resolve().anchor):
        raise ValueError(f"--out must be a folder below the file-system root (the study "
                         f"stages its files beside it), got {str(out)!r}")
    for path, what in ((out, "the output folder"), (staging_folder(out), "its staging folder")):
        for p in [path, *path.parents]:
            if p.exists() and not p.is_dir():
                raise ValueError(f"--out must be a folder, got {str(out)!r}: {what} "
                                 f"{str(path)!r} cannot be made because {str(p)!r} is an "
                                 "existing file, not a folder")


def publish(out: Path) -> None:
    """Moves the complete study's files from the staging folder into the output folder
    ``out``, each with an atomic rename: first the report's images and scripts
    (report_files/, named by their content, beside the earlier report's), then results.csv,
    report.html and results.json (which says whether the study is complete) last; then
    removes the files of report_files/ that the new report.html does not name, and the
    staging folder. Interrupted anywhere, the output folder's report.html finds all its
    files. Other files in the output folder are left alone."""
    out, staging = Path(out), staging_folder(out)
    out.mkdir(parents=True, exist_ok=True)
    report_files.move_in(staging, out)
    for name in OUTPUT_FILES:
        if (staging / name).exists():   # (a publish that was interrupted moved some)
            os.replace(staging / name, out / name)
    report_files.prune(out / "report.html")
    try:
        staging.rmdir()
    except OSError:  # someone put something else there: leave it
        pass
