"""The cache of Blender's results: one folder per plan, named by its key (Plan.key: the scene's
content, camera, R, samples, passes, resolution and Blender's release). An entry is written to
a temporary folder and renamed into place (aolab.cycles.run.render), so an interrupted render
leaves nothing half-written and a batch resumes where it stopped; an entry is used only while
its files still have the checksums recorded when it was rendered."""

from __future__ import annotations

import json
import os
import shutil
import sys
from pathlib import Path

from ..bridge.constants import RESULT_EXR, RESULT_JSON
from ..util import files
from .blender import ReferenceError, find_blender
from .plan import KEY_DIGEST_CHARS, Plan


def default_cache() -> Path:
    """$AOLAB_CACHE, else aolab/references in the user's cache folder ($XDG_CACHE_HOME or
    ~/.cache)."""
    if os.environ.get("AOLAB_CACHE"):
        return Path(os.environ["AOLAB_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "aolab" / "references"


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
    """The verified entry of ``plan`` in ``cache`` (its key for `blender`), or None."""
    folder = cache / plan.key(blender)
    return folder if verified_result(folder, plan) else None


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
        if not _matches(side, scene_hash, size, radius, spp, passes):
            continue
        mtime = side_path.stat().st_mtime
        if mtime > best_time:
            best, best_time = side_path.parent, mtime
    return best


def _matches(side: dict, scene_hash: str, size, radius, spp, passes) -> bool:
    """Whether a sidecar is a render of this content, size, and R, samples and passes when
    given (find_by_content)."""
    return (side.get("scene_hash") == scene_hash
            and (side.get("width"), side.get("height")) == tuple(size)
            and (radius is None or side.get("ao_distance") == radius)
            and (spp is None or side.get("samples") == spp)
            and set(passes) <= set(side.get("passes", ())))


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
