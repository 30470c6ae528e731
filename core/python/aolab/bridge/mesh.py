"""The scene-geometry file of the bridge's `mesh` pass: world-space triangles (no bpy).

``<stem>.mesh``, little-endian (docs/file_formats.md, "Scene geometry"):

    header, 24 bytes   b"AOLABMSH", uint32 version = 1, uint32 V, uint32 T, uint32 reserved = 0
    V x 3 float32      vertex positions, world space (Blender scene units)
    T x 3 uint32       vertex indices of each triangle, counter-clockwise seen from the front

and beside it ``<stem>.mesh.json``, written last: format, version, file, sha256 of the .mesh
bytes, the counts, and what the exporter adds (scene_hash, camera, objects, skipped...).
"""

from __future__ import annotations

import hashlib
import json
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..util import files

MAGIC = b"AOLABMSH"
VERSION = 1
FORMAT = "aolab-mesh"
HEADER = struct.Struct("<8sIIII")   # magic, version, V, T, reserved
MAX_COUNT = 2**32 - 1               # counts and indices are uint32


@dataclass
class Mesh:
    vertices: np.ndarray            # float32 (V, 3), world space
    triangles: np.ndarray           # uint32 (T, 3), indices into vertices
    info: dict = field(default_factory=dict)   # the .mesh.json, or {} without one
    path: str = ""


def json_path(path) -> Path:
    """``scene.mesh`` -> ``scene.mesh.json``."""
    p = Path(path)
    return p.with_name(p.name + ".json")


def encode(vertices, triangles) -> bytes:
    """The .mesh bytes of (V, 3) vertices and (T, 3) triangles, checked: finite vertices,
    integer indices in [0, V)."""
    v = np.asarray(vertices)
    t = np.asarray(triangles)
    if v.ndim != 2 or v.shape[1] != 3 or not np.issubdtype(v.dtype, np.floating):
        raise ValueError(f"vertices must be a float (V, 3) array, got {v.dtype} {v.shape}")
    if t.ndim != 2 or t.shape[1] != 3 or not np.issubdtype(t.dtype, np.integer):
        raise ValueError(f"triangles must be an integer (T, 3) array, got {t.dtype} {t.shape}")
    if len(v) > MAX_COUNT or len(t) > MAX_COUNT:
        raise ValueError(f"at most {MAX_COUNT} vertices and triangles, got {len(v)}, {len(t)}")
    with np.errstate(over="ignore"):   # a double beyond float32's range: refused below
        v32 = v.astype("<f4")
    bad = ~np.isfinite(v32).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"vertices must be finite (also as float32), vertex {i} is "
                         f"{v[i].tolist()}")
    if t.size and (t.min() < 0 or t.max() >= len(v)):
        raise ValueError(f"triangles must index vertices in [0, {len(v)}), got indices from "
                         f"{t.min()} to {t.max()}")
    return (HEADER.pack(MAGIC, VERSION, len(v), len(t), 0) + v32.tobytes()
            + t.astype("<u4").tobytes())


def write_mesh(path, vertices, triangles, info: dict | None = None) -> dict:
    """Writes ``path`` (the .mesh) and ``<path>.json`` atomically, the JSON last, so that a
    JSON at least as new as its .mesh means the pair is complete. The JSON holds format,
    version, file, sha256, vertices, triangles, then the keys of ``info``; returns it."""
    path = Path(path)
    data = encode(vertices, triangles)
    _, _, n_vertices, n_triangles, _ = HEADER.unpack_from(data)
    record = {"format": FORMAT, "version": VERSION, "file": path.name,
              "sha256": hashlib.sha256(data).hexdigest(), "vertices": n_vertices,
              "triangles": n_triangles}
    record.update({k: v for k, v in (info or {}).items() if k not in record})
    text = json.dumps(record, indent=1, allow_nan=False)
    files.write_together([(path, data), (json_path(path), text.encode())])
    return record


def read_mesh(path) -> Mesh:
    """Reads and validates ``path`` (a .mesh) and its ``.mesh.json`` when present. Anything
    wrong (magic, version, size, an index >= V, a non-finite vertex, a JSON that does not
    describe these bytes) is a ValueError naming the file and what is wrong."""
    path = Path(path)
    data = files.read_bytes(path, "mesh")
    if len(data) < HEADER.size:
        raise ValueError(f"{path}: {len(data)} bytes, shorter than the {HEADER.size}-byte "
                         "header: not an AO Lab mesh, or truncated")
    magic, version, n_vertices, n_triangles, reserved = HEADER.unpack_from(data)
    if magic != MAGIC:
        raise ValueError(f"{path}: not an AO Lab mesh (magic {magic!r}, expected {MAGIC!r})")
    if version != VERSION:
        raise ValueError(f"{path}: mesh format version {version} is unknown (this aolab reads "
                         f"version {VERSION}); re-export it with this build")
    if reserved != 0:
        raise ValueError(f"{path}: the header's reserved field must be 0, got {reserved}")
    expected = HEADER.size + 12 * n_vertices + 12 * n_triangles
    if len(data) != expected:
        how = "truncated" if len(data) < expected else "has extra bytes"
        raise ValueError(f"{path}: {how}: {len(data)} bytes, but {n_vertices} vertices and "
                         f"{n_triangles} triangles take {expected}")
    end = HEADER.size + 12 * n_vertices
    vertices = np.frombuffer(data, "<f4", 3 * n_vertices, HEADER.size).reshape(-1, 3)
    triangles = np.frombuffer(data, "<u4", 3 * n_triangles, end).reshape(-1, 3)
    bad = ~np.isfinite(vertices).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{path}: vertex {i} is not finite: {vertices[i].tolist()}")
    if n_triangles and int(triangles.max()) >= n_vertices:
        i = int(np.argmax(triangles.max(axis=1) >= n_vertices))
        raise ValueError(f"{path}: triangle {i} indexes vertex {int(triangles[i].max())}, "
                         f"but the file has {n_vertices} vertices")
    info = {}
    side = json_path(path)
    if side.exists():
        info = _check_info(side, data, n_vertices, n_triangles)
    return Mesh(vertices.astype(np.float32), triangles.astype(np.uint32), info, str(path))


def _check_info(side: Path, data: bytes, n_vertices: int, n_triangles: int) -> dict:
    try:
        info = json.loads(files.read_bytes(side, "mesh JSON").decode("utf-8-sig"))
    except (UnicodeDecodeError, ValueError) as e:
        raise ValueError(f"{side}: not valid UTF-8 JSON ({e})") from None
    if not isinstance(info, dict) or info.get("format") != FORMAT:
        raise ValueError(f"{side}: not an AO Lab mesh JSON (\"format\" must be {FORMAT!r})")
    digest = hashlib.sha256(data).hexdigest()
    if info.get("sha256") != digest:
        raise ValueError(f"{side}: sha256 {info.get('sha256')!r} does not match the .mesh "
                         f"bytes ({digest}): the two files are not from the same export")
    for key, value in (("vertices", n_vertices), ("triangles", n_triangles)):
        if info.get(key) != value:
            raise ValueError(f"{side}: \"{key}\" is {info.get(key)!r}, the .mesh has {value}")
    return info


def _gbuffer_name(g) -> str:
    side = getattr(g, "sidecar", None) or {}
    scene = side.get("scene")
    if getattr(g, "path", None):
        return str(g.path)
    if isinstance(scene, str) and scene.startswith("analytic:"):
        return f"{scene} (an analytic scene)"
    return "the G-buffer (no file)"


def check_pairing(g, mesh, *, allow_unknown_scene: bool = False, how: str = "") -> None:
    """The one rule for tracing ``mesh`` against G-buffer ``g`` (docs/file_formats.md, "Scene
    geometry"): when both carry a scene_hash (the sidecar's, the .mesh.json's), they must be
    equal; a mesh read from a file whose scene cannot be checked that way (either side lacks
    the hash: an analytic G-buffer, a .mesh without its JSON, a G-buffer not from the bridge)
    is refused unless ``allow_unknown_scene``; a mesh made in memory (no file) is the caller's
    own pairing. A refusal is a ValueError naming both files and both hashes, then ``how``."""
    want = (getattr(g, "sidecar", None) or {}).get("scene_hash")
    got = (getattr(mesh, "info", None) or {}).get("scene_hash")
    path = getattr(mesh, "path", "") or ""
    mesh_name = path or "the mesh made in memory"
    tail = f"; {how}" if how else ""
    if want is not None and got is not None:
        if want != got:
            raise ValueError(f"{mesh_name} is not the geometry of {_gbuffer_name(g)}: the "
                             f"mesh's scene_hash {got!r} differs from the G-buffer sidecar's "
                             f"{want!r}{tail}")
        return
    if not path or allow_unknown_scene:
        return
    lacking = " and ".join(name for name, h in (("the mesh", got), ("the G-buffer", want))
                           if h is None)
    raise ValueError(f"{mesh_name} cannot be checked to be the geometry of "
                     f"{_gbuffer_name(g)}: {lacking} carries no scene_hash (the mesh's "
                     f"scene_hash {got!r}, the G-buffer's {want!r}); pair them anyway with "
                     f"allow_unknown_scene=True (aolab rtao --allow-unknown-scene){tail}")


def mesh_for_gbuffer(g, *, allow_unknown_scene: bool = False) -> Mesh:
    """The mesh exported with G-buffer ``g``: ``<stem>.mesh`` next to ``g.path``, paired with
    ``g`` by check_pairing (its scene_hash must equal the sidecar's)."""
    gpath = getattr(g, "path", None)
    if not gpath:
        raise ValueError("g has no path: load it with aolab.load_gbuffer to find its mesh")
    path = Path(gpath).with_suffix(".mesh")
    how = (f"export one with `aolab mesh SCENE --out {path.parent}` (the scene the G-buffer "
           "was rendered from, at its resolution and camera) or render with "
           "`aolab reference ... --passes depth,normal,mesh`")
    if not path.exists():
        raise FileNotFoundError(2, f"no mesh {path} beside the G-buffer: {how}", str(path))
    mesh = read_mesh(path)
    check_pairing(g, mesh, allow_unknown_scene=allow_unknown_scene, how=how)
    return mesh
