"""What the tests that run Blender share: where Blender and the test scenes are, its release,
the EEVEE peer it renders, the skip mark without it, and running a tests/blender script or
`aolab reference` as a test does."""
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import aolab

ROOT = Path(__file__).resolve().parents[3]
TINY = ROOT / "tests" / "data" / "tiny_scene.py"
BLENDER = shutil.which("blender")


def _blender_version() -> tuple[int, int]:
    """(major, minor) of the Blender on PATH, (0, 0) without one."""
    if BLENDER is None:
        return (0, 0)
    out = subprocess.run([BLENDER, "-b", "--factory-startup", "-noaudio", "--version"],
                         capture_output=True, text=True, timeout=60).stdout
    found = re.search(r"^Blender (\d+)\.(\d+)", out, re.M)
    return (int(found[1]), int(found[2])) if found else (0, 0)


BLENDER_VERSION = _blender_version()


def blender_spy(folder: Path) -> tuple[Path, Path]:
    """(a Blender, a mark): the Blender answers --version as the real one does (the release is
    part of every cache key) and, asked for anything else, leaves the mark and fails. Serving
    a cached result with it proves that nothing was rendered."""
    mark, spy = folder / "rendered-again", folder / "blender"
    spy.write_text(f'#!/bin/sh\ncase " $* " in *" --version "*) exec {BLENDER} "$@" ;; esac\n'
                   f'touch {mark}\nexit 1\n')
    spy.chmod(0o755)
    return spy, mark


#: The name of this Blender's EEVEE peer: GTAO before 4.2, EEVEE Next from 4.2 on.
EEVEE_PEER = "eevee_next" if BLENDER_VERSION >= (4, 2) else "eevee_gtao"
needs_blender = pytest.mark.skipif(BLENDER is None, reason="Blender is not installed "
                                   "(scripts/install-deps.sh installs it)")


def checkout_env() -> dict:
    """Blender's environment for tests/blender scripts: the aolab this test imports first on
    its path (tests/blender/common.py use_checkout, as aolab.cycles.blender does for batch.py)."""
    return dict(os.environ, AOLAB_PACKAGE_PATH=str(Path(aolab.__file__).resolve().parents[1]))


def blender_check(script: str, *args: str) -> dict:
    """The RESULT line (JSON) of tests/blender/``script`` run in Blender with ``args``."""
    res = subprocess.run([BLENDER, "-b", "--factory-startup", "-noaudio", "--python-exit-code",
                          "1", "--python", str(ROOT / "tests" / "blender" / script), "--", *args],
                         capture_output=True, text=True, timeout=600, env=checkout_env())
    lines = [line for line in res.stdout.splitlines() if line.startswith("RESULT ")]
    assert res.returncode == 0 and lines, res.stdout[-3000:] + res.stderr[-3000:]
    return json.loads(lines[-1][len("RESULT "):])


def aolab_reference(*args, env=None, check=True):
    """``aolab reference --quiet *args`` in a child process (its exit status 0 if ``check``)."""
    res = subprocess.run([sys.executable, "-m", "aolab", "reference", "--quiet", *args],
                         capture_output=True, text=True, env=env, timeout=900)
    if check:
        assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    return res
