"""The compiled module imports and computes inside Blender's embedded Python (Debian's
Blender runs on /usr/bin/python3: 3.11 with Blender 3.4 on Debian 12, 3.13 with Blender 4.3 on
Debian 13, and the module is built for it). Skips with a reason where Blender is absent."""
import os
import shutil
import subprocess

import pytest

import aolab

BLENDER = shutil.which("blender")

pytestmark = pytest.mark.blender


@pytest.mark.skipif(BLENDER is None, reason="Blender is not installed (apt-get install blender)")
def test_aolab_computes_inside_blender(tmp_path):
    package_root = os.path.dirname(os.path.dirname(aolab.__file__))
    script = tmp_path / "probe.py"
    script.write_text(
        "import sys, aolab\n"
        "g = aolab.analytic_scene('plane', 32, 18)\n"
        "ao = aolab.compute('hbao', g, radius=1.0)\n"
        "print('AOLAB_OK', aolab.__file__, float(ao.min()))\n"
    )
    env = dict(os.environ, PYTHONPATH=package_root)
    # --python-use-system-env lets Blender's Python honour PYTHONPATH, so this test checks
    # the freshly built package; after scripts/setup.sh a .pth file does the same for every
    # Blender session.
    res = subprocess.run([BLENDER, "-b", "--factory-startup", "-noaudio",
                          "--python-use-system-env", "--python-exit-code", "1",
                          "--python", str(script)],
                         capture_output=True, text=True, env=env, timeout=120)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    line = next(out for out in res.stdout.splitlines() if out.startswith("AOLAB_OK"))
    assert line.startswith("AOLAB_OK " + package_root)
    assert line.endswith(" 1.0")
