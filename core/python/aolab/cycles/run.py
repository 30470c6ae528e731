"""Running plans in this process: ``render`` (one plan: from the cache, or Blender into a
temporary folder renamed into place), and ``run_plans`` (`aolab reference`, `aolab mesh`: each
plan in turn, its files copied to --out, a line printed for each, Ctrl-C and `kill` cleaning
up). ``Delivery`` says where the results go. The same plans run on a Dask cluster in
aolab.cycles.cluster; this module never imports it (the command chooses)."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from ..bridge.constants import RESULT_EXR, RESULT_MESH
from .. import scenes
from ..util import files
from ..util.arguments import parse_resolution
from ..util.files import check_paths
from .blender import ReferenceError, bridge_command, find_blender, recorded_source, run_bridge
from .cache import cached_result, complete_result, default_cache, remove_stale_temporaries
from ..util.progress import bar as progress_bar
from .console import interrupted_line, result_line
from .plan import Plan, make_plan, resolve_scene


def render(plan: Plan, cache: Path | None = None, *, force: bool = False,
           progress=True, blender: str | None = None,
           should_stop=None) -> tuple[Path, bool]:
    """Renders (or finds in the cache) the reference of `plan`. Returns (folder, cached).
    ``progress`` is True (a tqdm bar), False (none), or an object with tqdm's
    set_description, reset, n, total, refresh and close that the render drives instead.
    ``should_stop()``, when given, is asked at each line Blender prints: True stops the render
    (Blender killed, its temporary folder removed) with Stopped."""
    cache = Path(cache) if cache else default_cache()
    if not force:
        hit = cached_result(cache, plan, blender)
        if hit is not None:
            return hit, True
    blender = blender or find_blender()
    cache.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(cache)
    key = plan.key(blender)
    final = cache / key
    tmp = cache / f".{key}.tmp-{os.getpid()}"
    cmd = bridge_command(blender, bridge_arguments(plan, tmp),
                         blend=plan.scene.path if plan.scene.kind == "blend" else None,
                         opengl=plan.peers and plan.eevee)
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir()
    name = plan.scene.name
    bar = (progress_bar(progress, unit="spp", desc=name, leave=False)
           if isinstance(progress, bool) else progress)
    try:
        tail = run_bridge(cmd, name, bar, should_stop)
        if not complete_result(tmp, plan):   # never an entry without its files
            raise ReferenceError(f"{name}: Blender exited without writing the result:\n"
                                 + "\n".join(tail))
        files.write_checksums(tmp, [f.name for f in plan.result_files(tmp)])
        if final.exists():  # a concurrent run finished first; keep one
            shutil.rmtree(final)
        os.replace(tmp, final)
        return final, False
    finally:
        if bar is not None:
            bar.close()
        shutil.rmtree(tmp, ignore_errors=True)


def bridge_arguments(plan: Plan, tmp: Path) -> list[str]:
    """The bridge script's arguments (blender_addon/aolab_blender/export/batch.py) for ``plan``, its
    result written into the temporary folder ``tmp``."""
    s = plan.scene
    extra = {"source": recorded_source(s.path), "scene_name": s.name,
             "source_sha256": s.content_sha256, "manifest": s.manifest}
    out = tmp if plan.peers else tmp / (RESULT_MESH if plan.mesh_only else RESULT_EXR)
    args = ["--scene", str(s.path), "--kind", s.kind, "--out", str(out), "--spp", str(plan.spp),
            "--gbuffer-samples", str(plan.gbuffer_samples), "--passes", ",".join(plan.passes),
            "--extra", json.dumps(extra)]
    if plan.radius is not None:
        args += ["--radius", repr(float(plan.radius))]
    if plan.resolution:
        args += ["--resolution", f"{plan.resolution[0]}x{plan.resolution[1]}"]
    if plan.camera:
        args += ["--camera", plan.camera]
    if plan.frame is not None:
        args += ["--frame", str(plan.frame)]
    if plan.scale is not None:
        args += ["--scale", str(plan.scale)]
    if plan.peers:
        args += ["--peers", "--ladder", ",".join(str(v) for v in plan.ladder) or "none"]
        if not plan.eevee:
            args.append("--no-eevee")
    if plan.mesh_only:
        args.append("--mesh-only")
    return args


def copy_result(plan: Plan, folder: Path, out: Path) -> None:
    """Copies the render's files to `out` (a folder), all put in place together
    (files.write_together): a full disk leaves the earlier files and no temporary."""
    out.mkdir(parents=True, exist_ok=True)
    files.write_together([(out / src.name, files.read_bytes(src, "cached result"))
                          for src in plan.result_files(folder)])
    scenes.write_folder_checksums(out)   # what the folder holds now, this render's included


def output_folder(out: Path, plan: Plan, several_scenes: bool) -> Path:
    """Where --out receives a plan's files: OUT, OUT/<scene> when several scenes (the scene's
    name as files.file_name_for makes it a file name), and .../frames/NNNN for a frame
    (docs/file_formats.md, "Sequences")."""
    out = Path(out)
    if several_scenes:
        out = out / files.file_name_for(plan.scene.name)
    if plan.frame is not None:
        out = out / "frames" / f"{plan.frame:04d}"
    return out


@dataclass(frozen=True)
class Delivery:
    """Where rendered plans go and how: the cache (None: default_cache()), a folder to copy
    each result to (``out``, optional), rendering again what is cached (``force``) and the
    progress bar off (``quiet``)."""
    cache: str | None = None
    out: str | None = None
    force: bool = False
    quiet: bool = False

    def check(self) -> None:
        """--cache and --out, checked before Blender starts: a --cache that is a file said
        "File exists" only once the render was to be stored, and a bad --out failed after
        the render."""
        check_paths(folders={"--cache": self.cache, "--out": self.out})

    def check_plans(self, plans: list[Plan]) -> None:
        """Before any render: no file a plan copies to --out (its result and the folder's
        SHA256SUMS) is a scene file a plan reads (files.check_distinct)."""
        if not self.out:
            return
        several = several_scenes(plans)
        reads = {"the scene": sorted({p.scene.path for p in plans})}
        for plan in plans:
            folder = output_folder(self.out, plan, several)
            files.check_distinct(reads=reads, writes={"--out": [
                *plan.result_files(folder), folder / files.CHECKSUMS_NAME]})

    def cache_folder(self) -> Path:
        return Path(self.cache) if self.cache else default_cache()

    def deliver(self, plan: Plan, folder: Path, several_scenes: bool) -> None:
        """Copies a finished plan's files to --out, if given (output_folder)."""
        if self.out:
            copy_result(plan, folder, output_folder(self.out, plan, several_scenes))


def export_meshes(scenes: list[str], delivery: Delivery, *, resolution: str | None = None,
                  camera: str | None = None, follow_symlinks: bool = False) -> int:
    """`aolab mesh`: each scene's world-space triangles as Cycles renders them, without
    rendering, at the resolution and camera a reference of it has (so that the scene_hash of
    reference.mesh.json equals reference.json's); the exit status."""
    delivery.check()
    size = parse_resolution(resolution) if resolution else None
    found = [resolve_scene(s, follow_symlinks) for s in scenes]  # every error before any export
    plans = [make_plan(s, passes=["depth"], resolution=size, camera=camera) for s in found]
    for plan in plans:
        plan.mesh_only = True
    delivery.check_plans(plans)
    with holding(delivery.out, "aolab mesh"):
        return run_plans(plans, delivery)


def holding(out, owner: str):
    """The --out folder held for this run (files.output_lock), so that two runs never
    interleave their copies of a result; nothing to hold without --out."""
    return files.output_lock(out, owner) if out else contextlib.nullcontext()


@contextlib.contextmanager
def terminate_as_interrupt():
    """SIGTERM (`kill`) raises KeyboardInterrupt while inside, so that it stops and cleans
    up as Ctrl-C does."""
    def terminated(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGTERM, terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


def several_scenes(plans: list[Plan]) -> bool:
    """Whether the plans are of more than one scene (each then has its folder in --out)."""
    return len({p.scene.name for p in plans}) > 1


def run_plans(plans: list[Plan], delivery: Delivery) -> int:
    """Renders (or takes from the cache) each plan in turn, copying its files to
    ``delivery.out``; the exit status."""
    done = 0
    several = several_scenes(plans)
    cache = delivery.cache_folder()
    with terminate_as_interrupt():   # `kill` cleans up like Ctrl-C
        try:
            for plan in plans:
                t0 = time.perf_counter()
                folder, was_cached = render(plan, cache, force=delivery.force,
                                            progress=not delivery.quiet and sys.stderr.isatty())
                delivery.deliver(plan, folder, several)
                # done before its line: an interrupt while it prints has it done all the same
                done += 1
                verb = "exported" if plan.mesh_only else "rendered"
                how = "cached" if was_cached else f"{verb} in {time.perf_counter() - t0:.1f} s"
                print(result_line(plan, folder, how, delivery.out))
        except KeyboardInterrupt:
            print(interrupted_line(done, plans, cache), file=sys.stderr)
            return 130
    return 0
