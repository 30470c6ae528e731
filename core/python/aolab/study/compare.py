"""``aolab compare``: every method against the Cycles reference on every reference scene,
timed and scored, with a report (docs/comparison.md).

    aolab compare [SCENES...] [--methods M ...] [--sweep quick|presets|full] [--out DIR]

For each scene (a reference_scenes/<name> folder with reference.exr) and each configuration
of each method (aolab.presets), the method is run ``warmup`` + ``repeat`` times at the
scene's R; the median of the timed runs is its time, and the shared blur (if the
configuration has one) is timed apart in the same way. The output is scored against the
1024-spp reference on the scored pixels and on each region of aolab.regions, beside the
"AO = 1" baseline and the peers of reference_scenes/<name>/peers/ (Cycles at fewer samples,
an independent 1024-spp render, EEVEE's GTAO). Results go to DIR/results.csv,
DIR/results.json and DIR/report.html, with the report's images and scripts in
DIR/report_files/. While the study runs they are written to the staging folder DIR.partial/
beside DIR (atomically, after every scene) and moved into DIR only when the study is complete:
Ctrl-C keeps what is done in DIR.partial/ and leaves the results of an earlier complete run in
DIR untouched (docs/conventions.md, "Output folders").
"""

import math
import os
import signal
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import aolab

from .. import catalog
from .. import named_presets as presets_mod
from ..raytracing import RTAO_LADDER
from ..regions import DESCRIPTIONS as REGION_DESCRIPTIONS
from ..scenes import (Crop, Scene, check_sequence, find_scenes_dir, frame_folder, frame_numbers,
                      frame_scene_name, load_cropped, manifest, resolve_scenes, scene_files)
from ..scoring import signed_error_rgb
from ..util import files
from ..util.dask_cluster import ClusterSecurity, connect, wait_all
from ..util.progress import bar as progress_bar
from ..util.provenance import git_commit, machine_info
from . import report, report_files
from .companions import noise_floor, peer_images, peer_rows, rtao_rows
from .findings import WEAK_FRACTION
from .output import OUTPUT_FILES, check_out, publish, staging_folder
from .results import (BASELINE, LIMIT_KIND, aggregate, config_row, flag_rows, make_row,
                      score_row, tuned_results, write_results)
from .runner import (Timing, load_scene, run_configuration, score, score_outputs,
                     score_remotely, still_scenes, time_fields, vs_limit)
from .sequence_rows import accumulated_rows, sequence_info, sequence_means, set_flicker
from .temporal import Accumulation

# ----------------------------------------------------------------------------------------
# The study


#: A first run longer than this (ms) is a configuration's only timed run: the slow ones (the
#: visibility bitmask's defaults take over a second) would otherwise hold the study up by
#: their warm-up and repeats, which change their time by less than its spread.
DEFAULT_MAX_MS = 1000.0


@dataclass
class Options:
    scenes: list[str] = field(default_factory=list)
    #: Without scenes: every still and sequence of the corpus, not the default study's.
    corpus: bool = False
    methods: list[str] | None = None
    sweep: str = "quick"
    out: Path = Path("out/compare")
    threads: int = 0
    warmup: int = 1
    repeat: int = 3
    budget_ms: float = 1000.0
    #: A configuration whose first run takes longer is timed by that run alone.
    max_ms: float = DEFAULT_MAX_MS
    crop: Crop | None = None
    scenes_dir: Path | None = None
    progress: bool = True
    image_width: int = 480
    #: rtao's rays per pixel on each scene with a mesh (empty: no rtao rows).
    rtao_ladder: tuple[int, ...] = RTAO_LADDER
    #: Score the configurations on a Dask cluster: a local one of this many workers, or the
    #: scheduler's; the times are still measured here.
    workers: int = 1
    scheduler: str | None = None
    #: How to meet a remote scheduler (TLS files, or consent to plain tcp on the network).
    security: ClusterSecurity | None = None
    #: Read a scene's files through symbolic links (scenes.check_confined); refused without.
    follow_symlinks: bool = False


def _downscale(a: np.ndarray, width: int) -> np.ndarray:
    k = max(1, math.ceil(a.shape[1] / width))
    if k == 1:
        return a.astype(np.float32)
    h, w = (a.shape[0] // k) * k, (a.shape[1] // k) * k
    a = a[:h, :w].astype(np.float32)
    return a.reshape(h // k, k, w // k, k, *a.shape[2:]).mean(axis=(1, 3))


class _Images:
    """A scene's images for the report: every scored configuration's AO and signed error
    (encoded as it is offered, so that no full-size image is kept), and per method the best
    configuration within the time budget (lowest MAE on all scored pixels) and the fastest
    one, as the fallback when none fits, for the image grid."""

    def __init__(self, budget_ms: float, scene: Scene, width: int, encoded: bool = True):
        self.budget = budget_ms
        self.scene = scene
        self.width = width
        #: False: no image is encoded (a sequence's frames after the first, never shown).
        self.encoded = encoded
        self.best: dict[str, dict] = {}
        self.fastest: dict[str, dict] = {}
        #: "method/label" -> {"ao": WebP bytes, "error": WebP bytes}
        self.configs: dict[str, dict] = {}
        self._last = None   # (the last image encoded, its encoding)

    def encode(self, row: dict, ao: np.ndarray) -> None:
        """Keeps the row's AO and signed error (ao - reference, 0 off the scored pixels),
        downscaled to at most ``width`` px and encoded."""
        if not self.encoded:
            return
        if self._last is None or self._last[0] is not ao:   # (a blur group shares its image)
            valid = self.scene.regions["all"]
            err = np.where(valid, ao.astype(np.float64) - self.scene.reference, 0.0)
            self._last = (ao, {
                "ao": report_files.webp_bytes(_downscale(ao, self.width)),
                "error": report_files.webp_bytes(signed_error_rgb(_downscale(err, self.width)))})
        self.configs[f'{row["method"]}/{row["label"]}'] = self._last[1]

    def offer(self, row: dict, ao: np.ndarray) -> None:
        if "metrics" not in row or row.get("total_ms") is None:
            return
        self.encode(row, ao)
        m, t = row["metrics"]["all"]["mae"], row["total_ms"]
        name = row["method"]
        best = self.best.get(name)
        if t <= self.budget and (best is None or m < best["metrics"]["all"]["mae"]):
            self.best[name] = row
        if name not in self.fastest or t < self.fastest[name]["total_ms"]:
            self.fastest[name] = row

    def chosen(self):
        for name in self.fastest:
            if name in self.best:
                yield self.best[name], True
            else:
                yield self.fastest[name], False


def scene_images(scene: Scene, images: _Images, rows: list[dict]) -> dict:
    """A scene's images for the report, encoded (report_files.webp_bytes): the reference,
    every imaged configuration's AO and signed error ("configs", by "method/label"), and the
    image grid's entries, each naming its configuration."""
    valid = scene.regions["all"]
    entries = []
    shown = list(images.chosen()) + list(peer_images(scene, rows, images))
    for row, within in shown:
        entries.append({"key": row["key"], "config": f'{row["method"]}/{row["label"]}',
                        "method": row["method"], "label": row["label"],
                        "kind": row["kind"], "total_ms": row.get("total_ms"),
                        "mae": row["metrics"]["all"]["mae"], "within_budget": within})
    reference = _downscale(np.where(valid, scene.reference, 1.0), images.width)
    return {"reference": report_files.webp_bytes(reference), "configs": images.configs,
            "entries": entries, "size": [reference.shape[1], reference.shape[0]]}


def _method_runs(method: str, sweep: str) -> list[tuple[dict, list]]:
    """The configurations of ``method`` grouped by what the method computes (its settings over
    the defaults, whether spelled out or not): configurations that differ only in the blur,
    or only in their names (the defaults and a preset equal to them), share one timed run."""
    groups: dict[tuple, tuple[dict, list]] = {}
    for s in presets_mod.settings_for(method, sweep):
        key = presets_mod.identity(method, s.compute_settings(), False)
        groups.setdefault(key, (s.compute_settings(), []))[1].append(s)
    return list(groups.values())


class Study:
    """One run of the comparison; ``rows`` grows as configurations finish."""

    def __init__(self, opts: Options):
        self.opts = opts
        self.rows: list[dict] = []
        self.complete_scenes: list[str] = []
        self.scene_info: dict[str, dict] = {}
        self.images: dict[str, dict] = {}
        self.notes: list[str] = []
        self.meta: dict = {}
        #: Every scene is done and the staging folder holds the complete results.
        self.complete = False
        #: The Dask client and local cluster that score configurations (--workers, --scheduler).
        self.client = self.cluster = None

    def results(self, partial: bool) -> dict:
        rows = list(self.rows)
        flag_rows(rows)
        # ALL is the mean over the still scenes: a sequence's frames have their own size (the
        # committed one 320x180), so their times would pull the means of the stills' 1280x720
        # times down; sequences have their own rows and section (temporal stability).
        complete = set(self.complete_scenes)
        stills = [n for n in still_scenes(self.scene_info) if n in complete]
        scale = {n: self.scene_info[n].get("time_scale", 1.0) for n in stills}
        agg = aggregate(rows, stills, time_scale=scale) if stills else []
        meta = dict(self.meta)
        meta["partial"] = partial
        meta["finished"] = time.strftime("%Y-%m-%d %H:%M:%S")
        meta["elapsed_s"] = time.perf_counter() - self._t0
        meta["load_average_end"] = list(os.getloadavg()) if hasattr(os, "getloadavg") else None
        meta["complete_scenes"] = list(self.complete_scenes)
        return {"meta": meta, "scenes": self.scene_info, "notes": self.notes,
                "regions": REGION_DESCRIPTIONS, "rows": rows + agg, "tuned": tuned_results()}

    @property
    def staging(self) -> Path:
        """Where the study's files are written while it runs (staging_folder)."""
        return staging_folder(Path(self.opts.out))

    def write(self, partial: bool) -> dict:
        """results.csv, results.json and report.html into the staging folder, each atomically
        (publish() moves them into the output folder once the study is complete)."""
        staging = self.staging
        staging.mkdir(parents=True, exist_ok=True)
        results = self.results(partial)
        write_results(staging, results)
        report.write_report(staging / "report.html", results, self.images)
        return results

    def publish(self) -> None:
        """Moves the complete study's files into the output folder (output.publish)."""
        publish(Path(self.opts.out))

    def run(self) -> dict:
        opts = self.opts
        self._t0 = time.perf_counter()
        check_out(Path(opts.out))
        scenes_dir = opts.scenes_dir or find_scenes_dir()
        follow = opts.follow_symlinks
        folders = resolve_scenes(opts.scenes, scenes_dir, default_study=not opts.corpus,
                                 follow_symlinks=follow)
        out, staging = Path(opts.out), staging_folder(opts.out)
        files.check_paths(reads=scene_files(folders),
                          made={"--out": [f / n for f in (out, staging) for n in OUTPUT_FILES]},
                          cleared={"the report folder of --out": out / report_files.FOLDER})
        motion = {}   # sequence -> every frame after the first has motion vectors
        for folder in folders:  # every scene's errors before any work
            if frame_numbers(folder):
                motion[folder] = check_sequence(folder, opts.crop, follow_symlinks=follow)
            else:
                load_cropped(folder, opts.crop, follow_symlinks=follow)
        report_files.check_names_fit(Path(opts.out))
        # Bounds (method_info "bound") are not contenders, and slow: they run only when
        # named.
        methods = opts.methods if opts.methods else [
            m for m in aolab.methods() if not aolab.method_info(m)["bound"]]
        known = aolab.methods()
        for m in methods:
            if m not in known:
                raise ValueError(f"method {m!r} is not one of {known}")
        plan = {m: _method_runs(m, opts.sweep) for m in methods}
        frames = sum(len(frame_numbers(f) or [None]) for f in folders)
        n_units = frames * (1 + sum(len(v) for v in plan.values()) + len(opts.rtao_ladder))
        self.meta = {
            "command": "aolab compare", "argv": sys.argv[1:],
            "started": time.strftime("%Y-%m-%d %H:%M:%S"), "sweep": opts.sweep,
            "methods": methods, "scenes": [f.name for f in folders],
            "warmup": opts.warmup, "repeat": opts.repeat, "budget_ms": opts.budget_ms,
            "max_ms": opts.max_ms,
            "crop": None if opts.crop is None else f"{opts.crop.width}x{opts.crop.height}",
            "machine": machine_info(opts.threads), "aolab_commit": git_commit(folders[0]),
            "weak_fraction": WEAK_FRACTION, "blur_sigma": presets_mod.BLUR_SIGMA,
            "blur_taps": presets_mod.BLUR_TAPS,
            "presets_source": {m: (catalog.entry(m).source if catalog.entry(m) else
                                   "no presets registered: the method's defaults")
                               for m in methods},
        }
        threads = opts.threads
        bar = progress_bar(opts.progress, n_units, "run")
        if opts.scheduler is not None or opts.workers > 1:
            self.client, self.cluster = connect(opts.scheduler, opts.workers, opts.security)
        try:
            for folder in folders:
                if frame_numbers(folder):
                    self._run_sequence(folder, plan, threads, bar, motion[folder])
                else:
                    self._run_scene(folder, plan, threads, bar)
        finally:
            if bar is not None:
                bar.close()
            for held in (self.client, self.cluster):
                if held is not None:
                    held.close()
        results = self.write(partial=False)
        self.complete = True
        self.publish()
        return results

    def _run_sequence(self, folder: Path, plan: dict, threads: int, bar,
                      motion: bool = False) -> None:
        """Each frame scored as a scene of its own (rows of scene <name>@NNNN with ``sequence``
        and ``frame``), each row's flicker against the frame before, the reference's flicker
        floor per pair, then the sequence's rows (scene <name>): means over its frames, the
        flicker over its pairs. The images shown are the first frame's. With ``motion`` (every
        frame after the first has motion vectors) each configuration runs at frame=k and is
        also accumulated (Accumulation): a second row per frame, label + ACCUMULATED_SUFFIX."""
        name = folder.name
        frames = frame_numbers(folder)
        names = [frame_scene_name(name, f) for f in frames]
        floors, previous = [], None
        temporal = Accumulation(self.opts.warmup + self.opts.repeat) if motion else None
        for index, (frame, frame_name) in enumerate(zip(frames, names)):
            scene = self._run_scene(frame_folder(folder, frame), plan, threads, bar,
                                    name=frame_name, sequence=(name, frame),
                                    shown=frame == frames[0],
                                    temporal=(temporal, index) if temporal else None)
            if previous is not None:
                floors.append(set_flicker(previous, scene, self.rows))
            previous = scene
        info = self.scene_info[name] = sequence_info(folder, frames, names,
                                                     self.scene_info[names[0]], previous, floors)
        self.rows.extend(sequence_means(self.rows, name, names, frames, info, temporal))
        self.images[name] = self.images.get(names[0])
        self.complete_scenes.append(name)
        self.write(partial=True)

    def _run_scene(self, folder: Path, plan: dict, threads: int, bar, name: str | None = None,
                   sequence: tuple[str, int] | None = None, shown: bool = True,
                   temporal: tuple | None = None) -> Scene:
        """One scene (or, with ``name`` and ``sequence`` = (its name, the frame), one frame of
        a sequence, whose images are then kept for the flicker); ``shown``: its images are
        made for the report (a sequence shows its first frame's); ``temporal``: (the
        sequence's Accumulation, the frame's index) for a sequence with motion."""
        opts = self.opts
        if bar is not None:
            bar.set_description(f"{name or folder.name}: loading")
        scene = load_scene(folder, opts.crop, name, follow_symlinks=opts.follow_symlinks)
        if sequence is not None:
            scene.sequence, scene.frame = sequence
            scene.outputs = {}
        if temporal is not None:
            temporal[0].begin_frame(scene, temporal[1], opts.warmup, opts.repeat, threads)
        self.notes.extend(f"{scene.name}: {n}" for n in scene.notes)
        self.scene_info[scene.name] = {
            "folder": str(folder), "width": scene.g.width, "height": scene.g.height,
            "radius": scene.radius,
            "region_pixels": {r: int(m.sum()) for r, m in scene.regions.items()},
            "peers": [p.name for p in scene.peers if p.kind != LIMIT_KIND],
            "limits": [p.name for p in scene.peers if p.kind == LIMIT_KIND],
            "title": manifest(folder).get("title", scene.name),
            "family": manifest(folder).get("family"),
            # ALL's times are per 1280x720 frame; a crop's stay the crop's (runner.hd_scale)
            "time_scale": scene.time_scale,
        }
        images = _Images(opts.budget_ms, scene, opts.image_width, encoded=shown)
        # The baseline, AO = 1 everywhere: no occlusion at all, no time.
        base = make_row(scene, "baseline", BASELINE, "AO=1", preset="", settings={},
                        note="no occlusion at all (AO = 1 everywhere)")
        score_row(scene, base, np.ones_like(scene.reference))
        self.rows.append(base)
        self.rows.extend(peer_rows(scene, self.scene_info[scene.name]))
        if bar is not None:
            bar.update(1)
        frame = temporal[1] if temporal is not None else None
        remote = (self._score_on_cluster(folder, name, plan, bar, frame) if self.client
                  else {})
        for method, runs in plan.items():
            for i, (compute_settings, settings) in enumerate(runs):
                if bar is not None:
                    bar.set_description(f"{scene.name}: {method} {settings[0].label}")
                self._run_config(scene, method, compute_settings, settings, threads, images,
                                 remote.get((method, i)),
                                 temporal[0] if temporal is not None else None)
                if bar is not None:
                    bar.update(1)
        timing = Timing(opts.warmup, opts.repeat, threads, opts.max_ms)
        for row in rtao_rows(scene, opts.rtao_ladder, timing, images,
                             self.scene_info[scene.name], self.notes, bar):
            self.rows.append(row)   # (one by one: Ctrl-C keeps the rungs timed so far)
        self.scene_info[scene.name]["noise_floor"] = noise_floor(scene, self.rows)
        if shown:
            self.images[scene.name] = scene_images(scene, images, self.rows)
        if sequence is None:   # a sequence is complete with its last frame (_run_sequence)
            self.complete_scenes.append(scene.name)
            # (a frame's rows are written with its sequence's: the partial files after every
            # frame cost a third of a sequence's time; Ctrl-C still writes what is done)
            self.write(partial=True)
        return scene

    def _score_on_cluster(self, folder: Path, name: str | None, plan: dict, bar,
                          frame: int | None = None) -> dict:
        """(method, index in its runs) -> runner.score_remotely's result for each
        configuration of the scene, computed on the cluster before any is timed here: the
        workers are idle while this machine times (a local cluster shares its cores)."""
        if bar is not None:
            bar.set_description(f"{name or folder.name}: scoring on the cluster")
        futures = {(method, i): self.client.submit(
            score_remotely, str(folder), self.opts.crop, name, method, compute_settings,
            sorted({bool(s.blur) for s in settings}), score, frame, self.opts.follow_symlinks,
            pure=False)
            for method, runs in plan.items() for i, (compute_settings, settings) in enumerate(runs)}
        wait_all(self.client, list(futures.values()), lambda: None)
        return {k: f.result() for k, f in futures.items()}

    def _run_config(self, scene, method, compute_settings, settings, threads, images,
                    remote: dict | None = None, temporal: Accumulation | None = None):
        """One group of configurations (the same compute settings, blurred or not): run by
        the runner, timed here, scored here or, with ``remote`` (runner.score_remotely's
        result), on the cluster. With ``temporal`` (a frame of a sequence with motion) the
        method runs at frame=k, and each configuration also gets its accumulated row
        (sequence_rows.accumulated_rows)."""
        opts = self.opts
        timing = Timing(opts.warmup, opts.repeat, threads, opts.max_ms)
        try:
            if remote is not None and "error" in remote:
                raise ValueError(remote["error"])
            run = run_configuration(method, compute_settings, scene, timing,
                                    frame=temporal.index if temporal is not None else None)
        except (ValueError, RuntimeError) as e:
            for accumulated in (False, True) if temporal is not None else (False,):
                self.rows.extend(config_row(scene, method, s, threads, temporal, accumulated,
                                            note=f"error: {e}")
                                 for s in settings)
            return
        # Configurations of the group with the same blur switch give the same image: it is
        # blurred, timed and scored once and its numbers are shared.
        score_outputs(run, scene, timing, [bool(s.blur) for s in settings], remote=remote)
        for s in settings:
            out = run.output(s.blur)
            row = config_row(scene, method, s, threads, temporal, runs=len(run.times),
                             **time_fields("method", run.times),
                             **time_fields("blur", out.blur_times))
            row["total_ms"] = row["method_ms"] + (row.get("blur_ms") or 0.0)
            if out.scores is None:
                row["note"] = (f"output has shape {out.ao.shape} (RGB, e.g. colour bleeding): "
                               "timed, not scored against the grey AO reference")
            else:
                score_row(scene, row, out.ao, out.scores)
                row["occluded_mae_vs_limit"] = vs_limit(out.ao, scene)
                images.offer(row, out.ao)
            self.rows.append(row)
        if temporal is not None:
            for row in accumulated_rows(scene, compute_settings, settings, threads, temporal,
                                        run):
                self.rows.append(row)


def run_study(opts: Options) -> int:
    """The study of ``opts`` with its output folder held (``aolab compare``): the exit
    status."""
    study = Study(opts)
    # One run at a time in an output folder: a second one would remove this one's staging
    # folder and publish a mix of both (files.output_lock).
    check_out(opts.out)
    with files.output_lock(opts.out, "aolab compare"):
        return _run(study, opts)


def _run(study: Study, opts: Options) -> int:
    """The study, with Ctrl-C and `kill` keeping the partial results; the exit status."""
    def terminated(signum, frame):  # `kill` keeps the partial results like Ctrl-C
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, terminated)
    try:
        results = study.run()
    except KeyboardInterrupt:
        if not study.meta:
            print("aolab compare: interrupted before the first scene; nothing written",
                  file=sys.stderr)
            return 130
        if study.complete:   # interrupted while moving the complete results: finish that
            study.publish()
            print(f"\naolab compare: interrupted after the study was complete; its results "
                  f"are in {opts.out}/", file=sys.stderr)
            return 130
        study.write(partial=True)
        done = len(study.complete_scenes)
        kept = [n for n in OUTPUT_FILES if (opts.out / n).is_file()]
        earlier = (f"the results of an earlier run in {opts.out}/ are untouched"
                   if kept else f"nothing was written to {opts.out}/")
        print(f"\naolab compare: interrupted. Partial results ({len(study.rows)} rows, "
              f"{done} of {len(study.meta['scenes'])} scenes complete) are in "
              f"{study.staging}/ (results.csv, results.json, report.html marked PARTIAL); "
              f"{earlier}. Run the command again for the full study.", file=sys.stderr)
        return 130
    finally:
        signal.signal(signal.SIGTERM, previous)
    meta = results["meta"]
    # a sequence's configurations are counted once (its rows over the frames), not per frame,
    # and an accumulated row is its configuration's second
    mine = [r for r in results["rows"] if r["kind"] == "method" and r["scene"] in meta["scenes"]]
    n = sum(1 for r in mine if r.get("accumulated") is not True)
    accumulated = sorted({r["scene"] for r in mine if r.get("accumulated") is True})
    also = (f" (each also accumulated on {', '.join(accumulated)})" if accumulated else "")
    print(f"aolab compare: {n} configurations{also} on {len(meta['scenes'])} scenes in "
          f"{meta['elapsed_s']:.0f} s ({meta['machine']['threads']} threads, "
          f"{meta['machine']['cpu']}) -> {opts.out}/report.html, results.csv, results.json")
    return 0
