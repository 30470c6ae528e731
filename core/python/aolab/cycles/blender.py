"""The Blender process: finding Blender and its release, the bridge script it runs
(blender_addon/aolab_blender/export/batch.py), and running it in the background, under xvfb-run when
EEVEE needs an OpenGL context, dying with its parent, its progress lines read as it prints
them. Blender always starts with --factory-startup and --disable-autoexec, so a .blend from
elsewhere never runs its own scripts. Knows nothing of plans or the cache (aolab.cycles.plan,
aolab.cycles.cache)."""

from __future__ import annotations

import functools
import os
import re
import shutil
import subprocess
from pathlib import Path

#: Environment variable naming the folder that holds this aolab package, for Blender's
#: Python: batch.py puts it first on sys.path, so Blender uses the same build.
PACKAGE_PATH_ENV = "AOLAB_PACKAGE_PATH"
_SAMPLE_LINE = re.compile(r"Sample (\d+)/(\d+)")
#: The lines of Blender's output kept for the message when it fails.
TAIL_LINES = 40


class ReferenceError(Exception):
    """A problem the user can act on; its message says what to do."""


class Stopped(Exception):
    """A render stopped because its caller asked (run_bridge's ``should_stop``)."""


def find_blender() -> str:
    """The Blender executable: $AOLAB_BLENDER, else `blender` on PATH; a ReferenceError saying
    how to install it otherwise."""
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
    parent of aolab/, two levels above this module (aolab/cycles/blender.py). Blender 4.2
    and later ignore PYTHONPATH, so this is the only way their Python finds this build."""
    return str(Path(__file__).resolve().parents[2])


def die_with_parent(cmd: list[str]) -> list[str]:
    """cmd run under util-linux's `setpriv --pdeathsig KILL` where it exists (Linux): if this
    process dies (a Dask worker killed, `kill -9`), the kernel kills Blender too, instead of
    leaving it rendering for nobody. Its temporary folder is then removed by the next render's
    clean-up (aolab.cycles.cache.remove_stale_temporaries)."""
    setpriv = shutil.which("setpriv")
    return [setpriv, "--pdeathsig", "KILL", "--"] + cmd if setpriv else cmd


def xvfb() -> list[str]:
    """The xvfb-run prefix that gives Blender an OpenGL context (EEVEE needs one even with
    -b: docs/blender_facts.md); a ReferenceError saying what to install without it."""
    path = shutil.which("xvfb-run")
    if not path:
        raise ReferenceError("EEVEE needs xvfb-run for an OpenGL context: install the Debian "
                             "packages xvfb xauth libgl1-mesa-dri (scripts/install-deps.sh), or "
                             "pass --no-eevee")
    return [path, "-a", "-s", "-screen 0 1280x1024x24"]


def bridge_command(blender: str, bridge_args: list[str], *, blend: Path | None = None,
                   opengl: bool = False) -> list[str]:
    """The command that runs the bridge script with ``bridge_args`` in `blender` in the
    background: on the .blend ``blend`` if given (else an empty factory file), under xvfb-run
    when ``opengl``."""
    # --python-exit-code: a Python error outside the bridge's own handler (an import that
    # fails, say) ends Blender with 1 instead of its usual 0
    cmd = [blender, "-b", "--factory-startup", "-noaudio", "--disable-autoexec",
           "--python-exit-code", "1"]
    if opengl:
        cmd = xvfb() + cmd
    if blend is not None:
        cmd.append(str(blend))
    return cmd + ["--python", str(bridge_script()), "--", *bridge_args]


def run_bridge(cmd: list[str], name: str, bar=None, should_stop=None) -> list[str]:
    """Runs ``cmd`` (bridge_command) to its end, this package first on Blender's sys.path,
    driving ``bar`` (tqdm's set_description, reset, n, total and refresh; None: no progress)
    from the lines Blender prints; returns the last TAIL_LINES of them. Blender's failure or
    the bridge's AOLAB_ERROR line is a ReferenceError naming the scene ``name``;
    ``should_stop()``, asked at each line, stops it with Stopped. Blender never outlives the
    call."""
    env = dict(os.environ, **{PACKAGE_PATH_ENV: package_path()})
    proc = subprocess.Popen(die_with_parent(cmd), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, stdin=subprocess.DEVNULL,
                            env=env)
    tail, error = [], None
    try:
        for line in proc.stdout:
            if should_stop is not None and should_stop():
                raise Stopped(f"{name}: stopped")
            line = line.rstrip("\n")
            tail = (tail + [line])[-TAIL_LINES:]
            error = _follow(line, name, bar) or error
        rc = proc.wait()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    if rc != 0 or error:
        raise ReferenceError(f"{name}: " + (error or "Blender failed:\n" + "\n".join(tail)))
    return tail


def _follow(line: str, name: str, bar) -> str | None:
    """One line of Blender's output: a stage or sample count shown on ``bar``; the bridge's
    error message if the line is one."""
    if line.startswith("AOLAB_STAGE "):
        if bar is not None:
            bar.set_description(f"{name}: {line.split(' ', 1)[1]}")
    elif line.startswith("AOLAB_ERROR "):
        return line.split(" ", 1)[1]
    elif bar is not None and (m := _SAMPLE_LINE.search(line)):
        done, total = int(m.group(1)), int(m.group(2))
        if bar.total != total:
            bar.reset(total=total)
        bar.n = done
        bar.refresh()
    return None
