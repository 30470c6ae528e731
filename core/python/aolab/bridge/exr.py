"""Reading Blender's multilayer EXRs and writing the merged G-buffer + AO reference (no bpy;
OpenImageIO's and numpy's Python modules, which import in Blender and in /usr/bin/python3).

The merged file is what aolab.load_gbuffer reads (docs/file_formats.md): Depth.Z float32,
Normal.X/Y/Z (view space), AO.R/G/B, DiffCol.R/G/B, Emit.R/G/B as half, Motion.X/Y float32
(AO Lab's motion convention: bridge/motion.py), zip-compressed.
"""

from __future__ import annotations

import os

import numpy as np
import OpenImageIO as oiio

from ..util import files


def read_channels(path: str, names: list[str] | None = None) -> dict[str, np.ndarray]:
    """The channels of an EXR by full name, as float32 (H, W) arrays, row 0 at the top: all
    of them, or only ``names`` (then only the span of channels holding them is decoded)."""
    inp = oiio.ImageInput.open(str(files.regular_file(path, "EXR")))
    if inp is None:
        raise RuntimeError(f"cannot open {path}: {oiio.geterror()}")
    try:
        spec = inp.spec()
        order = list(spec.channelnames)
        names = order if names is None else list(names)
        missing = [n for n in names if n not in order]
        if missing:
            raise RuntimeError(f"{path} has no channels {missing}; channels found: {order}")
        index = [order.index(n) for n in names]
        if not index:
            return {}
        begin, end = min(index), max(index) + 1
        pixels = inp.read_image(0, 0, begin, end, "float")
        if pixels is None:
            raise RuntimeError(f"cannot read {path}: {inp.geterror()}")
        pixels = np.asarray(pixels, dtype=np.float32).reshape(spec.height, spec.width,
                                                              end - begin)
        return {n: pixels[..., i - begin].copy() for n, i in zip(names, index)}
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


#: The passes of the merged G-buffer EXR and their channels, in the order they are written.
LAYER_COMPONENTS = {"Depth": "Z", "Normal": "XYZ", "AO": "RGB", "DiffCol": "RGB", "Emit": "RGB",
                    "Motion": "XY"}


def write_multilayer(path: str, layers: list[tuple[str, np.ndarray, str]],
                     view_layer: str = "ViewLayer") -> None:
    """Writes (pass name, (H, W, C) array, "float"|"half") layers with channel names
    `<view_layer>.<pass>.<component>`, durably and atomically (files.write_bytes)."""
    files.write_bytes(path, encode_multilayer(path, layers, view_layer))


def encode_multilayer(path: str, layers: list[tuple[str, np.ndarray, str]],
                      view_layer: str = "ViewLayer") -> bytes:
    """The bytes write_multilayer writes to `path`, for files put in place together."""
    names, formats, planes = [], [], []
    for pass_name, data, fmt in layers:
        comps = LAYER_COMPONENTS[pass_name]
        data = data.reshape(data.shape[0], data.shape[1], -1)
        for i, c in enumerate(comps):
            names.append(f"{view_layer}.{pass_name}.{c}")
            formats.append(oiio.TypeFloat if fmt == "float" else oiio.TypeHalf)
            planes.append(data[..., i])
    return _encode(path, names, formats, planes)


def write_gray(path: str, image: np.ndarray) -> None:
    """Writes an (H, W) image as a one-channel ("Y") half-float EXR, atomically: the format
    of the comparison peers (docs/comparison.md)."""
    files.write_bytes(path, _encode(path, ["Y"], [oiio.TypeHalf],
                                    [np.asarray(image, dtype=np.float32)]))


def _encode(path: str, names: list[str], formats: list, planes: list[np.ndarray]) -> bytes:
    """The bytes of a zip-compressed EXR with the given channels, to be written to `path`.
    OpenImageIO's Python module can only write to a file, and its EXR writer does not report
    every failed write (a full disk can leave a short file behind a successful close), so the
    file it writes beside `path` is read back in full and removed, and its bytes go into
    place through the one durable write (files.write_bytes)."""
    pixels = np.ascontiguousarray(np.stack(planes, -1), dtype=np.float32)
    h, w, n = pixels.shape
    spec = oiio.ImageSpec(w, h, n, oiio.TypeFloat)
    spec.channelnames = tuple(names)
    spec.channelformats = tuple(formats)
    spec.attribute("compression", "zip")
    tmp = os.path.join(os.path.dirname(path) or ".",
                       f".{os.path.basename(path)}.encode-{os.getpid()}.exr")
    try:
        out = oiio.ImageOutput.create(tmp)
        if out is None:
            raise RuntimeError(f"cannot create {path}: {oiio.geterror()}")
        ok = out.open(tmp, spec) and out.write_image(pixels)
        error = out.geterror()
        if not out.close() or not ok:
            raise RuntimeError(f"cannot write {path}: {error or out.geterror()}")
        back = read_channels(tmp)
        if sorted(back) != sorted(names) or back[names[0]].shape != (h, w):
            raise RuntimeError(f"cannot write {path}: the encoded file does not read back")
        with open(tmp, "rb") as f:
            return f.read()
    except RuntimeError as e:
        raise OSError(f"{e} (is the disk full?)") from None
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def world_to_view_normals(normals: np.ndarray, camera_to_world) -> np.ndarray:
    """n_view = Rᵀ n_world with R the normalised rotation of camera_to_world (numpy rows:
    Nv = Nw @ R). Background (0, 0, 0) stays 0; lengths are kept (not renormalised)."""
    m = np.asarray(camera_to_world, dtype=np.float64)[:3, :3]
    r = m / np.linalg.norm(m, axis=0, keepdims=True)
    return (normals.astype(np.float64) @ r).astype(np.float32)
