"""Motion vectors (no bpy): Cycles' Vector pass turned into AO Lab's motion convention, and
the `Motion` pass of a G-buffer EXR read back and checked (docs/conventions.md, "Motion
vectors"; docs/blender_facts.md, "The Vector pass").

AO Lab's motion is a float32 (H, W, 2) image in pixels: at pixel (i, j) it holds (dx, dy)
such that the surface point seen at the pixel centre (i + 0.5, j + 0.5) of the current frame
was at (i + 0.5 + dx, j + 0.5 + dy) in the previous frame, x to the right and y down (rows),
NaN on background.

Cycles' Vector pass (measured in Blender 3.4.1, motion blur off) holds four numbers in
pixels with y up: (X, Y) = position in the previous frame (frame - 1) minus position in this
one, (Z, W) = position in this frame minus position in the next (frame + 1); 0 on background.
So dx = X and dy = -Y.
"""

from __future__ import annotations

import json
import os

import numpy as np

from ..util import files
from . import exr
from .constants import BACKGROUND_DEPTH

#: The pass's name in a G-buffer EXR (<view layer>.Motion.X/Y, float32, AO Lab's convention:
#: not Blender's Vector pass, whose convention differs).
MOTION_PASS = "Motion"
MOTION_COMPONENTS = ("X", "Y")


def geometry_mask(depth: np.ndarray, background_depth: float = BACKGROUND_DEPTH) -> np.ndarray:
    """True where the depth is a surface: finite, > 0 and below ``background_depth``
    (docs/conventions.md)."""
    d = np.asarray(depth)
    with np.errstate(invalid="ignore"):
        return np.isfinite(d) & (d > 0) & (d < background_depth)


def from_cycles_vector(vector: np.ndarray, depth: np.ndarray,
                       background_depth: float = BACKGROUND_DEPTH) -> np.ndarray:
    """AO Lab's motion (H, W, 2) float32 from Cycles' Vector pass (H, W, 4) and the Depth
    pass (H, W) of the same render: dx = X, dy = -Y (Cycles' y points up), NaN on
    background."""
    v = np.asarray(vector, dtype=np.float32)
    d = np.asarray(depth)
    if d.ndim == 3 and d.shape[2] == 1:
        d = d[..., 0]
    if v.ndim != 3 or v.shape[2] != 4 or v.shape[:2] != d.shape:
        raise ValueError(f"the Vector pass must be (H, W, 4) with the depth's (H, W) = "
                         f"{d.shape}, got {v.shape}")
    motion = np.stack([v[..., 0], -v[..., 1]], axis=-1).astype(np.float32)
    motion[~geometry_mask(d, background_depth)] = np.nan
    return motion


def layer_prefix(channels: list[str]) -> str:
    """The view layer of a G-buffer EXR as its channel prefix ("ViewLayer." or ""): the first
    layer, in file order, with a Depth.Z channel, as aolab.load_gbuffer's reader chooses it."""
    for name in channels:
        if name == "Depth.Z" or name.endswith(".Depth.Z"):
            return name[: -len("Depth.Z")]
    return ""


def check_motion(motion: np.ndarray, depth: np.ndarray, background_depth: float,
                 what: str) -> np.ndarray:
    """``motion`` checked against the G-buffer's ``depth``: float32 (H, W, 2) with the depth's
    (H, W), finite wherever the depth is a surface; returned with NaN on background. Anything
    else is a ValueError naming ``what``."""
    m = np.asarray(motion)
    d = np.asarray(depth)
    if m.dtype != np.float32 or m.ndim != 3 or m.shape[2] != 2 or m.shape[:2] != d.shape[:2]:
        raise ValueError(f"{what}: motion must be float32 (H, W, 2) with the depth's (H, W) = "
                         f"{d.shape[:2]}, got {m.dtype} {m.shape}")
    surface = geometry_mask(d if d.ndim == 2 else d[..., 0], background_depth)
    bad = surface & ~np.isfinite(m).all(axis=-1)
    if bad.any():
        j, i = np.argwhere(bad)[0]
        raise ValueError(f"{what}: motion is not finite at {int(bad.sum())} surface pixels, "
                         f"first at (x={i}, y={j}): {m[j, i].tolist()}")
    out = m.copy()
    out[~surface] = np.nan
    return out


def read_motion(path, channels: list[str], depth: np.ndarray,
                background_depth: float) -> np.ndarray | None:
    """The Motion pass of the G-buffer EXR ``path`` (whose channel names are ``channels``
    and whose depth is ``depth``), checked (check_motion); None when the file has none. A
    pass with one of its two channels is a ValueError naming the file."""
    prefix = layer_prefix(channels)
    names = [f"{prefix}{MOTION_PASS}.{c}" for c in MOTION_COMPONENTS]
    present = [n for n in names if n in channels]
    if not present:
        return None
    if len(present) != len(names):
        raise ValueError(f"{path}: the {MOTION_PASS} pass has {present} but not "
                         f"{sorted(set(names) - set(present))}; channels found: {channels}")
    try:
        planes = exr.read_channels(path, names)
    except RuntimeError as e:
        raise ValueError(str(e)) from None
    return check_motion(np.stack([planes[n] for n in names], axis=-1), depth,
                        background_depth, str(path))


#: Largest relative depth difference between a committed G-buffer and the fresh render whose
#: Motion pass is added to it (add_motion_pass): a few float32 ulp, as `aolab bridge-check`
#: allows for the same scene.
SAME_DEPTH_RTOL = 1e-5


def add_motion_pass(target_exr, source_exr) -> dict:
    """Copies the Motion pass of ``source_exr`` (a fresh G-buffer render with motion, e.g. 1
    sample) into ``target_exr`` (a committed reference whose AO took hours), leaving every
    channel of the target as it was (half channels pass through float32 exactly), and adds
    "motion" to its sidecar's passes with ``motion_previous_frame``. Both files and their
    sidecars must be the same scene, frame, camera and size (scene_hash, frame and
    camera_to_world equal), and their depths must agree (same background, relative difference
    at most SAME_DEPTH_RTOL). The EXR and its sidecar are written together; the new sidecar is
    returned. Anything else is a ValueError naming the files."""
    target_json = os.path.splitext(str(target_exr))[0] + ".json"
    source_json = os.path.splitext(str(source_exr))[0] + ".json"
    target = files.json_object(files.read_bytes(target_json, "sidecar"), target_json, "sidecar")
    source = files.json_object(files.read_bytes(source_json, "sidecar"), source_json, "sidecar")
    for key in ("scene_hash", "frame", "width", "height", "camera_to_world"):
        if target.get(key) != source.get(key):
            raise ValueError(f"{source_exr} is not a render of {target_exr}: their {key} "
                             f"differ ({source.get(key)!r} against {target.get(key)!r})")
    if "motion" not in source.get("passes", []) or "motion_previous_frame" not in source:
        raise ValueError(f"{source_exr} has no motion pass (render it with --passes "
                         "depth,motion)")
    channels = exr.read_channels(target_exr)
    prefix = layer_prefix(list(channels))
    fresh = exr.read_channels(source_exr)
    fresh_prefix = layer_prefix(list(fresh))
    depth, fresh_depth = channels[prefix + "Depth.Z"], fresh[fresh_prefix + "Depth.Z"]
    surface = geometry_mask(depth, target.get("background_depth", BACKGROUND_DEPTH))
    if not np.array_equal(surface, geometry_mask(fresh_depth, source.get(
            "background_depth", BACKGROUND_DEPTH))):
        raise ValueError(f"{source_exr} sees background where {target_exr} sees a surface, or "
                         "the reverse: not the same render")
    worst = float(np.max(np.abs(fresh_depth[surface] / depth[surface] - 1), initial=0.0))
    if worst > SAME_DEPTH_RTOL:
        raise ValueError(f"the depths of {source_exr} and {target_exr} differ by {worst:.2g} "
                         f"relative (at most {SAME_DEPTH_RTOL} allowed): not the same render")
    motion = check_motion(np.stack([fresh[f"{fresh_prefix}{MOTION_PASS}.{c}"]
                                    for c in MOTION_COMPONENTS], -1), depth,
                          target.get("background_depth", BACKGROUND_DEPTH), str(source_exr))
    layers = []
    for pass_name, comps in exr.LAYER_COMPONENTS.items():
        names = [f"{prefix}{pass_name}.{c}" for c in comps]
        if pass_name != MOTION_PASS and all(n in channels for n in names):
            fmt = "float" if pass_name == "Depth" else "half"
            layers.append((pass_name, np.stack([channels[n] for n in names], -1), fmt))
    layers.append((MOTION_PASS, motion, "float"))
    kept = {f"{prefix}{p}.{c}" for p, _, _ in layers for c in exr.LAYER_COMPONENTS[p]}
    if set(channels) - kept:
        raise ValueError(f"{target_exr} has channels AO Lab does not write: "
                         f"{sorted(set(channels) - kept)}")
    passes = [p for p in target.get("passes", []) if p not in ("motion", "ao")]
    sidecar = {**target, "passes": passes + ["motion"] + (
        ["ao"] if "ao" in target.get("passes", []) else []),
        "motion_previous_frame": source["motion_previous_frame"],
        "motion_render": {"blender_version": source.get("blender_version"),
                          "gbuffer_samples": source.get("render", {}).get("gbuffer_samples")}}
    files.write_together([
        (target_exr, exr.encode_multilayer(str(target_exr), layers,
                                           view_layer=prefix.rstrip("."))),
        (target_json, json.dumps(sidecar, indent=1).encode())])
    return sidecar
