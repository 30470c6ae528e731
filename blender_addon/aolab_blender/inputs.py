"""What the operators and Live read from Blender and check, on the main thread (bpy).

scene_inputs() gathers what every operation needs — the scene, R, the AO Lab size, the
ticked runs, the G-buffer passes, the cache folder, the threads and the content hash — and
raises UserError with what to fix (no camera, no world, a radius out of range, a cache
folder that cannot be one, nothing ticked). reference_inputs() adds the cached reference's
folder; find_reference() looks one up; scene_hash() is the content hash. operators.py and
live.py both use them (ui.py the camera check); this module imports neither.

What comes from `aolab` (and export.scene_record, which imports it) is library.py's, used
only once library.available() said aolab is there (scene_inputs checks it first).
"""

import math
from pathlib import Path

from . import library, preferences, properties


class UserError(Exception):
    """A problem the user can act on; the message says what to do."""


def camera_problem(scene) -> str | None:
    """Why AO Lab cannot render from the scene's camera, or None."""
    try:
        library.scene_record.scene_camera(scene)
    except library.scene_record.BridgeError as e:
        return str(e)
    return None


#: Blender renders at least 4x4 pixels (a smaller size is raised to 4 without a word), so a
#: G-buffer or reference at a smaller size would not match what was asked for.
MIN_SIZE = 4


def compare_size(scene) -> tuple[int, int]:
    """The output size scaled by the panel's resolution percentage; a UserError when a side
    falls below what Blender renders (MIN_SIZE)."""
    r = scene.render
    w, h = library.intrinsics.image_size(r.resolution_x, r.resolution_y,
                                         r.resolution_percentage)
    pct = scene.aolab.preview_scale
    size = max(1, w * pct // 100), max(1, h * pct // 100)
    if min(size) < MIN_SIZE:
        raise UserError(f"the AO Lab size would be {size[0]}x{size[1]} pixels ({pct} % of "
                        f"{w}x{h}); Blender renders at least {MIN_SIZE}x{MIN_SIZE}: raise "
                        f"the panel's Resolution")
    return size


def folder_problem(path, what: str) -> str | None:
    """Why `path` cannot be (or be made) a folder — it, or a folder above it, is an existing
    file — or None."""
    p = Path(path)
    for q in (p, *p.parents):
        if q.exists():
            return None if q.is_dir() else f"{what} {str(p)!r} cannot be a folder: " \
                f"{str(q)!r} is an existing file"
    return None


def max_radius() -> float:
    """The largest radius every method accepts (the upper bound of their `radius` settings);
    Blender lets the world's AO distance go up to 3.4e38."""
    return min(s["max"] for m in library.methods()
               for s in library.aolab.method_info(m)["settings"] if s["name"] == "radius")


def render_passes() -> list[str]:
    """The G-buffer passes every registered method needs (one cached render serves all)."""
    infos = [library.aolab.method_info(m) for m in library.methods()]
    return library.passes.required_passes(infos, [])


def scene_inputs(context, *, need_runs: bool = True, hash_scene: bool = True) -> dict:
    """What every operation reads from Blender and checks (UserError: what to fix).
    `hash_scene=False` leaves out the content hash (Live keeps its own, computed once)."""
    scene = context.scene
    if not library.available():
        raise UserError(library.problem())
    # The camera's matrix_world is the depsgraph's: a change made since its last evaluation
    # (a script's, or one made just before this operator) is not in it until evaluated.
    context.evaluated_depsgraph_get()
    problem = camera_problem(scene)
    if problem:
        raise UserError(problem)
    radius = properties.effective_radius(scene)
    if radius is None:
        raise UserError("the scene has no world, so no AO distance: add a world or untick "
                        "Scene AO Distance and set the radius")
    largest = max_radius()
    if not (math.isfinite(radius) and 0 < radius <= largest):
        raise UserError(f"the world's AO distance is {radius:g}: set World > Ambient Occlusion "
                        f"> Distance to a value in (0, {largest:g}], or untick Scene AO "
                        f"Distance and set the radius")
    cache = preferences.cache_dir(context)
    problem = folder_problem(cache, "the cache folder (Preferences > Add-ons > AO Lab)")
    if problem:
        raise UserError(problem)
    runs = properties.chosen_runs(scene)
    if need_runs and not runs:
        raise UserError("nothing selected: tick at least one method")
    size = compare_size(scene)
    inputs = {"scene": scene.name, "radius": float(radius), "size": size, "runs": runs,
              "passes": render_passes(), "cache": cache,
              "threads": preferences.threads(context)}
    if hash_scene:
        inputs["scene_hash"] = scene_hash(scene, size)
    return inputs


def scene_hash(scene, size: tuple[int, int]) -> str:
    """The content hash of the scene seen from its camera at `size` (W, H): the cache's key
    (scene_record.content_hash, which reads every mesh)."""
    return library.scene_record.content_hash(scene, scene.camera, size)


def find_reference(inputs: dict, spp: int | None) -> Path | None:
    return library.find_by_content(
        inputs["cache"], scene_hash=inputs["scene_hash"], size=inputs["size"],
        radius=None if spp is None else inputs["radius"], spp=spp,
        passes=tuple(inputs["passes"]))


def missing_reference(inputs: dict, spp: int) -> str:
    w, h = inputs["size"]
    return (f"reference missing: no {spp}-sample reference of this scene at R = "
            f"{inputs['radius']:g}, {w}x{h}; click Render Reference first")


def reference_inputs(context) -> dict:
    """scene_inputs and the folder of the cached reference at the panel's samples; a
    UserError saying what was looked for when there is none."""
    inputs = scene_inputs(context)
    spp = context.scene.aolab.reference_samples
    folder = find_reference(inputs, spp=spp)
    if folder is None:
        raise UserError(missing_reference(inputs, spp))
    return {**inputs, "folder": str(folder)}
