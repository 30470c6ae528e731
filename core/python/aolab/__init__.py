"""AO Lab: screen-space ambient occlusion methods scored against a Cycles reference.

Conventions (docs/conventions.md): AO is ambient accessibility in [0, 1] (1 = unoccluded);
view space is Blender's camera space (x right, y up, looking down -z); depth is planar
depth d = -z > 0; background pixels (depth not finite, <= 0 or >= background_depth) get AO 1
and are excluded from every metric.

Arrays are numpy float32; C-contiguous float32 input is used in place, without copies.
Bad input raises ValueError naming the parameter and its value. Heavy calls release the GIL.
"""

from __future__ import annotations

import numpy as np

from . import _core, named_presets
from .bridge import mesh as mesh_file
from .bridge import motion as motion_pass
from .motion import camera_motion  # noqa: F401
# The ray-traced peer (raytracing.py): Embree against the scene's triangles.
from .raytracing import (RayScene, RtaoRangeWarning, analytic_scene_mesh,  # noqa: F401
                         ray_scene, rtao, rtao_range, rtao_settings)
from .util import values as checked
from .util.arguments import MAX_SIDE

__all__ = [
    "GBuffer", "methods", "method_info", "compute", "gaussian_blur", "metrics",
    "load_gbuffer", "save_gbuffer", "write_image", "encode_image", "Progress", "Cancelled",
    "analytic_scene", "analytic_scene_names", "vao_pp_with_stats", "presets", "simd_target",
    "rtao", "ray_scene", "RayScene", "rtao_settings", "rtao_range", "RtaoRangeWarning",
    "analytic_scene_mesh", "load_mesh", "mesh_for_gbuffer", "working_memory",
    "set_working_memory_limit", "release_working_memory", "camera_motion", "TemporalHistory",
    "accumulate", "accumulate_settings", "frame_seed",
]

Progress = _core.Progress
Cancelled = _core.Cancelled
TemporalHistory = _core.TemporalHistory


class GBuffer(_core.GBuffer):
    __doc__ = _core.GBuffer.__doc__ + """
fx, fy and background_depth must be > 0 and normal float32 numbers, cx and cy finite float32
numbers (background_depth may be inf): each is checked as given, before the float32
conversion, so that 1e39 is refused by name rather than made inf (a ValueError naming it)."""

    def __init__(self, depth, normal=None, color=None, *, fx, fy, cx, cy,
                 background_depth=_core.DEFAULT_BACKGROUND_DEPTH, emission=None):
        fx, fy, cx, cy = checked.intrinsics(fx, fy, cx, cy)
        background_depth = checked.float32_number("background_depth", background_depth,
                                                  positive=True, allow_inf=True)
        super().__init__(depth, normal, color, fx=fx, fy=fy, cx=cx, cy=cy,
                         background_depth=background_depth, emission=emission)

    def view_positions(self, threads: int = 0):
        """View-space positions (H, W, 3); NaN on background."""
        return super().view_positions(threads=checked.threads(threads))

    def prepared_normals(self, threads: int = 0):
        """The normals methods use: renormalised, facing the camera, estimated from depth
        where missing or degenerate; (0, 0, 0) on background."""
        return super().prepared_normals(threads=checked.threads(threads))


def simd_target() -> str:
    """The instruction set the SIMD kernels run on here, as Highway names it: ``"AVX3"``
    (AVX-512), ``"AVX2"``, ``"SSE4"``, ``"NEON"``, ... (chosen at run time; the build is
    portable)."""
    return _core.simd_target()


def working_memory() -> dict:
    """The cache of working memory (docs/conventions.md, "Working memory"): the large arrays a
    computation allocates (depth copy, prepared normals, pyramids, the result) come from it and
    go back to it, so that the next frame reuses them instead of fresh pages from the system.
    A dict of ``cached_bytes`` (kept idle for the next computation), ``cached_blocks``,
    ``in_use_bytes`` (large arrays alive now, results a caller holds included) and
    ``limit_bytes`` (the cap on ``cached_bytes``, 512 MiB unless set)."""
    return _core.working_memory()


def set_working_memory_limit(limit_bytes: int) -> None:
    """Caps the bytes the cache keeps idle; 0 keeps nothing (every large array is freed when
    done with, as before the cache). Lowering it frees the least recently used blocks down to
    it. Anything but a whole number >= 0 (a bool, a float, a negative number) is a ValueError
    naming ``limit_bytes`` and the value."""
    _core.set_working_memory_limit(limit_bytes)


def release_working_memory() -> None:
    """Frees every block the cache keeps idle (the limit stays): after a burst of large
    frames, to give the memory back at once."""
    _core.release_working_memory()


def methods() -> list[str]:
    """Names of the available methods, e.g. ``['hbao']``."""
    return _core.methods()


def method_info(method: str) -> dict:
    """Description of a method: paper, what it reads, and every setting with its type,
    default, unit, range (``min``, ``max``) or, for a choice, its names (``choices``; the
    default is a name), and meaning."""
    return _core.method_info(method)


def compute(method: str, gbuffer: GBuffer, *, radius: float, threads: int = 0,
            preset: str | None = None, blur: bool | None = None, blur_sigma: float = 1.5,
            blur_taps: int = 5, progress: Progress | None = None, kernel: str = "simd",
            frame: int | None = None, **settings) -> np.ndarray:
    """AO of ``gbuffer`` by ``method`` as a float32 (H, W) array in [0, 1] — or (H, W, 3)
    where the method documents an RGB result (``vao_pp`` with ``color_bleeding=True``).

    ``radius`` is the view-space radius of influence (the reference's AO distance).
    ``settings`` are the method's own (see ``method_info``); a choice setting is given by
    name, e.g. ``falloff="clipped"`` for ``lsao``. ``blur`` applies the separable
    Gaussian of :func:`gaussian_blur` afterwards; it is kept apart from the method so that it
    can be timed apart (1-channel results only). ``threads = 0`` uses all cores; results do
    not depend on it.

    ``preset`` names one of ``presets(method)`` ("default", "low", ..., "tuned-100ms"): its
    settings and blur switch, each overridden by an explicit ``settings`` entry or ``blur``;
    an unknown name is a ValueError listing the method's presets.

    ``kernel`` chooses the implementation: ``"simd"`` (the default) runs the method's
    vectorised kernel where it has one (``method_info(method)["simd_kernel"]``), ``"scalar"``
    its straightforward per-pixel code, the oracle the SIMD kernel is tested against; the two
    differ by float rounding only (docs/benchmarks.md).

    ``blur`` must be a bool (``True``, ``False``, a numpy bool) or None (the preset's switch,
    else off); anything else, ``"no"`` or ``1`` included, is a ValueError naming ``blur``.

    ``threads``, ``blur_taps`` and ``frame`` are whole numbers (a bool is not one) in the C++
    side's range, ``blur_sigma`` a number float32 holds: anything else is a ValueError naming
    it and quoting the value.

    ``frame`` (an int >= 0) makes the method's per-pixel random numbers those of that frame of
    a sequence, for :func:`accumulate`: its ``seed`` (given, the preset's or the default)
    becomes ``frame_seed(seed, frame)``; frame 0 is the method as it is. A method without a
    ``seed`` (Chebyshev AO draws nothing at random) is unchanged.
    """
    _require_bool_or_none("blur", blur)
    threads = checked.threads(threads)
    blur_sigma, blur_taps = _blur_values(blur_sigma, blur_taps, "blur_sigma", "blur_taps")
    if preset is not None:
        values = named_presets.settings_of(method, preset)
        preset_blur = bool(values.pop("blur", False))
        values.update(settings)
        blur = preset_blur if blur is None else blur
    else:
        values = dict(settings)
    values["radius"] = radius
    if frame is not None:
        _apply_frame(method, values, frame)
    checked.settings_as_given(values, lambda: method_info(method)["settings"])
    ao = _core.compute(method, gbuffer, values, threads=threads, progress=progress,
                       kernel=kernel)
    if blur:
        if ao.ndim != 2:
            raise ValueError(f"blur applies to 1-channel AO; {method} returned {ao.shape} with "
                             "these settings (use the method's own filter)")
        ao = _core.gaussian_blur(ao, gbuffer, sigma=blur_sigma, taps=blur_taps,
                                 threads=threads)
    return ao


#: The blur's most taps per pass (BlurSettings::taps, core/filters/blur.h).
BLUR_MAX_TAPS = 129


def _blur_values(sigma, taps, sigma_name: str, taps_name: str) -> tuple[float, int]:
    """The blur's sigma and taps checked before they become a float32 and a C int (their
    ranges, [0.1, 64] px and odd in [1, 129], are the C++ side's)."""
    taps = checked.whole_number(taps_name, taps, 1, BLUR_MAX_TAPS, note="(odd)")
    if taps % 2 == 0:
        raise ValueError(f"{taps_name} must be odd, got {taps}")
    return checked.float32_number(sigma_name, sigma, positive=True), taps


def _apply_frame(method: str, values: dict, frame) -> None:
    """``values["seed"]`` made the seed of ``frame`` (compute's ``frame``)."""
    defaults = {s["name"]: s["default"] for s in method_info(method)["settings"]}
    if "seed" not in defaults:
        frame_seed(0, frame)  # still checks the frame
        return
    values["seed"] = frame_seed(values.get("seed", defaults["seed"]), frame)


def frame_seed(seed: int, frame: int) -> int:
    """The seed of ``frame`` of a sequence run at ``seed`` (docs/temporal.md): ``seed`` itself
    for frame 0, for later frames a hash of both in [1, 2**31 - 1], so that every method's
    per-pixel random numbers vary per frame. Both must be whole numbers in [0, 2**31 - 1]
    (a ValueError naming the argument otherwise)."""
    return _core.frame_seed(checked.whole_number("seed", seed),
                            checked.whole_number("frame", frame))


def accumulate(ao: np.ndarray, gbuffer: GBuffer, motion: np.ndarray, history: TemporalHistory,
               *, threads: int = 0, kernel: str = "simd",
               **settings) -> tuple[np.ndarray, np.ndarray]:
    """Temporal accumulation (docs/temporal.md): blends this frame's ``ao`` (H, W) of a method
    on ``gbuffer`` into ``history``, reprojected by ``motion``, and updates ``history`` to
    this frame. Returns ``(accumulated, disoccluded)``: the float32 (H, W) blend, and a bool
    (H, W) mask, True on geometry pixels whose history was rejected (all of them on the
    first frame), where the result is this frame's ``ao`` exactly.

    ``motion`` is float (H, W, 2) in pixels: at ``[j, i]`` the (dx, dy) such that the surface
    seen at pixel centre (i + 0.5, j + 0.5) was at (i + 0.5 + dx, j + 0.5 + dy) in the previous
    frame, y down; NaN on background. A camera pan moving the content k px right gives
    dx = -k. ``settings`` are those of :func:`accumulate_settings` (``alpha``,
    ``max_history``, ``depth_tolerance``, ``normal_tolerance``, ``clamp`` by name: ``"off"``,
    ``"minmax"`` or ``"variance"``, ``variance_gamma``). Vary the method's noise per frame
    with ``compute(..., frame=k)``. ``kernel``: ``"simd"`` (the default) or ``"scalar"``, the
    per-pixel code the SIMD kernel is tested against; the same bits. Bad values are a
    ValueError naming them, and so is an ``ao`` outside [0, 1] (AO is ambient accessibility;
    NaN is refused on geometry pixels); the bits do not depend on ``threads``."""
    threads = checked.threads(threads)
    _require_unit_interval("ao", ao)
    checked.settings_as_given(settings, accumulate_settings)
    return _core.accumulate(ao, gbuffer, motion, history, settings, threads=threads,
                            kernel=kernel)


def _require_unit_interval(name: str, image) -> None:
    """A ValueError naming ``name``, the first pixel and its value when an AO image holds a
    value outside [0, 1] (NaN is left to the C++ side, which refuses it on geometry)."""
    a = np.asarray(image)
    if a.dtype.kind not in "fiu" or a.ndim != 2:
        return   # the C++ side names a wrong dtype or shape
    with np.errstate(invalid="ignore"):
        outside = (a < 0) | (a > 1)
    if outside.any():
        y, x = (int(i) for i in np.argwhere(outside)[0])
        raise ValueError(f"{name} must be in [0, 1] (ambient accessibility), got "
                         f"{checked.shown(a[y, x])} at pixel (x={x}, y={y})")


def accumulate_settings() -> list[dict]:
    """The settings of :func:`accumulate` described as ``method_info`` describes a method's:
    type, default, range (or choices), unit and meaning."""
    return _core.accumulate_settings()


def _require_bool_or_none(name: str, value) -> None:
    """A switch is a real bool: a string such as "no" is truthy, and 0/1 hide a mistake."""
    if value is not None and not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be a bool (True or False) or None, got {value!r} "
                         f"({type(value).__name__})")


def gaussian_blur(ao: np.ndarray, gbuffer: GBuffer, *, sigma: float = 1.5, taps: int = 5,
                  threads: int = 0) -> np.ndarray:
    """Separable Gaussian low-pass of an AO image over the G-buffer's valid pixels:
    background pixels neither contribute nor change."""
    sigma, taps = _blur_values(sigma, taps, "sigma", "taps")
    return _core.gaussian_blur(ao, gbuffer, sigma=sigma, taps=taps,
                               threads=checked.threads(threads))


def metrics(ao: np.ndarray, reference: np.ndarray, mask: np.ndarray | None = None, *,
            threads: int = 0) -> dict:
    """Accuracy of ``ao`` against ``reference`` over ``mask`` (non-zero = scored pixel; all
    pixels when None): dict with ``mae``, ``rmse``, ``psnr``, ``bias`` (mean of ao - reference:
    positive = under-occlusion), ``ssim`` and ``count`` (docs/metrics.md).

    Every metric is finite for finite input, and ``ssim`` lies in [-1, 1] for any finite
    values however large (SSIM of constant +1e20 against -1e20 is -1); a NaN or infinity on a
    scored pixel is a ValueError naming the array and the pixel.

    An RGB result (``vao_pp`` with colour bleeding, (H, W, 3)) is refused with a ValueError:
    it is not an AO value and there is no indirect-diffuse reference to score it against
    (docs/methods/vao_pp.md); report it as an image instead."""
    if np.ndim(ao) == 3 and np.shape(ao)[2] == 3 and np.ndim(reference) == 2:
        raise ValueError(
            f"ao must be a 2-D array (H, W) to be scored, got an RGB image {tuple(np.shape(ao))} "
            "(colour bleeding), which cannot be scored against a 1-channel AO reference "
            f"{tuple(np.shape(reference))}; report it as an image, or score the AO of the same "
            "settings with color_bleeding=False")
    return _core.metrics(ao, reference, mask, threads=checked.threads(threads))


def vao_pp_with_stats(gbuffer: GBuffer, *, radius: float, threads: int = 0,
                      progress: Progress | None = None, **settings) -> tuple[np.ndarray, dict]:
    """``compute("vao_pp", ...)`` that also says what the run did: returns ``(ao, stats)``
    with ``stats`` a dict of ``pixels`` (geometry pixels), ``culled`` (culling candidates of
    the §4.2 pre-pass), ``culled_share`` (= culled / pixels), ``samples`` (evaluated in the
    full-resolution pass), ``mean_samples`` (per geometry pixel, §4.1) and ``prepass_pixels``
    (1/8-resolution pixels evaluated)."""
    values = dict(settings)
    values["radius"] = radius
    checked.settings_as_given(values, lambda: method_info("vao_pp")["settings"])
    return _core.vao_pp_with_stats(gbuffer, values, threads=checked.threads(threads),
                                   progress=progress)


def load_gbuffer(path) -> GBuffer:
    """A G-buffer from a Blender multilayer EXR and its camera sidecar JSON (``<stem>.json``):
    depth, normals, colour (DiffCol) and emission (Emit) where the file has them.
    The returned GBuffer also carries ``reference`` (the AO pass, or None), ``sidecar`` and
    ``motion``: the bridge's motion vectors (the Motion pass of a sequence's frame) as float32
    (H, W, 2) in pixels, (dx, dy) from each pixel centre to where its point was in the
    previous frame, y down, NaN on background (docs/conventions.md, "Motion vectors"); None
    when the file has none. A Motion pass with one channel, or not finite on a surface pixel,
    is a ValueError naming the file.

    ``reference`` is the AO pass as stored, NaN included: an AO pass that is all NaN is still
    returned (an array of NaN, not None), and scoring it selects no pixel (``aolab run`` then
    says the AO pass is all NaN). ``path`` and its sidecar must be regular files: a directory,
    FIFO or device is a ValueError naming the path and what it is (a FIFO is never opened, so
    the call cannot block). The sidecar must be UTF-8 JSON (a leading byte order mark is
    accepted), nest at most 64 levels, and hold fx, fy, cx, cy that fit a float32; any other
    sidecar is a ValueError naming the file (docs/file_formats.md)."""
    data = _core.load_gbuffer_arrays(str(path))
    side = data["sidecar"]
    g = GBuffer(data["depth"], data["normal"], data["color"], fx=side["fx"], fy=side["fy"],
                cx=side["cx"], cy=side["cy"],
                background_depth=side.get("background_depth", _core.DEFAULT_BACKGROUND_DEPTH),
                emission=data["emission"])
    g.reference = data["ao"]
    g.sidecar = side
    g.path = str(path)
    g.motion = motion_pass.read_motion(path, list(data["channels"]), data["depth"],
                                       g.background_depth)
    return g


def save_gbuffer(path, gbuffer: GBuffer, *, reference: np.ndarray | None = None,
                 sidecar: dict | None = None) -> None:
    """Writes ``gbuffer`` (and an optional AO reference) as a Blender-style multilayer EXR with
    its camera sidecar, atomically."""
    _core.save_gbuffer(str(path), gbuffer, reference, sidecar or {})


def write_image(path, image: np.ndarray) -> None:
    """Writes an AO image: ``.exr`` as float32, ``.png`` as 8-bit (value·255, no transfer
    curve), durably and atomically (aolab.files): a failed write raises OSError and leaves the
    earlier file."""
    _core.write_image(str(path), image)


def encode_image(path, image: np.ndarray) -> bytes:
    """The bytes :func:`write_image` would write to ``path`` (its extension picks EXR or PNG),
    to put several files in place together with ``aolab.files.write_together``."""
    return _core.encode_image(str(path), image)


def load_mesh(path):
    """The scene geometry of a ``.mesh`` file (the bridge's ``mesh`` pass, `aolab mesh`):
    a ``Mesh`` with ``vertices`` float32 (V, 3) in world space, ``triangles`` uint32 (T, 3)
    and ``info``, its ``.mesh.json`` ({} without one). Every inconsistency is a ValueError
    naming the file (docs/file_formats.md, "Scene geometry")."""
    return mesh_file.read_mesh(path)


def mesh_for_gbuffer(g, *, allow_unknown_scene: bool = False):
    """The ``Mesh`` exported with G-buffer ``g`` (from ``load_gbuffer``): ``<stem>.mesh``
    beside ``g.path``, checked to be the same scene (its scene_hash equals the sidecar's;
    one without a scene_hash only with ``allow_unknown_scene``), else a ValueError saying how
    to export one."""
    return mesh_file.mesh_for_gbuffer(g, allow_unknown_scene=allow_unknown_scene)


def analytic_scene_names() -> list[str]:
    """Names of the built-in analytic scenes (docs/analytic_scenes.md)."""
    return _core.analytic_scene_names()


def analytic_scene(name: str, width: int = 320, height: int = 180, **params) -> GBuffer:
    """A G-buffer of a built-in scene with known answers, rendered exactly. Its
    ``reference`` is the closed-form Cycles AO for ``params['radius']`` (default 1) where the
    scene has one, NaN elsewhere; ``camera_to_world`` is a 4x4 list (row-major).

    ``width`` and ``height`` are whole numbers in [1, 16384], the command line's cap (a
    larger side would need tens of gigabytes), and numeric ``params`` numbers float32 holds
    (the depth is float32): anything else is a ValueError naming it."""
    width = checked.whole_number("width", width, 1, MAX_SIDE)
    height = checked.whole_number("height", height, 1, MAX_SIDE)
    checked.float32_params(params)
    data = _core.analytic_scene(name, width, height, params)
    g = GBuffer(data["depth"], data["normal"], fx=data["fx"], fy=data["fy"], cx=data["cx"],
                cy=data["cy"])
    g.reference = data["reference"]
    g.camera_to_world = data["camera_to_world"]
    g.sidecar = {"width": width, "height": height, "fx": data["fx"], "fy": data["fy"],
                 "cx": data["cx"], "cy": data["cy"], "camera_to_world": data["camera_to_world"],
                 "ao_distance": params.get("radius", 1.0), "normal_space": "view",
                 "scene": f"analytic:{name}", "params": params}
    return g


def presets(method: str) -> dict:
    """Every named preset of ``method`` as name -> settings, each with its "blur" switch:
    "default" (every setting's default, R excepted), the study's presets cheapest first
    (aolab.catalog; a builtin blur switch off where the shared blur replaces it) and the tuned
    presets of tuned_presets.json cheapest first (``aolab tune``, docs/tuning.md). An unknown
    method, or a tuned-presets file that is not what ``aolab tune`` writes, is a ValueError."""
    return named_presets.presets_of(method)
