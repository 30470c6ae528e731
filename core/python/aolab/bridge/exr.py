"""Reading Blender's multilayer EXRs and writing the merged G-buffer + AO reference (no bpy;
OpenImageIO's and numpy's Python modules, which import in Blender and in /usr/bin/python3).

The merged file is what aolab.load_gbuffer reads (docs/file_formats.md): Depth.Z float32,
Normal.X/Y/Z (view space), AO.R/G/B, DiffCol.R/G/B, Emit.R/G/B as half, zip-compressed.
"""

from __future__ import annotations

import os

import numpy as np
import OpenImageIO as oiio


def read_channels(path: str) -> dict[str, np.ndarray]:
    """All channels of an EXR by full name, as float32 (H, W) arrays, row 0 at the top."""
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise RuntimeError(f"cannot open {path}: {oiio.geterror()}")
    try:
        spec = inp.spec()
        pixels = inp.read_image(0, 0, 0, spec.nchannels, "float")
        if pixels is None:
            raise RuntimeError(f"cannot read {path}: {inp.geterror()}")
        pixels = np.asarray(pixels, dtype=np.float32).reshape(spec.height, spec.width,
                                                              spec.nchannels)
        return {name: pixels[..., i].copy() for i, name in enumerate(spec.channelnames)}
    finally:
        inp.close()


def find_pass(channels: dict[str, np.ndarray], pass_name: str, components) -> np.ndarray | None:
    """The (H, W, C) array of pass `pass_name` (e.g. Depth with ('Z',)) from a Blender EXR,
    whatever the view-layer prefix; None if absent."""
    for name in channels:
        if name.endswith(f"{pass_name}.{components[0]}"):
            prefix = name[: -len(f"{pass_name}.{components[0]}")]
            try:
                return np.stack([channels[f"{prefix}{pass_name}.{c}"] for c in components], -1)
            except KeyError:
                continue
    return None


def write_multilayer(path: str, layers: list[tuple[str, np.ndarray, str]],
                     view_layer: str = "ViewLayer") -> None:
    """Writes (pass name, (H, W, C) array, "float"|"half") layers with channel names
    `<view_layer>.<pass>.<component>` atomically (temporary file + rename)."""
    names, formats, planes = [], [], []
    components = {"Depth": "Z", "Normal": "XYZ", "AO": "RGB", "DiffCol": "RGB", "Emit": "RGB"}
    for pass_name, data, fmt in layers:
        comps = components[pass_name]
        data = data.reshape(data.shape[0], data.shape[1], -1)
        for i, c in enumerate(comps):
            names.append(f"{view_layer}.{pass_name}.{c}")
            formats.append(oiio.TypeFloat if fmt == "float" else oiio.TypeHalf)
            planes.append(data[..., i])
    _write(path, names, formats, planes)


def write_gray(path: str, image: np.ndarray) -> None:
    """Writes an (H, W) image as a one-channel ("Y") half-float EXR, atomically: the format
    of the comparison peers (docs/comparison.md)."""
    _write(path, ["Y"], [oiio.TypeHalf], [np.asarray(image, dtype=np.float32)])


def _write(path: str, names: list[str], formats: list, planes: list[np.ndarray]) -> None:
    """Zip-compressed EXR with the given channels, via a temporary file and a rename."""
    pixels = np.ascontiguousarray(np.stack(planes, -1), dtype=np.float32)
    h, w, n = pixels.shape
    spec = oiio.ImageSpec(w, h, n, oiio.TypeFloat)
    spec.channelnames = tuple(names)
    spec.channelformats = tuple(formats)
    spec.attribute("compression", "zip")
    tmp = f"{path}.tmp-{os.getpid()}.exr"
    out = oiio.ImageOutput.create(tmp)
    if out is None:
        raise RuntimeError(f"cannot create {path}: {oiio.geterror()}")
    try:
        if not out.open(tmp, spec) or not out.write_image(pixels):
            raise RuntimeError(f"cannot write {path}: {out.geterror()}")
        out.close()
        os.replace(tmp, path)
    except BaseException:
        out.close()
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def world_to_view_normals(normals: np.ndarray, camera_to_world) -> np.ndarray:
    """n_view = Rᵀ n_world with R the normalised rotation of camera_to_world (numpy rows:
    Nv = Nw @ R). Background (0, 0, 0) stays 0; lengths are kept (not renormalised)."""
    m = np.asarray(camera_to_world, dtype=np.float64)[:3, :3]
    r = m / np.linalg.norm(m, axis=0, keepdims=True)
    return (normals.astype(np.float64) @ r).astype(np.float32)
