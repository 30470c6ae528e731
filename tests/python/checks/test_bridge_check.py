"""`aolab bridge-check` (aolab/checks/bridge_check.py): its comparison on known differences,
the scenes it covers and its document block. The check itself, on the committed scenes with
the Blender at hand, is `aolab bridge-check` (docs/blender_bridge.md);
tests/python/bridge/test_bridge.py renders with Blender."""
import copy
from dataclasses import dataclass, field

import numpy as np
import pytest

from aolab.checks import bridge_check
from aolab.study.compare import find_scenes_dir
from aolab.util.arguments import MAX_SAMPLES, int_list_option


@dataclass
class Fake:
    """What compare() reads of an aolab.GBuffer."""
    depth: np.ndarray
    normal: np.ndarray
    reference: np.ndarray
    sidecar: dict = field(default_factory=dict)

    @property
    def height(self):
        return self.depth.shape[0]

    @property
    def width(self):
        return self.depth.shape[1]

    def valid_mask(self):
        return self.depth < 1e9


def scene(seed=0, shape=(64, 96)):
    rng = np.random.default_rng(seed)
    depth = rng.uniform(1, 50, shape).astype(np.float32)
    depth[:4] = 1e10                                      # a background band
    normal = rng.normal(size=shape + (3,)).astype(np.float32)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    ao = rng.uniform(0.2, 1, shape).astype(np.float32)
    side = {"width": shape[1], "height": shape[0], "fx": 80.0, "fy": 80.0, "cx": 48.0,
            "cy": 32.0, "camera_to_world": np.eye(4).tolist(), "clip_start": 0.1,
            "clip_end": 100.0, "scene_hash": "abc", "blender_version": "3.4.1"}
    return Fake(depth, normal, ao, side)


def noisy(g, sigma, seed, bias=0.0):
    out = copy.deepcopy(g)
    rng = np.random.default_rng(seed)
    out.reference = np.clip(g.reference + bias + rng.normal(0, sigma, g.reference.shape),
                            0, 1).astype(np.float32)
    return out


def test_identical_exports_agree_exactly():
    g = scene()
    r = bridge_check.compare(g, noisy(g, 0.02, 1), noisy(g, 0.02, 2).reference)
    assert r["intrinsics_max_difference"] == 0 and r["scene_hash_equal"]
    assert r["depth_identical"] == 1 and r["normal_identical"] == 1
    assert r["depth_max_relative"] == 0 and r["coverage_changed"] == 0
    assert r["intrinsics_agree"] and r["gbuffer_agrees"] and r["ao_agrees"]
    assert r["mae_over_rung"] == pytest.approx(1, abs=0.05)   # equal noise, equal MAE
    assert r["pixels"] == 60 * 96


def test_each_difference_is_caught():
    g = scene()
    moved = copy.deepcopy(g)
    moved.depth = np.where(g.depth < 1e9, g.depth * (1 + 1e-3), g.depth).astype(np.float32)
    assert not bridge_check.compare(g, moved, None)["gbuffer_agrees"]
    few = copy.deepcopy(g)                               # a few silhouette pixels: judged alike
    few.depth[10, :5] *= 1.5
    few.normal[11, :5] *= -1
    r = bridge_check.compare(g, few, None)
    assert r["gbuffer_agrees"] and r["depth_max_relative"] == pytest.approx(0.5, rel=1e-6)
    assert r["normal_max_angle_deg"] == pytest.approx(180, abs=0.01)
    turned = copy.deepcopy(g)
    turned.normal = np.roll(g.normal, 1, axis=-1)
    assert not bridge_check.compare(g, turned, None)["gbuffer_agrees"]
    covered = copy.deepcopy(g)
    covered.depth[:4] = 5.0                               # the background became surface
    r = bridge_check.compare(g, covered, None)
    assert r["coverage_changed"] == 4 * 96 and not r["gbuffer_agrees"]
    other = copy.deepcopy(g)
    other.sidecar["fx"] = 80.001
    assert not bridge_check.compare(g, other, None)["intrinsics_agree"]
    biased = noisy(g, 0.02, 1, bias=-0.01)                # darker everywhere: not noise
    assert not bridge_check.compare(g, biased, None)["ao_agrees"]
    last_ulp = copy.deepcopy(g)                           # a float's last bit: agrees
    last_ulp.depth = np.nextafter(g.depth, np.float32(np.inf)).astype(np.float32)
    r = bridge_check.compare(g, last_ulp, None)
    assert r["depth_identical"] == 0 and r["gbuffer_agrees"]


def test_every_committed_reference_is_covered():
    items = bridge_check.committed_scenes(find_scenes_dir(), [])
    labels = [label for label, _, _ in items]
    for still in ("analytic", "room", "street"):
        assert still in labels
    assert [f for label, _, f in items if label.startswith("flythrough@")] == list(range(1, 9))
    with pytest.raises(ValueError, match="nowhere"):
        bridge_check.committed_scenes(find_scenes_dir(), ["nowhere"])


def test_doc_block_per_release(tmp_path):
    doc = tmp_path / "d.md"
    doc.write_text("# Bridge\n\ntext\n")
    bridge_check.update_doc(doc, "4.3", "table one")
    bridge_check.update_doc(doc, "3.4", "table two")
    bridge_check.update_doc(doc, "4.3", "table three")
    text = doc.read_text()
    assert text.startswith("# Bridge\n\ntext\n")
    assert "table one" not in text and text.count("table three") == 1
    assert text.index("bridge-check 4.3") < text.index("bridge-check 3.4")


def test_ladder_none_and_errors():
    import argparse
    parse_ladder = int_list_option("--ladder", MAX_SAMPLES)   # aolab reference's and batch.py's
    assert parse_ladder("none") == () and parse_ladder("1,4") == (1, 4)
    for bad in ("", "0,4", "a", "1,,4", str(MAX_SAMPLES + 1)):
        with pytest.raises(argparse.ArgumentTypeError, match="--ladder"):
            parse_ladder(bad)


def test_command_line_errors_name_the_value():
    import subprocess
    import sys
    for args, said in [(["nowhere"], "no committed reference for nowhere"),
                       (["--spp", "0"], "--spp must be an integer in [1, 65536], got 0")]:
        r = subprocess.run([sys.executable, "-m", "aolab", "bridge-check", *args],
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 2 and said in r.stderr and "Traceback" not in r.stderr, r.stderr
