"""What a Blender run renders: the scene (a `.blend` file, a build script `.py` run into an
empty factory file, or a folder of reference_scenes/ whose manifest.json names the build
script, R, resolution and effects), the plan (samples, R, passes, size, camera, frame, peers
or mesh) and its cache key, the digest of everything the render depends on."""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import aolab

from ..bridge.constants import (BRIDGE_VERSION, LADDER_SPP, PEERS_JSON, RESULT_EXR, RESULT_JSON,
                                RESULT_MESH, RESULT_MESH_JSON)
from ..bridge.passes import parse_passes, required_passes
from .. import scenes
from ..util import files
from ..util.arguments import MAX_FRAMES, check_resolution, parse_frames, parse_resolution
from .blender import ReferenceError, blender_version

SCENE_KIT = "scene_kit.py"  # reference_scenes/scene_kit.py, shared by the build scripts
#: The hexadecimal digits of the digest that ends a cache key (Plan.key).
KEY_DIGEST_CHARS = 16


def _sha256_of(path: Path, what: str) -> str:
    return hashlib.sha256(files.read_bytes(path, what)).hexdigest()


@dataclass
class BlenderScene:
    """A scene Blender renders (a .blend or a build script) and the hash of what its render
    depends on: what a plan is made of, not the loaded scene the study scores (scenes.Scene)."""
    name: str
    kind: str            # "blend" or "script"
    path: Path           # the .blend or the build script
    manifest: dict = field(default_factory=dict)
    content_sha256: str = ""


def resolve_scene(spec: str, follow_symlinks: bool = False) -> BlenderScene:
    """The scene of ``spec`` (a .blend, a build script or a scene folder) and the hash of
    what its render depends on. A scene folder is confined (scenes.check_confined: a symbolic
    link among its files is refused unless ``follow_symlinks``), its build script a plain
    file name in it."""
    p = Path(spec)
    if not p.exists():
        raise ReferenceError(f"no such scene: {spec} (give a .blend, a build script .py or a "
                             "reference_scenes/<name> folder)")
    # Every file is checked to be a regular file before it is hashed: reading a FIFO would
    # wait forever for a writer (files.read_bytes).
    if p.is_dir():
        return _scene_folder(p, spec, follow_symlinks)
    if p.suffix == ".blend":
        return BlenderScene(p.stem, "blend", p, {}, _sha256_of(p, "scene .blend"))
    if p.suffix == ".py":
        return BlenderScene(p.stem, "script", p, {}, _sha256_of(p, "scene build script"))
    raise ReferenceError(f"{spec}: a scene is a .blend, a .py build script or a folder with "
                         "manifest.json")


def _scene_folder(p: Path, spec: str, follow_symlinks: bool) -> BlenderScene:
    """The scene of a reference_scenes/<name> folder: its manifest, build script, the scene
    kit and the modules it uses, all hashed."""
    scenes.check_confined(p, follow_symlinks)
    mpath = p / "manifest.json"
    if not mpath.exists():
        raise ReferenceError(f"{spec} is a folder without manifest.json")
    manifest_bytes = files.read_bytes(mpath, "scene manifest")   # read once: parsed, hashed
    manifest = files.json_object(manifest_bytes, mpath, "scene manifest")
    build = manifest.get("build", "build.py")
    if not (isinstance(build, str) and files.plain_name(build)):
        raise ReferenceError(f'{mpath}: "build" must be the name of a file in the scene\'s '
                             f"folder, got {build!r}")
    script = p / build
    if not script.exists():
        raise ReferenceError(f"{mpath} names the build script {script.name}, which is missing")
    h = hashlib.sha256(files.read_bytes(script, "build script") + manifest_bytes)
    kit = p.resolve().parent / SCENE_KIT  # the helpers every reference scene imports
    if kit.exists():
        h.update(files.read_bytes(kit, "scene kit"))
    for used in scene_uses(manifest, mpath):
        h.update(files.read_bytes(p.resolve().parent / used, "scene module"))
    return BlenderScene(manifest.get("name", p.name), "script", script, manifest, h.hexdigest())


def scene_uses(manifest: dict, mpath: Path) -> list[str]:
    """The manifest's "uses": the modules its build script imports besides scene_kit.py
    (a corpus family and its kit), relative to the scenes folder, which the scene's hash
    covers. Each must exist."""
    uses = manifest.get("uses", [])
    if not (isinstance(uses, list) and all(isinstance(u, str) and u for u in uses)):
        raise ReferenceError(f'{mpath}: "uses" must be a list of paths, got {uses!r}')
    for used in uses:
        if not (mpath.resolve().parent.parent / used).is_file():
            raise ReferenceError(f'{mpath}: "uses" names {used}, which is missing')
    return uses


@dataclass
class Plan:
    """One Blender run: a scene and what to render of it."""
    scene: BlenderScene
    spp: int
    radius: float | None      # None: the scene world's AO distance (a .blend's own)
    passes: list[str]
    resolution: tuple[int, int] | None
    camera: str | None
    gbuffer_samples: int = 1
    # The comparison peers (Cycles ladder + EEVEE: blender_addon/aolab_blender/export/peers.py)
    # instead of the reference; spp, passes and gbuffer_samples do not apply then.
    peers: bool = False
    ladder: tuple[int, ...] = LADDER_SPP
    eevee: bool = True
    # Only the scene's geometry, no render (`aolab mesh`): spp, R, passes do not apply.
    mesh_only: bool = False
    # The animation frame rendered (scene.frame_set), or None: the file's current frame.
    frame: int | None = None
    # Render at this percentage of the scene's output size (after `resolution`), as the
    # add-on's Resolution does (`aolab advise`), or None: the output size itself.
    scale: int | None = None

    def key(self, blender: str | None = None) -> str:
        """The cache folder's name: the scene's name and a digest of everything the render
        depends on, the release of `blender` (default: find_blender's) included."""
        material = {"bridge": BRIDGE_VERSION, "scene": self.scene.content_sha256,
                    "spp": self.spp, "radius": self.radius, "passes": self.passes,
                    "resolution": self.resolution, "camera": self.camera,
                    "gbuffer_samples": self.gbuffer_samples}
        if self.peers:  # only then, so that the references' keys stay as they were
            material.update(peers=True, ladder=list(self.ladder), eevee=self.eevee)
        if self.mesh_only:  # the geometry depends on the scene, camera and size alone
            material = {"bridge": BRIDGE_VERSION, "scene": self.scene.content_sha256,
                        "resolution": self.resolution, "camera": self.camera,
                        "mesh_only": True}
        if self.frame is not None:  # only then, so that still renders keep their keys
            material["frame"] = self.frame
        if self.scale is not None:  # likewise
            material["scale"] = self.scale
        material["blender"] = blender_version(blender)
        digest = hashlib.sha256(json.dumps(material, sort_keys=True).encode()).hexdigest()
        return f"{self.key_prefix()}{digest[:KEY_DIGEST_CHARS]}"

    def key_prefix(self) -> str:
        """The cache folder's name without its digest: the scene's name, the kind and the
        frame. Cheap, where key() hashes, so that count_cached looks at most keys by name."""
        kind = "peers-" if self.peers else "mesh-" if self.mesh_only else ""
        frame = "" if self.frame is None else f"f{self.frame:04d}-"
        return f"{files.file_name_for(self.scene.name)}-{kind}{frame}"

    def result_files(self, folder: Path) -> list[Path]:
        """The files a finished render leaves in its folder (the JSON last)."""
        if self.mesh_only:
            return [folder / RESULT_MESH, folder / RESULT_MESH_JSON]
        if self.peers:
            return sorted(folder.glob("*.exr")) + [folder / PEERS_JSON]
        mesh = [folder / RESULT_MESH, folder / RESULT_MESH_JSON] if "mesh" in self.passes else []
        return [folder / RESULT_EXR, *mesh, folder / RESULT_JSON]


def make_plan(scene: BlenderScene, *, spp: int | None = None, radius: float | None = None,
              methods: list[str] | None = None, passes: list[str] | None = None,
              resolution: tuple[int, int] | None = None, camera: str | None = None,
              gbuffer_samples: int = 1, scale: int | None = None) -> Plan:
    """What to render: explicit arguments first, then the scene's manifest, then defaults.
    Passes follow from the methods (all registered ones by default) and the manifest's
    effects unless given explicitly. ``scale``: a percentage of the output size, 1 to 100
    (Plan.scale)."""
    m = scene.manifest
    if passes is None:
        names = aolab.methods() if methods is None else methods
        infos = [aolab.method_info(n) for n in names]  # ValueError for an unknown name
        passes = required_passes(infos, m.get("effects", []), sequence="frames" in m)
    else:
        passes = parse_passes(",".join(passes))
    spp = spp if spp is not None else int(m.get("spp", 1024))
    radius = radius if radius is not None else m.get("radius")
    if radius is not None and not radius > 0:
        raise ReferenceError(f"radius must be > 0, got {radius}")
    if spp < 1:
        raise ReferenceError(f"spp must be >= 1, got {spp}")
    if resolution is None and m.get("resolution"):
        resolution = tuple(m["resolution"])
    if resolution is not None:
        resolution = check_resolution(resolution)
    if scale is not None and not (isinstance(scale, int) and 1 <= scale <= 100):
        raise ReferenceError(f"scale must be a percentage, an integer in [1, 100], got {scale!r}")
    return Plan(scene, spp, radius, passes, resolution, camera or m.get("camera"), gbuffer_samples,
                scale=scale)


def manifest_frames(scene: BlenderScene) -> list[int] | None:
    """The frames a sequence scene's manifest names ({"start", "end", "step"}), or None."""
    f = scene.manifest.get("frames")
    if f is None:
        return None
    try:
        return parse_frames(f"{int(f['start'])}-{int(f['end'])}:{int(f.get('step', 1))}")
    except (KeyError, TypeError, ValueError):
        raise ReferenceError(f"{scene.name}: manifest.json's \"frames\" must be {{\"start\": S, "
                             f"\"end\": E, \"step\": T}} with S <= E and T >= 1, got {f!r}") \
            from None


def per_frame(plans: list[Plan], frames: list[int] | None) -> list[Plan]:
    """One plan per frame of ``frames``, or of each scene's manifest frames when None; a still
    scene without frames keeps its one plan. More than MAX_FRAMES plans in all is a
    ReferenceError, raised before any is made."""
    each, total = [], 0
    for plan in plans:
        mine = frames if frames is not None else manifest_frames(plan.scene)
        each.append(mine)
        total += 1 if mine is None else len(mine)
        if total > MAX_FRAMES:
            raise ReferenceError(
                f"{len(plans)} scenes and their frames make more than {MAX_FRAMES} references, "
                "the most one `aolab reference` renders: split them over several commands "
                "(they share the cache)")
    out = []
    for plan, mine in zip(plans, each):
        if mine is None:
            out.append(plan)
        else:
            out += [dataclasses.replace(plan, frame=f) for f in mine]
    return out


def command_plans(scenes: list[str], *, spp: int | None = None, radius: float | None = None,
                  methods: list[str] | None = None, passes: str | None = None,
                  resolution: str | None = None, camera: str | None = None,
                  gbuffer_samples: int = 1, peers: bool = False,
                  ladder: tuple[int, ...] | None = None, no_eevee: bool = False,
                  frames=None, follow_symlinks: bool = False) -> list[Plan]:
    """The plans of an `aolab reference` call (its options by name), every error raised
    before any render. The caller runs them here (aolab.cycles.run.run_plans) or on a cluster
    (aolab.cycles.cluster.run_plans)."""
    size = parse_resolution(resolution) if resolution else None
    found = [resolve_scene(s, follow_symlinks) for s in scenes]  # every error before a render
    plans = [make_plan(s, spp=spp, radius=radius, methods=methods,
                       passes=passes.split(",") if passes else None,
                       resolution=size, camera=camera,
                       gbuffer_samples=gbuffer_samples) for s in found]
    if peers:
        ladder = ladder if ladder is not None else LADDER_SPP
        if not ladder and no_eevee:
            raise ReferenceError("--ladder none with --no-eevee leaves nothing to render")
        for plan in plans:
            plan.peers, plan.ladder, plan.eevee = True, ladder, not no_eevee
    if isinstance(frames, str):
        frames = parse_frames(frames)
    return per_frame(plans, frames)
