"""The folder beside report.html: its images and scripts (docs/comparison.md, "report.html").

Every file is named by its content (``report_files/<stem>-<first 16 hex digits of its
SHA-256><suffix>``), so a file of a given name never changes. That is what keeps the study's
interruption-safe output (compare.Study.publish) safe with a folder of files: the new files are
moved in first, beside the old ones (a name both reports use holds the same bytes), then
report.html replaces the old one in one rename, and only then are the files no report.html
names any more removed. At every instant the report.html in the folder finds all its files,
and a copy of the folder works anywhere (from a file:// URL too: nothing is fetched).

Images are WebP (lossy, quality IMAGE_QUALITY) through Pillow; plotly.js is the minified file
committed in core/web/vendor/ (the npm package core/web/package-lock.json pins, fetched by
scripts/update_plotly.sh), which the build copies into the package (vendor/): never
downloaded at build or run time.
"""

from __future__ import annotations

import hashlib
import io
import os
import re
from pathlib import Path

import numpy as np
from PIL import Image

from ..util import files

#: The folder beside report.html that holds its files.
FOLDER = "report_files"
#: WebP quality (0-100) of every image of the report: AO images, error maps, references. At
#: 75 the AO's per-pixel noise and the error map's colours survive, and the default study's
#: folder stays well under 20 MB (docs/comparison.md, "report.html": sizes).
IMAGE_QUALITY = 75
#: libwebp's effort (0-6): 2 encodes a 426x240 image in about 6 ms, 3x faster than 4 for 3 %
#: more bytes (the study encodes some 1200 images).
WEBP_METHOD = 2
#: plotly.js: the file the report loads (npm package plotly.js-basic-dist-min, core/web).
PLOTLY_FILE = "plotly-basic.min.js"
#: The report's own script, beside this module.
SCRIPT = Path(__file__).with_name("report.js")

_REFERENCE = re.compile(re.escape(FOLDER) + r"/[A-Za-z0-9_.-]+")


def plotly_js() -> Path | None:
    """plotly.js as installed: the built package's copy (vendor/, made by the build from
    core/web/vendor), else the checkout's core/web/vendor (a run from the source tree); None
    when neither exists."""
    here = Path(__file__).resolve()
    for path in (here.parent / "vendor" / PLOTLY_FILE,
                 here.parents[3] / "web" / "vendor" / PLOTLY_FILE):
        if path.is_file():
            return path
    return None


def name_for(stem: str, suffix: str, data: bytes) -> str:
    """The file's name in the report's folder, from its content: ``report_files/<stem>-<hash>
    <suffix>``, the stem made a file name by files.file_name_for (a scene's and a
    configuration's names are the user's: bounded, no ``/``, nothing hidden)."""
    return (f"{FOLDER}/{files.file_name_for(stem)}-{hashlib.sha256(data).hexdigest()[:16]}"
            f"{suffix}")


def check_names_fit(out: Path) -> None:
    """Before any work: the longest name the report gives a file (a stem of
    files.MAX_NAME_CHARS, its hash and suffix) fits in a file name of the file system where
    the output folder ``out`` will be, so that a study never ends in "File name too long"."""
    longest = Path(name_for("x" * files.MAX_NAME_CHARS, ".min.js", b"")).name
    files.check_name_fits(out, longest, "--out")


def webp_bytes(image: np.ndarray, quality: int = IMAGE_QUALITY) -> bytes:
    """A lossy WebP of a float image in [0, 1]: (H, W) grey or (H, W, 3) RGB."""
    a = np.clip(np.nan_to_num(image, nan=0.0), 0.0, 1.0)
    a = np.ascontiguousarray(np.round(a * 255).astype(np.uint8))
    buf = io.BytesIO()
    Image.fromarray(a).save(buf, "WEBP", quality=quality, method=WEBP_METHOD)   # L or RGB
    return buf.getvalue()


class Files:
    """The files one report.html names, collected while it is rendered: name (relative to
    the report's folder) -> bytes."""

    def __init__(self):
        self.items: dict[str, bytes] = {}
        self._names: dict[bytes, str] = {}   # content -> its name

    def add(self, stem: str, suffix: str, data: bytes) -> str:
        """Adds ``data`` and returns its name, ``report_files/<stem>-<hash><suffix>``
        (name_for). Content added before (two configurations with the same image) keeps its
        first name: one file."""
        if data not in self._names:
            name = name_for(stem, suffix, data)
            self.items[name] = data
            self._names[data] = name
        return self._names[data]

    def write(self, folder: Path) -> None:
        """Every file into ``folder``/report_files that is not there yet (a file of the same
        name holds the same bytes), each written durably and atomically."""
        if self.items:
            (Path(folder) / FOLDER).mkdir(parents=True, exist_ok=True)
        for name, data in self.items.items():
            path = Path(folder) / name
            if not path.is_file():
                files.write_bytes(path, data)


def referenced(html_text: str) -> set[str]:
    """The report_files/... names a report.html uses."""
    return set(_REFERENCE.findall(html_text))


def prune(page: Path) -> None:
    """Removes from the report_files/ folder beside the report.html ``page`` every file that
    the page does not name (an earlier report's, after a new one replaced it), and the folder
    once empty. Nothing is removed while the page is missing."""
    page = Path(page)
    assets = page.parent / FOLDER
    if not assets.is_dir() or not page.is_file():
        return
    keep = referenced(files.read_text(page, "report"))
    for path in assets.iterdir():
        if f"{FOLDER}/{path.name}" not in keep and path.is_file():
            path.unlink()
    try:
        assets.rmdir()
    except OSError:   # not empty: the report uses it
        pass


def move_in(staging: Path, out: Path) -> None:
    """Moves every file of ``staging``/report_files into ``out``/report_files, each with an
    atomic rename (a name already there holds the same bytes); before report.html moves."""
    src = Path(staging) / FOLDER
    if not src.is_dir():
        return
    dst = Path(out) / FOLDER
    dst.mkdir(parents=True, exist_ok=True)
    for path in sorted(src.iterdir()):
        if path.is_file():
            os.replace(path, dst / path.name)
    try:
        src.rmdir()
    except OSError:
        pass
