"""The reference scenes: finding and resolving them, loading one (its G-buffer, reference,
R, regions, peers and screen-space limits, cropped if asked), the frames of a sequence, and
where each scene keeps its peers and limits (docs/file_formats.md). Below the study, the
checks and the panel's jobs (aolab.jobs), which all read scenes."""

from __future__ import annotations

import functools
import json
import math
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import aolab

from .bridge.constants import (EEVEE_NEXT_JSON, PEERS_DIR, PEERS_JSON, RESULT_EXR, RESULT_JSON,
                               RESULT_MESH, RESULT_MESH_JSON)
from .regions import region_masks
from .scoring import nothing_to_score
from .util import files

#: reference_scenes/<scene>/limits/: the committed screen-space limits (aolab limits).
LIMITS_DIR = "limits"
LIMITS_JSON = "limits.json"


def find_scenes_dir() -> Path | None:
    """reference_scenes/: $AOLAB_SCENES, ./reference_scenes, or beside the package's
    checkout (build/python/aolab -> the repository)."""
    if os.environ.get("AOLAB_SCENES"):
        return Path(os.environ["AOLAB_SCENES"])
    candidates = [Path.cwd()] + list(Path(__file__).resolve().parents)
    for base in candidates:
        if (base / "reference_scenes").is_dir():
            return base / "reference_scenes"
    return None


#: A sequence scene's folder of frames: frames/NNNN/reference.exr (docs/file_formats.md).
FRAMES_DIR = "frames"
#: Between a sequence's name and its frame number in the scene name of a frame's rows.
FRAME_SEPARATOR = "@"


def frame_numbers(folder: Path) -> list[int] | None:
    """The frames of a sequence scene (its manifest's ``"frames": {"start", "end", "step"}``),
    or None for a still scene. A malformed "frames" is a ValueError naming it."""
    spec = manifest(folder).get("frames")
    if spec is None:
        return None
    keys = ("start", "end", "step")
    ok = isinstance(spec, dict) and all(isinstance(spec.get(k), int)
                                        and not isinstance(spec.get(k), bool) for k in keys)
    if not ok or not (0 <= spec["start"] <= spec["end"] <= 9999 and spec["step"] >= 1):
        raise ValueError(f"scene {folder.name!r}: manifest.json \"frames\" must be "
                         '{"start": S, "end": E, "step": T} with integers 0 <= S <= E <= 9999 '
                         f"and T >= 1, got {spec!r}")
    return list(range(spec["start"], spec["end"] + 1, spec["step"]))


def frame_folder(folder: Path, frame: int) -> Path:
    """Where frame ``frame`` of a sequence lives: ``folder/frames/NNNN``."""
    return Path(folder) / FRAMES_DIR / f"{frame:04d}"


def frame_scene_name(sequence: str, frame: int) -> str:
    """The scene name of a frame's rows: ``<sequence>@NNNN``."""
    return f"{sequence}{FRAME_SEPARATOR}{frame:04d}"


def is_scene(folder: Path) -> bool:
    """A still scene with its reference.exr, or a sequence with its first frame rendered."""
    if (folder / "reference.exr").exists():
        return True
    frames = frame_numbers(folder) if (folder / "manifest.json").exists() else None
    return bool(frames) and (frame_folder(folder, frames[0]) / "reference.exr").exists()


#: The families of the scene corpus (manifest "family"): what kind of place or object a
#: scene shows. Leave-one-family-out validation holds out one family at a time.
FAMILIES = ("analytic", "interior", "exterior", "organic", "thin", "clutter", "terrain",
            "mechanical")
#: Manifest key: true for the scenes of the default study (`aolab compare` without
#: --corpus): the six 1280x720 scenes and one corpus scene of each family they lack.
DEFAULT_STUDY_KEY = "default_study"


def family(folder: Path) -> str:
    """The family of a scene folder (its manifest's "family"); a missing or unknown family
    is a ValueError naming the scene."""
    name = manifest(folder).get("family")
    if name not in FAMILIES:
        raise ValueError(f"scene {Path(folder).name!r}: manifest.json \"family\" must be one "
                         f"of {', '.join(FAMILIES)}, got {name!r}")
    return name


def in_default_study(folder: Path) -> bool:
    return manifest(folder).get(DEFAULT_STUDY_KEY) is True


def resolve_scenes(specs: list[str], scenes_dir: Path | None, *, default_study: bool = False,
                   follow_symlinks: bool = False) -> list[Path]:
    """Scene folders (is_scene): names in ``scenes_dir``, folders, or .exr paths (their
    folder). No spec: every scene folder of ``scenes_dir``, sorted (a sequence not rendered
    yet is left out) — only those of the default study when ``default_study``. Each is
    confined (check_confined, ``follow_symlinks``)."""
    folders = _resolved(specs, scenes_dir, default_study)
    for folder in folders:
        check_confined(folder, follow_symlinks)
    return folders


#: How a command and the API let a scene's symbolic links be read (check_confined).
#: The checks of the committed references (bench-table, rtao-check, bridge-check) take no
#: such option: they read committed folders, which hold no links.
FOLLOW_SYMLINKS_HINT = ("--follow-symlinks (compare, tune, advise, limits, reference, mesh, "
                        "radius-study, rtao; follow_symlinks=True in Python) reads it anyway")
_followed: set[str] = set()   # the links check_confined has warned about, once each


def check_confined(folder: Path, follow_symlinks: bool = False) -> None:
    """A scene's files are regular files inside its folder: a symbolic link anywhere in
    ``folder`` (a file or a subfolder such as frames/0001) is a ValueError naming it and
    where it points, before anything is read through it; with ``follow_symlinks`` it is
    read, and a warning line says so. ``folder`` itself may be a link (the user's)."""
    link = files.first_symlink(folder)
    if link is None:
        return
    where = f"{str(link)!r} is a symbolic link to {os.readlink(link)!r}"
    if not follow_symlinks:
        raise ValueError(f"scene {Path(folder).name!r}: {where}: a scene's files must be "
                         f"regular files inside its folder; {FOLLOW_SYMLINKS_HINT}")
    if where not in _followed:
        _followed.add(where)
        print(f"aolab: warning: scene {Path(folder).name!r}: {where}, followed "
              "(--follow-symlinks)", file=sys.stderr, flush=True)


def _resolved(specs: list[str], scenes_dir: Path | None, default_study: bool) -> list[Path]:
    if not specs:
        if scenes_dir is None:
            raise ValueError("no reference_scenes folder found: run from the repository, pass "
                             "--scenes-dir, or set AOLAB_SCENES")
        found = sorted(p for p in Path(scenes_dir).iterdir() if p.is_dir() and is_scene(p))
        if default_study and any(in_default_study(p) for p in found):
            found = [p for p in found if in_default_study(p)]
        if not found:
            raise ValueError(f"no scene with a reference.exr in {scenes_dir}")
        return found
    out = []
    for spec in specs:
        p = Path(spec)
        if p.suffix == ".exr" and p.exists():
            p = p.parent
        elif not p.exists() and scenes_dir is not None:
            p = Path(scenes_dir) / spec
        if not is_scene(p):
            frames = frame_numbers(p) if (p / "manifest.json").exists() else None
            where = (f"{frame_folder(p, frames[0]) / 'reference.exr'} (a sequence: render "
                     "its frames with `aolab reference --frames`)" if frames else p)
            raise ValueError(f"scene {spec!r}: no reference.exr found (looked in {where})")
        out.append(p)
    return out


def scene_files(folders: list[Path]) -> dict:
    """Every file the scene folders hold (their frames, peers and limits included), as
    ``reads`` for files.check_distinct: what a command that reads scenes must not
    overwrite."""
    return {"the scene file": sorted(p for folder in folders for p in Path(folder).rglob("*")
                                     if p.is_file())}


def median_projected_radius(g, radius: float) -> float:
    """The median over geometry pixels of R·f/d, the radius's length on screen in pixels."""
    depth = np.asarray(g.depth, np.float64)
    valid = np.asarray(g.valid_mask(), bool)
    return float(np.median(radius * g.fx / depth[valid]))


def radius_for_pixels(g, pixels: float) -> float:
    """The view-space R whose median projected radius on ``g`` is ``pixels``
    (:func:`median_projected_radius` is linear in R)."""
    return pixels / median_projected_radius(g, 1.0)


def read_y_exr(path: Path) -> np.ndarray:
    """A one-channel AO EXR (channel "Y", or the only channel) as float32 (H, W)."""
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(str(files.regular_file(path, "AO image")))
    if inp is None:
        raise ValueError(f"cannot open {path}: {oiio.geterror()}")
    try:
        spec = inp.spec()
        names = list(spec.channelnames)
        channel = names.index("Y") if "Y" in names else 0
        if "Y" not in names and len(names) != 1:
            raise ValueError(f"{path}: expected a channel named Y, got {names}")
        pixels = inp.read_image(channel, channel + 1, oiio.FLOAT)
    finally:
        inp.close()
    if pixels is None:
        raise ValueError(f"cannot read {path}")
    return np.ascontiguousarray(np.asarray(pixels, np.float32).reshape(spec.height, spec.width))


@dataclass
class Peer:
    """One render of reference_scenes/<scene>/peers/peers.json."""
    name: str
    kind: str               # cycles, noise_floor, eevee
    ao: np.ndarray
    render_time_s: float | None
    entry: dict


#: The files of a scene or frame folder that its SHA256SUMS covers: a render's results (the
#: manifest and build script are the render's inputs, in its cache key).
RESULT_FILES = (RESULT_EXR, RESULT_JSON, RESULT_MESH, RESULT_MESH_JSON)


def checked_names(folder: Path) -> list[str]:
    """The files of ``folder`` its SHA256SUMS covers: in a scene or frame folder the render's
    results that are there (RESULT_FILES); in peers/ and limits/ every file."""
    if folder.name in (PEERS_DIR, LIMITS_DIR):
        return sorted(p.name for p in folder.iterdir() if p.is_file()
                      and not p.name.startswith(".") and p.name != files.CHECKSUMS_NAME)
    return [n for n in RESULT_FILES if (folder / n).is_file()]


def verify_folder(folder: Path) -> None:
    """A ValueError naming the file when ``folder`` has a SHA256SUMS that its files no longer
    match (docs/file_formats.md, "Checksums"); a folder without one is not checked."""
    if not (folder / files.CHECKSUMS_NAME).exists():
        return
    why = files.checksum_mismatch(folder, checked_names(folder))
    if why:
        raise ValueError(f"{folder}: {why}: not the files recorded when they were made; "
                         "restore them (git checkout) or make them again "
                         "(scripts/update_references.sh, which records them anew)")


def write_folder_checksums(folder: Path) -> None:
    """Records the SHA-256 of ``folder``'s checked_names in its SHA256SUMS."""
    files.write_checksums(folder, checked_names(folder))


def write_scene_checksums(scene: Path) -> list[Path]:
    """SHA256SUMS in every folder of a scene that holds results: the scene folder (or each
    frame of a sequence) and the peers/ and limits/ beside it; returns the folders."""
    frames = frame_numbers(scene)
    tops = [frame_folder(scene, f) for f in frames] if frames else [scene]
    done = []
    for top in tops:
        for folder in (top, top / PEERS_DIR, top / LIMITS_DIR):
            if folder.is_dir() and checked_names(folder):
                write_folder_checksums(folder)
                done.append(folder)
    return done


def load_peers(folder: Path, shape: tuple[int, int], crop) -> tuple[list[Peer], list[str]]:
    """The peers of a scene folder and its committed screen-space limits (aolab limits, kind
    "limit"), and notes about entries that could not be used."""
    peers, notes = load_renders(folder / PEERS_DIR, PEERS_JSON, shape, crop)
    # EEVEE Next (Blender 4.2+) beside 3.4's peers: the two EEVEEs scored side by side
    next_, more = load_renders(folder / PEERS_DIR, EEVEE_NEXT_JSON, shape, crop)
    limits, most = load_renders(folder / LIMITS_DIR, LIMITS_JSON, shape, crop)
    return peers + next_ + limits, notes + more + most


def load_renders(where: Path, json_name: str, shape: tuple[int, int],
                 crop) -> tuple[list[Peer], list[str]]:
    """The images listed in ``where/json_name`` ({"entries": [{name, kind, file, ...}]}),
    cropped like the scene, and notes about entries that could not be used."""
    path = where / json_name
    if not path.exists():
        return [], []
    verify_folder(where)
    notes = []
    try:
        listing = json.loads(files.read_text(path, "limits"))
        entries = listing.get("entries", [])
    except (OSError, ValueError) as e:
        return [], [f"{path}: unreadable ({e})"]
    for e in entries:  # which Blender rendered it: the two EEVEEs differ by release
        if "blender_version" in listing:
            e.setdefault("blender_version", listing["blender_version"])
    peers = []
    for e in entries:
        try:
            if not files.plain_name(str(e["file"])):   # never a path out of the folder
                raise ValueError(f"its file {e['file']!r} is not a plain file name in {where}")
            ao = read_y_exr(where / e["file"])
            if crop is not None:
                ao = crop.apply(ao)
            if ao.shape != shape:
                raise ValueError(f"size {ao.shape[1]}x{ao.shape[0]}, reference "
                                 f"{shape[1]}x{shape[0]}")
            t = e.get("render_time_s")
            peers.append(Peer(e["name"], e.get("kind", "cycles"), ao,
                              float(t) if t is not None else None, e))
        except (OSError, ValueError, KeyError) as err:
            notes.append(f"peer {e.get('name', '?')}: not used ({err})")
    return peers, notes


@dataclass
class Crop:
    """A centred window of at most width x height pixels (tests and quick looks)."""
    width: int
    height: int
    x0: int = 0
    y0: int = 0

    def fit(self, w: int, h: int) -> "Crop":
        cw, ch = min(self.width, w), min(self.height, h)
        return Crop(cw, ch, (w - cw) // 2, (h - ch) // 2)

    def apply(self, a):
        if a is None:
            return None
        return np.ascontiguousarray(a[self.y0:self.y0 + self.height, self.x0:self.x0 + self.width])


@dataclass
class Scene:
    """A scene as the studies run it: its G-buffer, reference, R and regions, the peers and
    screen-space limits beside it, and what the studies add (a frame's sequence, the kept
    outputs, the family and the time scale)."""
    name: str
    folder: Path
    g: object
    reference: np.ndarray
    radius: float
    regions: dict
    peers: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    #: The scene's screen-space limit: its committed thickness with the lowest occluded MAE
    #: (a Peer), against which each method's approximation error is measured; None without.
    limit: object = None
    #: A frame of a sequence: the sequence's name and the frame number (None for a still).
    sequence: str | None = None
    frame: int | None = None
    #: A frame's scored images by (kind, method, label), kept for the flicker against the
    #: next frame; None for a still scene, whose images are not kept.
    outputs: dict | None = None
    #: The scene's family (manifest.json's "family"; "" without): tune holds one out at a time.
    family: str = ""
    #: Measured ms -> ms per 1280x720 frame, the budgets' unit (1 for a crop, whose times stay
    #: the crop's); set by the study's runner (study.runner.hd_scale).
    time_scale: float = 1.0

    @property
    def valid(self) -> np.ndarray:
        """The scored pixels (the region "all")."""
        return self.regions["all"]

    @property
    def occluded(self) -> np.ndarray:
        """The occluded region (reference AO < 0.9, aolab.regions)."""
        return self.regions["occluded"]

    @functools.cached_property
    def ao_one_mae(self) -> float:
        """The whole-frame MAE of AO = 1, the output that draws no occlusion: no tuned preset
        or advice may be worse on any scene (study.budget.Guard)."""
        return float(np.mean(np.abs(1.0 - self.reference[self.valid].astype(np.float64))))


def load_cropped(folder: Path, crop: Crop | None = None, name: str | None = None, *,
                 follow_symlinks: bool = False) -> tuple:
    """(G-buffer, reference AO, R, the crop fitted to the frame or None) of a scene folder,
    cropped to a centred ``crop`` if given; ``name`` (default: the folder's) in errors. A
    symbolic link among its files is refused unless ``follow_symlinks`` (check_confined)."""
    shown = name or folder.name
    check_confined(folder, follow_symlinks)
    verify_folder(folder)
    g = aolab.load_gbuffer(folder / "reference.exr")
    sidecar = g.sidecar or {}
    if "ao_distance" not in sidecar:
        raise ValueError(f"scene {shown!r}: its sidecar ({folder / 'reference.json'}) "
                         "has no 'ao_distance', the R the reference was rendered with, which "
                         "the study runs every method at; render it with `aolab reference`")
    try:
        radius = float(sidecar["ao_distance"])
    except (TypeError, ValueError):
        radius = math.nan
    if not (math.isfinite(radius) and radius > 0):
        raise ValueError(f"scene {shown!r}: ao_distance must be a finite number > 0, got "
                         f"{sidecar['ao_distance']!r}")
    if g.reference is None:
        raise ValueError(f"scene {shown!r}: reference.exr has no AO pass to score against")
    reference = np.asarray(g.reference, np.float32)
    if crop is not None:
        crop = crop.fit(g.width, g.height)
        side = g.sidecar
        cropped = aolab.GBuffer(crop.apply(g.depth), crop.apply(g.normal), crop.apply(g.color),
                                fx=g.fx, fy=g.fy, cx=g.cx - crop.x0, cy=g.cy - crop.y0,
                                background_depth=g.background_depth,
                                emission=crop.apply(g.emission))
        cropped.sidecar, cropped.path = side, g.path
        # offsets between two pixel positions: a crop moves both alike
        cropped.motion = crop.apply(g.motion)
        reference = crop.apply(reference)
        cropped.reference = reference
        g = cropped
    where = "" if crop is None else f" in the {crop.width}x{crop.height} crop"
    problem = nothing_to_score(g, reference, where)
    if problem:
        raise ValueError(f"scene {shown!r}: {problem}")
    return g, reference, radius, crop


def load_scene(folder: Path, crop: Crop | None = None, name: str | None = None, *,
               follow_symlinks: bool = False) -> Scene:
    """A scene folder loaded (load_cropped) with its regions and peers."""
    g, reference, radius, crop = load_cropped(folder, crop, name,
                                              follow_symlinks=follow_symlinks)
    masks = region_masks(g, reference, radius)
    peers, notes = load_peers(folder, reference.shape, crop)
    return Scene(name or folder.name, folder, g, reference, radius, masks, peers, notes)


def check_sequence(folder: Path, crop: Crop | None = None, *,
                   follow_symlinks: bool = False) -> bool:
    """Every frame of a sequence loads (load_cropped) and all have the first frame's size and
    R, so that consecutive frames compare pixel by pixel; a ValueError names the frame.
    Returns whether every frame after the first carries motion vectors (GBuffer.motion)."""
    check_confined(folder, follow_symlinks)   # frames/ and frames/NNNN included
    first = None
    motion = True
    for i, frame in enumerate(frame_numbers(folder)):
        where = frame_folder(folder, frame)
        name = frame_scene_name(folder.name, frame)
        if not (where / "reference.exr").exists():
            raise ValueError(f"scene {folder.name!r}: frame {frame} has no reference.exr "
                             f"(looked in {where}); render the sequence with `aolab reference "
                             "--frames`")
        g, reference, radius, _ = load_cropped(where, crop, name,
                                               follow_symlinks=follow_symlinks)
        motion = motion and (i == 0 or g.motion is not None)
        if first is None:
            first = (reference.shape, radius)
        elif (reference.shape, radius) != first:
            raise ValueError(f"scene {name!r}: {reference.shape[1]}x{reference.shape[0]} at "
                             f"R = {radius:g}, but the sequence's first frame is "
                             f"{first[0][1]}x{first[0][0]} at R = {first[1]:g}: every frame "
                             "of a sequence must have the same size and R")
    return motion


def noise_floor_peer(peers: list[Peer]) -> tuple[Peer, float, str] | None:
    """The peer whose MAE against the reference gives the reference's own noise floor, the
    factor on that MAE and a description: an independent 1024-spp render (measured, factor 1),
    else the 256-spp rung (estimated, MAE x sqrt(2/5): Monte Carlo noise halves with 4x the
    samples, and a difference of two renders adds their variances); None without either."""
    measured = [p for p in peers if p.kind == "noise_floor"]
    if measured:
        return measured[0], 1.0, f"measured: {measured[0].name} vs the reference"
    rung = [p for p in peers if p.kind == "cycles" and p.entry.get("samples") == 256]
    if rung:
        return rung[0], math.sqrt(2 / 5), f"estimated: {rung[0].name} MAE x sqrt(2/5)"
    return None


def manifest(folder: Path) -> dict:
    try:
        return json.loads(files.read_text(folder / "manifest.json", "scene manifest"))
    except (OSError, ValueError):
        return {}
