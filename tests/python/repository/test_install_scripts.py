"""scripts/install.sh and scripts/uninstall.sh, run for real into a scratch prefix
(AOLAB_INSTALL_PREFIX) instead of /usr/local."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
SITE = f"lib/python3.{sys.version_info.minor}/dist-packages"


def run_script(name, prefix, *args):
    env = dict(os.environ, AOLAB_INSTALL_PREFIX=str(prefix))
    return subprocess.run(["bash", str(ROOT / "scripts" / name), *args], env=env,
                          capture_output=True, text=True, check=True)


def fake_build(folder):
    (folder / "python" / "aolab").mkdir(parents=True)
    return folder


def test_install_writes_pth_and_command_then_uninstall_removes_them(tmp_path):
    prefix, build = tmp_path / "prefix", fake_build(tmp_path / "build")
    out = run_script("install.sh", prefix, str(build))
    pth, command = prefix / SITE / "aolab.pth", prefix / "bin" / "aolab"
    assert pth.read_text().strip() == str(build / "python")
    assert os.access(command, os.X_OK) and "-m aolab" in command.read_text()
    assert "REPLACING" not in out.stdout and "uninstall.sh" in out.stdout
    out = run_script("uninstall.sh", prefix)
    assert not pth.exists() and not command.exists()
    assert "removing" in out.stdout
    assert "nothing" in run_script("uninstall.sh", prefix).stdout


def test_a_second_checkout_says_it_replaces_the_first(tmp_path):
    prefix = tmp_path / "prefix"
    first, second = fake_build(tmp_path / "one"), fake_build(tmp_path / "two")
    run_script("install.sh", prefix, str(first))
    assert "REPLACING" not in run_script("install.sh", prefix, str(first)).stdout  # same one
    out = run_script("install.sh", prefix, str(second))
    assert f"REPLACING the AO Lab installed from {first / 'python'}" in out.stdout
    assert (prefix / SITE / "aolab.pth").read_text().strip() == str(second / "python")


def test_uninstall_leaves_a_foreign_aolab_command(tmp_path):
    prefix = tmp_path / "prefix"
    (prefix / "bin").mkdir(parents=True)
    foreign = prefix / "bin" / "aolab"
    foreign.write_text("#!/bin/sh\necho someone else's tool\n")
    out = run_script("uninstall.sh", prefix)
    assert foreign.exists() and "not installed by AO Lab" in out.stderr


def test_install_refuses_a_folder_without_a_build(tmp_path):
    with pytest.raises(subprocess.CalledProcessError) as failure:
        run_script("install.sh", tmp_path / "prefix", str(tmp_path))
    assert failure.value.returncode == 2 and "scripts/build.sh" in failure.value.stderr
