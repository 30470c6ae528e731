"""rtao: Cycles' AO integral ray traced on the CPU (Embree) against the scene's triangles, from
the points of a G-buffer (docs/methods/rtao.md). The triangles come from the bridge's `mesh`
pass (`aolab mesh`, or `aolab reference --passes ...,mesh`; docs/blender_bridge.md)."""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np

from . import _core
from .bridge.mesh import check_pairing
from .util import values as checked


class RayScene(_core.RayScene):
    __doc__ = _core.RayScene.__doc__

    def __init__(self, vertices, triangles, camera_to_world, *, threads: int = 0):
        super().__init__(vertices, triangles, camera_to_world, threads=checked.threads(threads))


#: The default rays per pixel: the reference's own 1024 samples (core/raytracing/rtao.h).
DEFAULT_RAYS = next(s["default"] for s in _core.rtao_settings() if s["name"] == "rays")
#: rtao's rays per pixel in the study (`aolab compare --rtao-rays`): the CPU ray tracer's
#: ladder, timed on the same cores as the methods (docs/methods/rtao.md).
RTAO_LADDER = (1, 2, 4, 8, 16, 64)


class RtaoRangeWarning(UserWarning):
    """rtao traced, but its ray offset exceeds 1 % of R on some pixels, where occluders
    nearer than the offset to a surface are lost (docs/conventions.md, "Ranges")."""


def rtao_settings() -> list[dict]:
    """rtao's settings (radius, rays, seed) described as ``method_info`` describes a method's:
    type, default, range, unit and meaning."""
    return _core.rtao_settings()


def camera_to_world_of(gbuffer, mesh=None) -> np.ndarray:
    """The 4x4 camera matrix of ``gbuffer``'s sidecar (the view space rtao traces in), else
    the one stored with ``mesh``; a ValueError when neither has one."""
    for source in (getattr(gbuffer, "sidecar", None), getattr(mesh, "info", None)):
        if isinstance(source, dict) and source.get("camera_to_world") is not None:
            return np.asarray(source["camera_to_world"], np.float64)
    raise ValueError("camera_to_world: neither the G-buffer's sidecar nor the mesh names the "
                     "camera; pass camera_to_world= (the 4x4 camera matrix, row-major)")


def ray_scene(mesh, gbuffer=None, *, camera_to_world=None, threads: int = 0,
              allow_unknown_scene: bool = False) -> RayScene:
    """The BVH of ``mesh`` (anything with world-space ``vertices`` (V, 3) and ``triangles``
    (T, 3), e.g. ``aolab.load_mesh(...)``) in the view space of ``gbuffer``'s camera, or of
    ``camera_to_world`` when given. Build it once to trace several times; its
    ``build_seconds`` is the BVH build's wall-clock time.

    With ``gbuffer``, the two are paired by one rule (``aolab.bridge.mesh.check_pairing``):
    a mesh whose .mesh.json names another scene_hash than the G-buffer's sidecar is a
    ValueError naming both; a mesh read from a file whose scene cannot be checked (one side
    has no scene_hash) is one too unless ``allow_unknown_scene``; a mesh made in memory is
    not checked. The scene remembers where its mesh came from, so that :func:`rtao` checks
    it against the G-buffer it is traced for."""
    if gbuffer is not None:
        check_pairing(gbuffer, mesh, allow_unknown_scene=allow_unknown_scene)
    if camera_to_world is None:
        camera_to_world = camera_to_world_of(gbuffer, mesh)
    scene = RayScene(mesh.vertices, mesh.triangles, camera_to_world, threads=threads)
    scene.mesh_source = SimpleNamespace(info=dict(getattr(mesh, "info", None) or {}),
                                        path=getattr(mesh, "path", "") or "")
    return scene


def _paired_scene(gbuffer, scene, threads: int, allow_unknown_scene: bool) -> RayScene:
    """``scene`` (a RayScene or a mesh) as a RayScene, paired with ``gbuffer`` by
    check_pairing through the mesh it was built from."""
    if not isinstance(scene, RayScene):
        return ray_scene(scene, gbuffer, threads=threads,
                         allow_unknown_scene=allow_unknown_scene)
    source = getattr(scene, "mesh_source", None)
    if source is not None:
        check_pairing(gbuffer, source, allow_unknown_scene=allow_unknown_scene)
    return scene


def rtao(gbuffer, scene, *, radius: float, rays: int = DEFAULT_RAYS, seed: int = 0,
         threads: int = 0, progress=None, allow_unknown_scene: bool = False) -> np.ndarray:
    """Ray-traced AO of every geometry pixel of ``gbuffer`` (which needs normals) as a float32
    (H, W) array in [0, 1], background 1: ``rays`` stratified cosine-weighted rays per pixel
    from the point its depth gives, a hit within ``radius`` occluding (Cycles' AO pass,
    docs/conventions.md).

    ``scene`` is a :class:`RayScene` (built once, e.g. by :func:`ray_scene`) or a mesh (then
    built here, for this call only); either way its mesh is paired with ``gbuffer`` as
    :func:`ray_scene` says (``allow_unknown_scene``). The same inputs give the same bits for
    any ``threads``. The GIL is released while rays are traced.

    Each ray starts a small offset ε off the surface (docs/methods/rtao.md): a G-buffer on
    which ε ≥ ``radius`` at some pixel is a ValueError saying what to change, and where ε
    exceeds 1 % of ``radius`` an :class:`RtaoRangeWarning` says on how many pixels
    (:func:`rtao_range` gives the same numbers without tracing)."""
    threads = checked.threads(threads)
    settings = {"radius": radius, "rays": rays, "seed": seed}
    checked.settings_as_given(settings, rtao_settings)
    scene = _paired_scene(gbuffer, scene, threads, allow_unknown_scene)
    ao, offsets = _core.rtao(gbuffer, scene, settings, threads=threads, progress=progress)
    if offsets["warning"]:
        warnings.warn(offsets["warning"], RtaoRangeWarning, stacklevel=2)
    return ao


def rtao_range(gbuffer, scene, *, radius: float, threads: int = 0,
               allow_unknown_scene: bool = False) -> dict:
    """How rtao's ray offset ε compares with ``radius`` over the pixels of ``gbuffer`` it
    traces from, without tracing (docs/conventions.md, "Ranges"): ``pixels``, how many of
    them have ε above 1 % of R (``warned``) or ε ≥ R (``refused``), or a point beyond the ray
    tracer's range (``beyond``); the ``largest`` offset with its parts (pixel ``x``, ``y``,
    ``depth``, ``epsilon``, ``footprint``, ``scale``, ``point_distance``) and
    ``largest_share_of_radius``; the scene's ``camera_distance``, ``longest_edge`` and
    ``coordinate_scale``; and the texts of rtao's ``refusal`` and ``warning`` (None when there
    is none). ``scene`` is a :class:`RayScene` or a mesh, paired as for :func:`rtao`."""
    threads = checked.threads(threads)
    radius = checked.float32_number("radius", radius, positive=True)
    scene = _paired_scene(gbuffer, scene, threads, allow_unknown_scene)
    return _core.rtao_range(gbuffer, scene, radius, threads=threads)


def analytic_scene_mesh(name: str, extent: float = 1000.0, **params):
    """The built-in analytic scene ``name`` (the same ``params`` as ``aolab.analytic_scene``)
    as world-space triangles ``(vertices (V, 3) float32, triangles (T, 3) uint32)``: each
    face a square of half-side ``extent`` about the camera, clipped to the face, so unbounded
    planes end ``extent`` away."""
    params.pop("radius", None)  # the closed form's R; the geometry does not depend on it
    checked.float32_params(params)
    extent = checked.float32_number("extent", extent, positive=True)
    return _core.analytic_scene_mesh(name, params, extent)
