"""``aolab limits``: the screen-space limit of every reference scene, computed once and
committed beside the scene like the peers (docs/comparison.md, "The screen-space limit").

    aolab limits [SCENES...] [--thickness 0.1 0.25 1 inf] [--rays 256] [--force]

The limit is the ``screen_space_limit`` method (docs/methods/screen_space_limit.md): the
reference's own definition evaluated on the depth buffer alone, with a scene that is solid
for a thickness T behind every visible surface. It takes minutes per scene, so ``aolab
compare`` reads it from reference_scenes/<scene>/limits/ instead of running it: one
half-float EXR per thickness (channel Y, the peers' format) and limits.json describing each
(thickness, rays, seed, compute time, the SHA-256 of the reference.exr it was computed from,
the commit and date). A thickness is given as a multiple of the scene's R (``inf`` = a
height field), so one list serves scenes of any size. The thicknesses of a scene are
computed in one pass (``screen_space_limit_thicknesses``: each ray marched once), which
costs about one run at the thinnest of them.

An entry is recomputed only when it is missing, when its file or settings differ from the
request, when the scene's reference.exr changed, or with ``--force`` (after a change to the
method itself). An entry of more rays than asked for is kept without ``--force``: a quick
look at fewer rays never replaces the committed, better limit. Each EXR and limits.json are
written atomically, limits.json after every scene, so an interrupted run keeps the scenes it
finished.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

import aolab

from ..bridge.exr import write_gray
from ..scenes import (LIMITS_DIR, LIMITS_JSON, find_scenes_dir, resolve_scenes,
                      write_folder_checksums)
from ..util import files
from ..util import values as checked
from ..util.arguments import parse_thickness
from ..util.files import check_paths
from ..util.provenance import git_commit

LIMIT_METHOD = "screen_space_limit"
#: Thicknesses of the committed limits as multiples of R. A height field (inf) counts
#: everything behind a visible surface as solid and over-occludes; a thin shell (0.1 R) lets
#: rays pass behind thin objects' front faces; the scenes' objects are mostly between
#: (docs/comparison.md shows the limit at each).
THICKNESS_R = (0.1, 0.25, 0.5, 1.0, math.inf)
#: Rays per pixel: the method's default (256, stratified), whose Monte-Carlo error on one
#: pixel is at most 0.5/sqrt(256) = 0.031 and far less on a region's mean.
RAYS = 256
#: A height field is the method's largest thickness.
HEIGHT_FIELD = 1e30


def thickness_label(t_r: float) -> str:
    return "T = ∞ (height field)" if math.isinf(t_r) else f"T = {t_r:g} R"


def entry_name(t_r: float) -> str:
    return f"{LIMIT_METHOD}_t_inf" if math.isinf(t_r) else f"{LIMIT_METHOD}_t{t_r:g}R"


def read_entries(folder: Path) -> list[dict]:
    """The entries of a scene's limits.json ([] when there is none)."""
    path = folder / LIMITS_DIR / LIMITS_JSON
    if not path.exists():
        return []
    return json.loads(files.read_text(path, "limits")).get("entries", [])


def _up_to_date(entry: dict | None, folder: Path, want: dict) -> bool:
    if entry is None or not (folder / LIMITS_DIR / entry.get("file", "")).exists():
        return False
    return all(entry.get(k) == v for k, v in want.items())


def compute_scene(folder: Path, thickness_r, rays: int, threads: int, force: bool,
                  log=print) -> list[dict]:
    """Computes the missing or stale limits of one scene folder; returns its entries."""
    threads = checked.threads(threads)
    g = aolab.load_gbuffer(folder / "reference.exr")
    radius = float(g.sidecar["ao_distance"])
    digest = files.sha256_file(folder / "reference.exr")
    out_dir = folder / LIMITS_DIR
    out_dir.mkdir(exist_ok=True)
    entries = {e["name"]: e for e in read_entries(folder)}
    todo = []
    for t_r in thickness_r:
        name = entry_name(t_r)
        want = {"rays": rays, "seed": 0, "thickness_r": None if math.isinf(t_r) else t_r,
                "reference_sha256": digest, "radius": radius}
        have = entries.get(name)
        better = {**want, "rays": have.get("rays")} if have else None
        if not force and _up_to_date(have, folder, want):
            log(f"{folder.name}: {name} up to date")
        elif not force and _up_to_date(have, folder, better) and have["rays"] > rays:
            log(f"{folder.name}: {name} kept: it has {have['rays']} rays, more than --rays "
                f"{rays} (--force replaces it)")
        else:
            todo.append((t_r, name, want))
    if not todo:
        return read_entries(folder)
    # One pass for every stale thickness: each ray is marched once (docs/comparison.md).
    # A shell thicker than the height field's is the height field (min): a huge R times a
    # large multiple would pass the method's largest thickness.
    thickness = [min(t_r * radius, HEIGHT_FIELD) for t_r, _, _ in todo]
    t0 = time.perf_counter()
    images = aolab._core.screen_space_limit_thicknesses(
        g, {"radius": radius, "rays": rays, "seed": 0}, thickness, threads=threads)
    seconds = time.perf_counter() - t0
    commit, date = git_commit(folder), time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime())
    together = [name for _, name, _ in todo]
    for (t_r, name, want), t, ao in zip(todo, thickness, images):
        write_gray(str(out_dir / f"{name}.exr"), np.asarray(ao, np.float32))
        entries[name] = {"name": name, "kind": "limit", "label": thickness_label(t_r),
                         "file": f"{name}.exr", "thickness": t, **want,
                         "render_time_s": seconds, "computed_with": together,
                         "threads": threads, "aolab_commit": commit, "date": date,
                         "note": "the screen-space limit (a bound): the reference's AO on "
                                 "the depth buffer alone, solid for T behind each surface; "
                                 "render_time_s is the one pass that computed the entries of "
                                 "computed_with"}
    order = [entry_name(t) for t in THICKNESS_R]
    ordered = sorted(entries.values(), key=lambda e: (
        order.index(e["name"]) if e["name"] in order else len(order), e["name"]))
    files.write_text(out_dir / LIMITS_JSON, json.dumps({"entries": ordered}, indent=1) + "\n")
    write_folder_checksums(out_dir)
    log(f"{folder.name}: {', '.join(together)} in {seconds:.1f} s (one pass)")
    return read_entries(folder)


def compute_scenes(specs: list[str], *, thickness: list[float] | None = None, rays: int = RAYS,
                   threads: int = 0, force: bool = False, scenes_dir: Path | None = None,
                   follow_symlinks: bool = False) -> None:
    """``aolab limits``: the limits of each scene of ``specs`` (names, folders; none: every
    scene of ``scenes_dir``, default find_scenes_dir()) at ``thickness`` (multiples of R,
    default THICKNESS_R), each scene's limits folder held while it is written; a symbolic
    link among a scene's files is refused unless ``follow_symlinks``."""
    check_paths(inputs={"--scenes-dir": scenes_dir})
    thickness = [parse_thickness(t) for t in thickness] if thickness else list(THICKNESS_R)
    folders = resolve_scenes(specs, Path(scenes_dir) if scenes_dir else find_scenes_dir(),
                             follow_symlinks=follow_symlinks)
    for folder in folders:   # before any work: a file named limits is no folder to write in
        files.check_output_folder(folder / LIMITS_DIR, "the limits folder of a scene")
    for folder in folders:
        # One run at a time per scene: two would each rewrite limits.json from what they read.
        with files.output_lock(folder / LIMITS_DIR, "aolab limits"):
            compute_scene(folder, thickness, rays, threads, force)
