"""`aolab reference`: Cycles AO references rendered by Blender in the background, cached.

A scene is a `.blend` file, a build script (`.py`, run into an empty factory file), or a
folder of reference_scenes/ (its manifest.json names the build script, R, resolution and
effects). Blender always starts with --factory-startup and --disable-autoexec, so a .blend
from elsewhere never runs its own scripts.

Results go to a cache folder keyed by the scene's content (file bytes), camera, R, samples,
passes and resolution; they are written to a temporary folder and renamed into place, so an
interrupted render leaves nothing half-written, a repeated call is served from the cache, and
a batch resumes where it stopped.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import aolab

from ..bridge.constants import (BRIDGE_VERSION, LADDER_SPP, PEERS_JSON, RESULT_EXR, RESULT_JSON,
                                RESULT_MESH, RESULT_MESH_JSON)
from ..bridge.passes import parse_passes, required_passes
from .. import scenes
from ..util import files
from ..util.files import check_paths

SCENE_KIT = "scene_kit.py"  # reference_scenes/scene_kit.py, shared by the build scripts
#: Environment variable naming the folder that holds this aolab package, for Blender's
#: Python: batch.py puts it first on sys.path, so Blender uses the same build.
PACKAGE_PATH_ENV = "AOLAB_PACKAGE_PATH"
_SAMPLE_LINE = re.compile(r"Sample (\d+)/(\d+)")
#: The largest render width or height (16384 = 16K, the largest side the rest of aolab
#: accepts, cli.MAX_SIDE): one 100000x100000 frame of G-buffer passes would take hundreds of
#: gigabytes and Cycles would render it for days.
MAX_RESOLUTION = 16384
#: The smallest render width or height: Blender's own minimum (RenderSettings.resolution_x
#: and resolution_y have a hard minimum of 4 in Blender 3.4 and 4.x). Blender raises a
#: smaller value to 4 without a word, so a 1x1 request would come back as a 4x4 reference.
MIN_RESOLUTION = 4


#: The hexadecimal digits of the digest that ends a cache key (Plan.key).
KEY_DIGEST_CHARS = 16


def _sha256_of(path: Path, what: str) -> str:
    return hashlib.sha256(files.read_bytes(path, what)).hexdigest()


class ReferenceError(Exception):
    """A problem the user can act on; its message says what to do."""


def find_blender() -> str:
    path = os.environ.get("AOLAB_BLENDER") or shutil.which("blender")
    if not path or not os.path.exists(path):
        raise ReferenceError(
            "Blender not found" + (f" at AOLAB_BLENDER={path}" if path else " on PATH") +
            ": install it with `apt-get install blender` (Debian 12 ships Blender 3.4) or set "
            "AOLAB_BLENDER to its executable")
    return path


@functools.lru_cache(maxsize=None)
def _version_of(path: str, mtime_ns: int) -> str:
    try:
        out = subprocess.run([path, "-b", "--factory-startup", "-noaudio", "--version"],
                             capture_output=True, text=True, timeout=120,
                             stdin=subprocess.DEVNULL).stdout
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    found = re.search(r"^Blender (\d+\.\d+(?:\.\d+)?)", out, re.M)
    return found[1] if found else "unknown"


def blender_version(blender: str | None = None) -> str:
    """The release of `blender` (default: the one find_blender finds), e.g. "3.4.1"; "none"
    where there is none. Part of every cache key: Cycles' sampling differs between releases,
    so the same scene renders to other bits (docs/blender_bridge.md)."""
    try:
        path = blender or find_blender()
        return _version_of(path, os.stat(path).st_mtime_ns)
    except (ReferenceError, OSError):
        return "none"


def bridge_script() -> Path:
    """blender_addon/aolab_blender/export/batch.py of the checkout this package was built
    from: the build writes that folder into aolab/_build_info.py. The add-on's package is
    never imported here (it needs bpy); only Blender runs it."""
    try:
        from .._build_info import ADDON_SOURCE_DIR
    except ImportError:
        raise ReferenceError("this aolab package does not say where its Blender add-on's "
                             "sources are (no aolab/_build_info.py): build it with "
                             "scripts/build.sh") from None
    script = Path(ADDON_SOURCE_DIR) / "aolab_blender" / "export" / "batch.py"
    if not script.exists():
        raise ReferenceError(f"the Blender bridge's entry point {script} is missing: was the "
                             "checkout moved? Rebuild with scripts/build.sh")
    return script


def recorded_source(path: Path) -> str:
    """The scene's path as the sidecar records it: relative to the checkout for the checkout's
    own scenes, so that a committed sidecar names no folder of the machine that rendered it;
    absolute for any other scene."""
    p = Path(path).resolve()
    try:
        from .._build_info import ADDON_SOURCE_DIR
        return p.relative_to(Path(ADDON_SOURCE_DIR).resolve().parent).as_posix()
    except (ImportError, ValueError):
        return str(p)


def package_path() -> str:
    """The folder that holds this aolab package (put first on Blender's sys.path): the
    parent of aolab/, two levels above this module (aolab/render/reference.py). Blender 4.2
    and later ignore PYTHONPATH, so this is the only way their Python finds this build."""
    return str(Path(__file__).resolve().parents[2])


def default_cache() -> Path:
    if os.environ.get("AOLAB_CACHE"):
        return Path(os.environ["AOLAB_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "aolab" / "references"


@dataclass
class Scene:
    name: str
    kind: str            # "blend" or "script"
    path: Path           # the .blend or the build script
    manifest: dict = field(default_factory=dict)
    content_sha256: str = ""


def resolve_scene(spec: str, follow_symlinks: bool = False) -> Scene:
    """The scene of ``spec`` (a .blend, a build script or a scene folder) and the hash of
    what its render depends on. A scene folder is confined (scenes.check_confined: a symbolic
    link among its files is refused unless ``follow_symlinks``), its build script a plain
    file name in it."""
    p = Path(spec)
    if not p.exists():
        raise ReferenceError(f"no such scene: {spec} (give a .blend, a build script .py or a "
                             "reference_scenes/<name> folder)")
    manifest = {}
    # Every file is checked to be a regular file before it is hashed: reading a FIFO would
    # wait forever for a writer (files.read_bytes).
    if p.is_dir():
        scenes.check_confined(p, follow_symlinks)
        mpath = p / "manifest.json"
        if not mpath.exists():
            raise ReferenceError(f"{spec} is a folder without manifest.json")
        manifest_bytes = files.read_bytes(mpath, "scene manifest")   # read once: parsed, hashed
        manifest = files.json_object(manifest_bytes, mpath, "scene manifest")
        build = manifest.get("build", "build.py")
        if not (isinstance(build, str) and files.plain_name(build)):
            raise ReferenceError(f'{mpath}: "build" must be the name of a file in the scene\'s '
                                 f"folder, got {build!r}")
        script = p / build
        if not script.exists():
            raise ReferenceError(f"{mpath} names the build script {script.name}, which is missing")
        h = hashlib.sha256(files.read_bytes(script, "build script") + manifest_bytes)
        kit = p.resolve().parent / SCENE_KIT  # the helpers every reference scene imports
        if kit.exists():
            h.update(files.read_bytes(kit, "scene kit"))
        for used in scene_uses(manifest, mpath):
            h.update(files.read_bytes(p.resolve().parent / used, "scene module"))
        return Scene(manifest.get("name", p.name), "script", script, manifest, h.hexdigest())
    if p.suffix == ".blend":
        return Scene(p.stem, "blend", p, {}, _sha256_of(p, "scene .blend"))
    if p.suffix == ".py":
        return Scene(p.stem, "script", p, {}, _sha256_of(p, "scene build script"))
    raise ReferenceError(f"{spec}: a scene is a .blend, a .py build script or a folder with "
                         "manifest.json")


def scene_uses(manifest: dict, mpath: Path) -> list[str]:
    """The manifest's "uses": the modules its build script imports besides scene_kit.py
    (a corpus family and its kit), relative to the scenes folder, which the scene's hash
    covers. Each must exist."""
    uses = manifest.get("uses", [])
    if not (isinstance(uses, list) and all(isinstance(u, str) and u for u in uses)):
        raise ReferenceError(f'{mpath}: "uses" must be a list of paths, got {uses!r}')
    for used in uses:
        if not (mpath.resolve().parent.parent / used).is_file():
            raise ReferenceError(f'{mpath}: "uses" names {used}, which is missing')
    return uses


@dataclass
class Plan:
    scene: Scene
    spp: int
    radius: float | None      # None: the scene world's AO distance (a .blend's own)
    passes: list[str]
    resolution: tuple[int, int] | None
    camera: str | None
    gbuffer_samples: int = 1
    # The comparison peers (Cycles ladder + EEVEE: blender_addon/aolab_blender/export/peers.py)
    # instead of the reference; spp, passes and gbuffer_samples do not apply then.
    peers: bool = False
    ladder: tuple[int, ...] = LADDER_SPP
    eevee: bool = True
    # Only the scene's geometry, no render (`aolab mesh`): spp, R, passes do not apply.
    mesh_only: bool = False
    # The animation frame rendered (scene.frame_set), or None: the file's current frame.
    frame: int | None = None
    # Render at this percentage of the scene's output size (after `resolution`), as the
    # add-on's Resolution does (`aolab advise`), or None: the output size itself.
    scale: int | None = None

    def key(self, blender: str | None = None) -> str:
        """The cache folder's name: the scene's name and a digest of everything the render
        depends on, the release of `blender` (default: find_blender's) included."""
        material = {"bridge": BRIDGE_VERSION, "scene": self.scene.content_sha256,
                    "spp": self.spp, "radius": self.radius, "passes": self.passes,
                    "resolution": self.resolution, "camera": self.camera,
                    "gbuffer_samples": self.gbuffer_samples}
        if self.peers:  # only then, so that the references' keys stay as they were
            material.update(peers=True, ladder=list(self.ladder), eevee=self.eevee)
        if self.mesh_only:  # the geometry depends on the scene, camera and size alone
            material = {"bridge": BRIDGE_VERSION, "scene": self.scene.content_sha256,
                        "resolution": self.resolution, "camera": self.camera,
                        "mesh_only": True}
        if self.frame is not None:  # only then, so that still renders keep their keys
            material["frame"] = self.frame
        if self.scale is not None:  # likewise
            material["scale"] = self.scale
        material["blender"] = blender_version(blender)
        digest = hashlib.sha256(json.dumps(material, sort_keys=True).encode()).hexdigest()
        return f"{self.key_prefix()}{digest[:KEY_DIGEST_CHARS]}"

    def key_prefix(self) -> str:
        """The cache folder's name without its digest: the scene's name, the kind and the
        frame. Cheap, where key() hashes, so that count_cached looks at most keys by name."""
        kind = "peers-" if self.peers else "mesh-" if self.mesh_only else ""
        frame = "" if self.frame is None else f"f{self.frame:04d}-"
        return f"{files.file_name_for(self.scene.name)}-{kind}{frame}"

    def result_files(self, folder: Path) -> list[Path]:
        """The files a finished render leaves in its folder (the JSON last)."""
        if self.mesh_only:
            return [folder / RESULT_MESH, folder / RESULT_MESH_JSON]
        if self.peers:
            return sorted(folder.glob("*.exr")) + [folder / PEERS_JSON]
        mesh = [folder / RESULT_MESH, folder / RESULT_MESH_JSON] if "mesh" in self.passes else []
        return [folder / RESULT_EXR, *mesh, folder / RESULT_JSON]


def make_plan(scene: Scene, *, spp: int | None = None, radius: float | None = None,
              methods: list[str] | None = None, passes: list[str] | None = None,
              resolution: tuple[int, int] | None = None, camera: str | None = None,
              gbuffer_samples: int = 1, scale: int | None = None) -> Plan:
    """What to render: explicit arguments first, then the scene's manifest, then defaults.
    Passes follow from the methods (all registered ones by default) and the manifest's
    effects unless given explicitly. ``scale``: a percentage of the output size, 1 to 100
    (Plan.scale)."""
    m = scene.manifest
    if passes is None:
        names = aolab.methods() if methods is None else methods
        infos = [aolab.method_info(n) for n in names]  # ValueError for an unknown name
        passes = required_passes(infos, m.get("effects", []), sequence="frames" in m)
    else:
        passes = parse_passes(",".join(passes))
    spp = spp if spp is not None else int(m.get("spp", 1024))
    radius = radius if radius is not None else m.get("radius")
    if radius is not None and not radius > 0:
        raise ReferenceError(f"radius must be > 0, got {radius}")
    if spp < 1:
        raise ReferenceError(f"spp must be >= 1, got {spp}")
    if resolution is None and m.get("resolution"):
        resolution = tuple(m["resolution"])
    if resolution is not None:
        resolution = check_resolution(resolution)
    if scale is not None and not (isinstance(scale, int) and 1 <= scale <= 100):
        raise ReferenceError(f"scale must be a percentage, an integer in [1, 100], got {scale!r}")
    return Plan(scene, spp, radius, passes, resolution, camera or m.get("camera"), gbuffer_samples,
                scale=scale)


def complete_result(folder: Path, plan: Plan) -> bool:
    """Whether ``folder`` holds every file of ``plan``'s result, none empty, and a sidecar that
    reads as one."""
    try:
        paths = plan.result_files(folder)
        side = json.loads(files.read_text(paths[-1], "cached sidecar"))
        return (all(files.regular_file(f, "cached result").stat().st_size > 0
                    for f in paths[:-1]) and "scene_hash" in side)
    except (OSError, ValueError):
        return False


def verified_result(folder: Path, plan: Plan) -> bool:
    """Whether ``folder`` is a complete result (complete_result) whose files still have the
    SHA-256 recorded when it was rendered (files.write_checksums). A changed or damaged entry
    is reported on stderr and is not a result: the caller renders it again. An entry from
    before the checksums has them recorded now, once (docs/scale_out.md, "Security")."""
    if not complete_result(folder, plan):
        return False
    names = [f.name for f in plan.result_files(folder)]
    try:
        if files.read_checksums(folder) is None:
            files.write_checksums(folder, names)
            return True
    except (OSError, ValueError):
        pass   # unreadable or malformed: checksum_mismatch says so
    why = files.checksum_mismatch(folder, names)
    if why is None:
        return True
    print(f"aolab: warning: cache entry {folder}: {why}; not used, rendering it again",
          file=sys.stderr, flush=True)
    return False


def cached_result(cache: Path, plan: Plan, blender: str | None = None) -> Path | None:
    folder = cache / plan.key(blender)
    return folder if verified_result(folder, plan) else None


def progress_bar(enabled: bool, desc: str):
    """The tqdm bar render drives when its ``progress`` is True (None when tqdm is
    missing or ``enabled`` is False)."""
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=0, desc=desc, unit="spp", dynamic_ncols=True, leave=False)


class Stopped(Exception):
    """A render stopped because its caller asked (render's ``should_stop``)."""


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
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir()
    s = plan.scene
    # --python-exit-code: a Python error outside the bridge's own handler (an import that
    # fails, say) ends Blender with 1 instead of its usual 0
    cmd = [blender, "-b", "--factory-startup", "-noaudio", "--disable-autoexec",
           "--python-exit-code", "1"]
    if plan.peers and plan.eevee:
        cmd = _xvfb() + cmd  # EEVEE needs an OpenGL context even with -b (docs/blender_facts.md)
    if s.kind == "blend":
        cmd.append(str(s.path))
    extra = {"source": recorded_source(s.path), "scene_name": s.name,
             "source_sha256": s.content_sha256, "manifest": s.manifest}
    out = tmp if plan.peers else tmp / (RESULT_MESH if plan.mesh_only else RESULT_EXR)
    cmd += ["--python", str(bridge_script()), "--", "--scene", str(s.path), "--kind", s.kind,
            "--out", str(out), "--spp", str(plan.spp),
            "--gbuffer-samples", str(plan.gbuffer_samples), "--passes", ",".join(plan.passes),
            "--extra", json.dumps(extra)]
    if plan.radius is not None:
        cmd += ["--radius", repr(float(plan.radius))]
    if plan.resolution:
        cmd += ["--resolution", f"{plan.resolution[0]}x{plan.resolution[1]}"]
    if plan.camera:
        cmd += ["--camera", plan.camera]
    if plan.frame is not None:
        cmd += ["--frame", str(plan.frame)]
    if plan.scale is not None:
        cmd += ["--scale", str(plan.scale)]
    if plan.peers:
        cmd += ["--peers", "--ladder", ",".join(str(v) for v in plan.ladder) or "none"]
        if not plan.eevee:
            cmd.append("--no-eevee")
    if plan.mesh_only:
        cmd.append("--mesh-only")

    bar = progress_bar(progress, s.name) if isinstance(progress, bool) else progress
    tail, error = [], None
    try:
        env = dict(os.environ, **{PACKAGE_PATH_ENV: package_path()})
        proc = subprocess.Popen(_die_with_parent(cmd), stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, stdin=subprocess.DEVNULL,
                                env=env)
        stage = ""
        for line in proc.stdout:
            if should_stop is not None and should_stop():
                raise Stopped(f"{s.name}: stopped")
            line = line.rstrip("\n")
            tail = (tail + [line])[-40:]
            if line.startswith("AOLAB_STAGE "):
                stage = line.split(" ", 1)[1]
                if bar is not None:
                    bar.set_description(f"{s.name}: {stage}")
            elif line.startswith("AOLAB_ERROR "):
                error = line.split(" ", 1)[1]
            elif bar is not None and (m := _SAMPLE_LINE.search(line)):
                done, total = int(m.group(1)), int(m.group(2))
                if bar.total != total:
                    bar.reset(total=total)
                bar.n = done
                bar.refresh()
        rc = proc.wait()
        if rc != 0 or error:
            raise ReferenceError(f"{s.name}: " + (error or "Blender failed:\n" + "\n".join(tail)))
        if not complete_result(tmp, plan):   # never an entry without its files
            raise ReferenceError(f"{s.name}: Blender exited without writing the result:\n"
                                 + "\n".join(tail))
        files.write_checksums(tmp, [f.name for f in plan.result_files(tmp)])
        if final.exists():  # a concurrent run finished first; keep one
            shutil.rmtree(final)
        os.replace(tmp, final)
        return final, False
    finally:
        if bar is not None:
            bar.close()
        if 'proc' in locals() and proc.poll() is None:
            proc.kill()
            proc.wait()
        shutil.rmtree(tmp, ignore_errors=True)


def find_by_content(cache: Path, *, scene_hash: str, size: tuple[int, int],
                    radius: float | None = None, spp: int | None = None,
                    passes: tuple[str, ...] = ()) -> Path | None:
    """The newest render in ``cache`` of this scene content (the ``scene_hash`` of its sidecar:
    the add-on's export/scene_record.content_hash, which a re-saved, unchanged file keeps) at this
    size, and R, samples, with these passes when given; or None. The cache's own keys are
    the file's bytes (Plan.key): this finds a render whichever file or tool made it."""
    best, best_time = None, -1.0
    cache = Path(cache)
    if not cache.is_dir():
        return None
    for side_path in cache.glob(f"[!.]*/{RESULT_JSON}"):
        try:
            side = json.loads(files.read_text(side_path, "cached sidecar"))
            if not side_path.with_name(RESULT_EXR).exists():
                continue
        except (OSError, ValueError):
            continue
        if side.get("scene_hash") != scene_hash:
            continue
        if (side.get("width"), side.get("height")) != tuple(size):
            continue
        if radius is not None and side.get("ao_distance") != radius:
            continue
        if spp is not None and side.get("samples") != spp:
            continue
        if not set(passes) <= set(side.get("passes", ())):
            continue
        mtime = side_path.stat().st_mtime
        if mtime > best_time:
            best, best_time = side_path.parent, mtime
    return best


def _die_with_parent(cmd: list[str]) -> list[str]:
    """cmd run under util-linux's `setpriv --pdeathsig KILL` where it exists (Linux): if this
    process dies (a Dask worker killed, `kill -9`), the kernel kills Blender too, instead of
    leaving it rendering for nobody. Its temporary folder is then removed by the next render's
    clean-up (remove_stale_temporaries)."""
    setpriv = shutil.which("setpriv")
    return [setpriv, "--pdeathsig", "KILL", "--"] + cmd if setpriv else cmd


def _xvfb() -> list[str]:
    path = shutil.which("xvfb-run")
    if not path:
        raise ReferenceError("EEVEE needs xvfb-run for an OpenGL context: install the Debian "
                             "packages xvfb xauth libgl1-mesa-dri (scripts/install-deps.sh), or "
                             "pass --no-eevee")
    return [path, "-a", "-s", "-screen 0 1280x1024x24"]


def remove_stale_temporaries(cache: Path) -> None:
    """Temporary folders (`.<key>.tmp-<pid>`) of renders whose process no longer exists (a
    killed machine, SIGKILL) are removed; those of running renders are left alone."""
    for tmp in cache.glob(".*.tmp-*"):
        try:
            pid = int(tmp.name.rsplit("-", 1)[1])
            os.kill(pid, 0)
        except ProcessLookupError:
            shutil.rmtree(tmp, ignore_errors=True)
        except (ValueError, PermissionError):
            pass


def copy_result(plan: Plan, folder: Path, out: Path) -> None:
    """Copies the render's files to `out` (a folder), all put in place together
    (files.write_together): a full disk leaves the earlier files and no temporary."""
    out.mkdir(parents=True, exist_ok=True)
    files.write_together([(out / src.name, files.read_bytes(src, "cached result"))
                          for src in plan.result_files(folder)])
    scenes.write_folder_checksums(out)   # what the folder holds now, this render's included


def check_resolution(resolution, name: str = "resolution") -> tuple[int, int]:
    """(width, height) as integers in [MIN_RESOLUTION, MAX_RESOLUTION]; else a ValueError
    naming ``name`` and the value."""
    try:
        w, h = resolution
        ok = all(not isinstance(v, bool) and int(v) == v and
                 MIN_RESOLUTION <= v <= MAX_RESOLUTION for v in (w, h))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"{name} must be a width and a height, integers in "
                         f"[{MIN_RESOLUTION}, {MAX_RESOLUTION}] (Blender renders at least "
                         f"{MIN_RESOLUTION}x{MIN_RESOLUTION}), got {resolution!r}")
    return int(w), int(h)


def parse_resolution(text: str, name: str = "--resolution") -> tuple[int, int]:
    """``WxH``: width and height integers in [MIN_RESOLUTION, MAX_RESOLUTION], else a
    ValueError naming ``name`` and the text."""
    parts = str(text).strip().lower().split("x")
    if len(parts) == 2 and all(p.strip().isascii() and p.strip().isdigit() for p in parts):
        try:
            return check_resolution([int(p) for p in parts], name)
        except ValueError:
            pass
    raise ValueError(f"{name} must be WxH with integers in [{MIN_RESOLUTION}, "
                     f"{MAX_RESOLUTION}] (Blender renders at least "
                     f"{MIN_RESOLUTION}x{MIN_RESOLUTION}), got {text!r}")


#: Blender's frame range (scene.frame_current's hard limits in 3.4 and 4.x).
MAX_FRAME = 1048574
#: The most frames one --frames names, and the most references one command renders (every
#: scene's frames together). A reference costs at least Blender's start-up, a second or more,
#: so 100000 of them are days of a machine's time already: a larger request is a mistyped
#: range, refused before anything is planned or submitted.
MAX_FRAMES = 100000


def parse_frames(text: str, name: str = "--frames") -> list[int]:
    """``N``, ``S-E`` or ``S-E:STEP`` (E included, STEP >= 1; frames may be negative, as in
    Blender: ``-5--1``) -> the frame numbers; a ValueError naming ``name`` otherwise."""
    import re
    m = re.fullmatch(r"\s*(-?\d+)(?:\s*-\s*(-?\d+)(?:\s*:\s*(\d+))?)?\s*", str(text))
    if m:
        start = int(m.group(1))
        end = int(m.group(2)) if m.group(2) is not None else start
        step = int(m.group(3)) if m.group(3) is not None else 1
        if (step >= 1 and start <= end and -MAX_FRAME <= start and end <= MAX_FRAME
                and (end - start) // step < MAX_FRAMES):
            return list(range(start, end + 1, step))
    raise ValueError(f"{name} must be N, START-END or START-END:STEP with START <= END, STEP "
                     f">= 1, frames in [-{MAX_FRAME}, {MAX_FRAME}] and at most {MAX_FRAMES} of "
                     f"them, got {text!r}")


def manifest_frames(scene: Scene) -> list[int] | None:
    """The frames a sequence scene's manifest names ({"start", "end", "step"}), or None."""
    f = scene.manifest.get("frames")
    if f is None:
        return None
    try:
        return parse_frames(f"{int(f['start'])}-{int(f['end'])}:{int(f.get('step', 1))}")
    except (KeyError, TypeError, ValueError):
        raise ReferenceError(f"{scene.name}: manifest.json's \"frames\" must be {{\"start\": S, "
                             f"\"end\": E, \"step\": T}} with S <= E and T >= 1, got {f!r}") \
            from None


def per_frame(plans: list[Plan], frames: list[int] | None) -> list[Plan]:
    """One plan per frame of ``frames``, or of each scene's manifest frames when None; a still
    scene without frames keeps its one plan. More than MAX_FRAMES plans in all is a
    ReferenceError, raised before any is made."""
    each, total = [], 0
    for plan in plans:
        mine = frames if frames is not None else manifest_frames(plan.scene)
        each.append(mine)
        total += 1 if mine is None else len(mine)
        if total > MAX_FRAMES:
            raise ReferenceError(
                f"{len(plans)} scenes and their frames make more than {MAX_FRAMES} references, "
                "the most one `aolab reference` renders: split them over several commands "
                "(they share the cache)")
    out = []
    for plan, mine in zip(plans, each):
        if mine is None:
            out.append(plan)
        else:
            out += [dataclasses.replace(plan, frame=f) for f in mine]
    return out


def unit(plans: list[Plan]) -> str:
    """What the plans are, for a count: frames, scenes or references (a mix)."""
    framed = {p.frame is not None for p in plans}
    return "frames" if framed == {True} else "scenes" if framed == {False} else "references"


def count_cached(cache: Path, plans: list[Plan]) -> int:
    """How many of ``plans`` have a complete entry in ``cache`` (what a resume takes from it),
    whoever rendered them and whenever. One listing of the cache; a plan's key, a hash, is
    computed only when an entry bears its name and frame, so that counting 100000 frames of
    which few are rendered takes no time. The keys are this machine's: entries rendered by
    workers with another release of Blender are not counted."""
    try:
        names = [e.name for e in os.scandir(cache) if not e.name.startswith(".")]
    except OSError:
        return 0
    prefixes = {n[:-KEY_DIGEST_CHARS] for n in names}
    try:
        blender = find_blender()  # once, not once per key
    except ReferenceError:
        blender = None
    return sum(1 for p in plans
               if p.key_prefix() in prefixes and cached_result(cache, p, blender) is not None)


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


def command_plans(scenes: list[str], *, spp: int | None = None, radius: float | None = None,
                  methods: list[str] | None = None, passes: str | None = None,
                  resolution: str | None = None, camera: str | None = None,
                  gbuffer_samples: int = 1, peers: bool = False,
                  ladder: tuple[int, ...] | None = None, no_eevee: bool = False,
                  frames=None, follow_symlinks: bool = False) -> list[Plan]:
    """The plans of an `aolab reference` call (its options by name), every error raised
    before any render. The caller runs them here (run_plans) or on a cluster
    (aolab.render.cluster.run_plans); this module never imports the cluster."""
    size = parse_resolution(resolution) if resolution else None
    found = [resolve_scene(s, follow_symlinks) for s in scenes]  # every error before a render
    plans = [make_plan(s, spp=spp, radius=radius, methods=methods,
                       passes=passes.split(",") if passes else None,
                       resolution=size, camera=camera,
                       gbuffer_samples=gbuffer_samples) for s in found]
    if peers:
        ladder = ladder if ladder is not None else LADDER_SPP
        if not ladder and no_eevee:
            raise ReferenceError("--ladder none with --no-eevee leaves nothing to render")
        for plan in plans:
            plan.peers, plan.ladder, plan.eevee = True, ladder, not no_eevee
    if isinstance(frames, str):
        frames = parse_frames(frames)
    return per_frame(plans, frames)


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
        several = len({p.scene.name for p in plans}) > 1
        reads = {"the scene": sorted({p.scene.path for p in plans})}
        for plan in plans:
            folder = output_folder(self.out, plan, several)
            files.check_distinct(reads=reads, writes={"--out": [
                *plan.result_files(folder), folder / files.CHECKSUMS_NAME]})

    def cache_folder(self) -> Path:
        return Path(self.cache) if self.cache else default_cache()


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


def result_line(plan: Plan, folder: Path, how: str, out) -> str:
    """The line printed for a finished plan: what, how (cached, rendered in ...), its last
    file and where it was copied."""
    what = plan.scene.name + ("" if plan.frame is None else f" frame {plan.frame}")
    return (f"{what}: {how} -> {plan.result_files(folder)[-1]}"
            + (f" (copied to {out})" if out else ""))


def interrupted_line(done: int, plans: list[Plan], cache: Path, stopped: str = "") -> str:
    """The line printed on Ctrl-C: this run's count and the cache's as well (a render can
    finish between the last line printed and the interrupt, and frames of an earlier run are
    not rendered again), ``stopped`` saying what became of the running renders."""
    return (f"interrupted after {done} of {len(plans)} {unit(plans)} "
            f"({count_cached(cache, plans)} in the cache); {stopped}run the same command "
            "again to resume")


def run_plans(plans: list[Plan], delivery: Delivery) -> int:
    """Renders (or takes from the cache) each plan in turn, copying its files to
    ``delivery.out``; the exit status."""
    done = 0
    several = len({p.scene.name for p in plans}) > 1
    cache = delivery.cache_folder()
    out = delivery.out
    with terminate_as_interrupt():   # `kill` cleans up like Ctrl-C
        try:
            for plan in plans:
                t0 = time.perf_counter()
                folder, was_cached = render(plan, cache, force=delivery.force,
                                            progress=not delivery.quiet and sys.stderr.isatty())
                if out:
                    copy_result(plan, folder, output_folder(out, plan, several))
                # done before its line: an interrupt while it prints has it done all the same
                done += 1
                verb = "exported" if plan.mesh_only else "rendered"
                how = "cached" if was_cached else f"{verb} in {time.perf_counter() - t0:.1f} s"
                print(result_line(plan, folder, how, out))
        except KeyboardInterrupt:
            print(interrupted_line(done, plans, cache), file=sys.stderr)
            return 130
    return 0
