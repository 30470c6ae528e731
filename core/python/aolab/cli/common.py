"""What the commands that read one G-buffer share (run, rtao, bench, analytic): the input
options and their --set values, the G-buffer or analytic scene they name, and the output
files run and rtao write."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np

import aolab

from ..bridge import mesh as mesh_file
from ..scoring import metrics_mask
from ..settings import parse_assignments
from ..util import files
from ..util.arguments import MAX_SIDE, MAX_THREADS, float_option, int_option
from .options import threads_option

#: The --radius option's type.
RADIUS = float_option("--radius", unit="view-space units", float32=True)
#: The --width and --height options' types.
SIDE = {name: int_option(name, 1, MAX_SIDE) for name in ("--width", "--height")}


def input_options(q, threads=True, settings=True):
    """--radius, --width, --height and (unless switched off) --threads and --set."""
    q.add_argument("--radius", type=RADIUS, help="view-space radius R, finite > 0 "
                   "(default: the sidecar's ao_distance; 1 for analytic scenes)")
    q.add_argument("--width", type=SIDE["--width"], default=1280,
                   help=f"analytic scenes: width, 1 to {MAX_SIDE} (default 1280)")
    q.add_argument("--height", type=SIDE["--height"], default=720,
                   help=f"analytic scenes: height, 1 to {MAX_SIDE} (default 720)")
    if threads:
        q.add_argument("--threads", type=threads_option(), default=0,
                       help=f"worker threads, 0 to {MAX_THREADS} (0 = all cores)")
    if not settings:
        return
    q.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="a method setting, e.g. --set directions=16; a choice by "
                   "name, e.g. --set falloff=clipped (repeatable; `aolab methods` lists "
                   "them). R is not a setting here: --set radius=... is refused, use "
                   "--radius")


def key_values(pairs: list[str] | None, method: str | None = None) -> dict:
    """--set / --param KEY=VALUE items as a dict: numbers, bools, and a choice setting's name
    (or any other text, which aolab.compute then rejects, naming what is valid). With a
    method, a setting's text that is no value of its type is a ValueError naming it, and so
    is a key that is one of the command's own options (--set radius=2: use --radius)."""
    values = parse_assignments(pairs, method)
    if method is not None:
        for key in values:
            if key in OWN_OPTIONS:
                raise ValueError(f"--set {key}=...: {key} is not set with --set; use "
                                 f"{OWN_OPTIONS[key]}")
    return values


#: Keywords of aolab.compute that the commands set from their own options.
OWN_OPTIONS = {"radius": "--radius", "threads": "--threads", "preset": "--preset",
               "blur": "--blur / --no-blur", "blur_sigma": "--blur-sigma",
               "blur_taps": "--blur-taps", "progress": "no option (it is not a setting)"}


def load_input(spec: str, radius: float | None, width: int, height: int):
    """A G-buffer from an EXR path or ``analytic:NAME``; returns (gbuffer, radius)."""
    if spec.startswith("analytic:"):
        params = {"radius": radius} if radius is not None else {}
        g = aolab.analytic_scene(spec.split(":", 1)[1], width, height, **params)
        return g, radius if radius is not None else 1.0
    path = files.regular_file(spec, "G-buffer")
    g = aolab.load_gbuffer(path)
    if radius is None:
        radius = g.sidecar.get("ao_distance")
        if not isinstance(radius, (int, float)) or not (np.isfinite(radius) and radius > 0):
            raise ValueError(f"the sidecar of {spec} has no ao_distance > 0 (got {radius!r}); "
                             "pass --radius")
    return g, float(radius)


#: What aolab run writes: one image per suffix.
OUT_SUFFIXES = (".exr", ".png")


def existing_ancestor_is_not_a_folder(path: Path) -> Path | None:
    """The first existing ancestor of ``path`` (itself excluded) that is not a folder."""
    for parent in path.parents:
        if parent.exists():
            return None if parent.is_dir() else parent
        if parent.is_symlink():   # a dangling link
            return parent
    return None


def output_stem(out: str | None, method: str) -> Path:
    """The path aolab run writes STEM.exr and STEM.png to: METHOD_ao by default, inside
    ``out`` when it is an existing folder or ends in a slash, else ``out`` without its .exr
    or .png suffix; another suffix (out.txt) is a ValueError naming it, and so is a path
    under a file. :func:`check_outputs` then makes its folder."""
    default = f"{method}_ao"
    if not out:
        return Path(default)
    if out.endswith(("/", os.sep)) or Path(out).is_dir():
        stem = Path(out) / default
    else:
        stem = Path(out)
        suffix = stem.suffix
        if suffix.lower() in OUT_SUFFIXES:
            stem = stem.with_suffix("")
        elif re.fullmatch(r"\.[A-Za-z][A-Za-z0-9]*", suffix):
            raise ValueError(f"--out is the output path without extension (aolab run writes "
                             f"OUT.exr and OUT.png), got {out!r} with the suffix {suffix!r}")
        if stem.is_dir():
            raise ValueError(f"--out {out!r}: {stem} is a folder")
    blocker = existing_ancestor_is_not_a_folder(stem)
    if blocker is not None:
        raise ValueError(f"--out {out!r}: {blocker} is a file, not a folder")
    for target in out_paths(stem):
        if target.is_dir():
            raise ValueError(f"--out {out!r}: {target} is a folder")
    return stem


def out_paths(stem: Path) -> list[Path]:
    """The files written for --out STEM: STEM.exr and STEM.png."""
    return [stem.parent / (stem.name + suffix) for suffix in OUT_SUFFIXES]


def gbuffer_files(spec: str, label: str = "the input") -> dict:
    """The files a G-buffer input is read from, {what: path} for files.check_distinct: the
    EXR and its sidecar (``<stem>.json`` beside the path given, as aolab.load_gbuffer finds
    it); nothing for ``analytic:NAME``."""
    if spec.startswith("analytic:"):
        return {}
    found = {label: spec}
    if Path(spec).name not in ("", ".", ".."):
        found[f"{label}'s sidecar"] = Path(spec).with_suffix(".json")
    return found


def mesh_files(path, label: str) -> dict:
    """The files a .mesh is read from: the mesh and its .mesh.json beside it."""
    return {label: path, f"{label}'s JSON": mesh_file.json_path(path)}


def check_outputs(stem: Path, json_path: str | None, reads: dict) -> None:
    """Before any work: the --json file can be written, no output (STEM.exr, STEM.png, the
    --json file) is an input (``reads``, {what: path}) or another output; then STEM's
    folder is made."""
    files.check_paths(files={"--json": json_path}, made={"--out": out_paths(stem)}, reads=reads)
    stem.parent.mkdir(parents=True, exist_ok=True)


def scores(g, ao) -> tuple[dict | None, str]:
    """``ao``'s metrics against the G-buffer's AO pass where it has one, and the line that
    reports them or says why nothing is scored."""
    mask = metrics_mask(g)
    if ao.ndim == 3:
        return None, "  RGB result (colour bleeding): written as an image, not scored"
    if mask is not None:
        m = aolab.metrics(ao, g.reference, mask)
        return m, (f"  against the reference on {m['count']} pixels: MAE {m['mae']:.4f}  "
                   f"SSIM {m['ssim']:.4f}  RMSE {m['rmse']:.4f}  PSNR {m['psnr']:.2f} dB  "
                   f"bias {m['bias']:+.4f}")
    if getattr(g, "reference", None) is not None:
        return None, ("  the input's AO pass has no finite value on a geometry pixel (all "
                      "NaN): nothing to score")
    return None, "  no reference AO in the input: nothing to score"


def write_result(g, ao, stem: Path, result: dict, json_path: str | None, header: str) -> None:
    """STEM.exr, STEM.png and the --json file, put in place together (files.write_together:
    a full disk leaves the earlier ones), then the header line and the scores printed."""
    exr, png = out_paths(stem)
    metrics, line = scores(g, ao)
    if metrics is not None:
        result["metrics"] = metrics
    result["output"] = str(exr)
    outputs = [(exr, aolab.encode_image(exr, ao)), (png, aolab.encode_image(png, ao))]
    if json_path:
        outputs.append((json_path, json.dumps(result, indent=2, default=float).encode()))
    files.write_together(outputs)
    print(f"{header} -> {exr}, {png}")
    print(line)
