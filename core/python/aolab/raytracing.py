"""rtao: Cycles' AO integral ray traced on the CPU (Embree) against the scene's triangles, from
the points of a G-buffer (docs/methods/rtao.md). The triangles come from the bridge's `mesh`
pass (`aolab mesh`, or `aolab reference --passes ...,mesh`; docs/blender_bridge.md)."""

from __future__ import annotations

import warnings

import numpy as np

from . import _core

RayScene = _core.RayScene
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


def ray_scene(mesh, gbuffer=None, *, camera_to_world=None, threads: int = 0) -> RayScene:
    """The BVH of ``mesh`` (anything with world-space ``vertices`` (V, 3) and ``triangles``
    (T, 3), e.g. ``aolab.load_mesh(...)``) in the view space of ``gbuffer``'s camera, or of
    ``camera_to_world`` when given. Build it once to trace several times; its
    ``build_seconds`` is the BVH build's wall-clock time."""
    if camera_to_world is None:
        camera_to_world = camera_to_world_of(gbuffer, mesh)
    return RayScene(mesh.vertices, mesh.triangles, camera_to_world, threads=threads)


def rtao(gbuffer, scene, *, radius: float, rays: int = DEFAULT_RAYS, seed: int = 0,
         threads: int = 0, progress=None) -> np.ndarray:
    """Ray-traced AO of every geometry pixel of ``gbuffer`` (which needs normals) as a float32
    (H, W) array in [0, 1], background 1: ``rays`` stratified cosine-weighted rays per pixel
    from the point its depth gives, a hit within ``radius`` occluding (Cycles' AO pass,
    docs/conventions.md).

    ``scene`` is a :class:`RayScene` (built once, e.g. by :func:`ray_scene`) or a mesh (then
    built here, for this call only). The same inputs give the same bits for any ``threads``.
    The GIL is released while rays are traced.

    Each ray starts a small offset ε off the surface (docs/methods/rtao.md): a G-buffer on
    which ε ≥ ``radius`` at some pixel is a ValueError saying what to change, and where ε
    exceeds 1 % of ``radius`` an :class:`RtaoRangeWarning` says on how many pixels
    (:func:`rtao_range` gives the same numbers without tracing)."""
    if not isinstance(scene, RayScene):
        scene = ray_scene(scene, gbuffer, threads=threads)
    ao, offsets = _core.rtao(gbuffer, scene, {"radius": radius, "rays": rays, "seed": seed},
                             threads=threads, progress=progress)
    if offsets["warning"]:
        warnings.warn(offsets["warning"], RtaoRangeWarning, stacklevel=2)
    return ao


def rtao_range(gbuffer, scene, *, radius: float, threads: int = 0) -> dict:
    """How rtao's ray offset ε compares with ``radius`` over the pixels of ``gbuffer`` it
    traces from, without tracing (docs/conventions.md, "Ranges"): ``pixels``, how many of
    them have ε above 1 % of R (``warned``) or ε ≥ R (``refused``), or a point beyond the ray
    tracer's range (``beyond``); the ``largest`` offset with its parts (pixel ``x``, ``y``,
    ``depth``, ``epsilon``, ``footprint``, ``scale``, ``point_distance``) and
    ``largest_share_of_radius``; the scene's ``camera_distance`` and ``longest_edge``; and
    the texts of rtao's ``refusal`` and ``warning`` (None when there is none). ``scene`` is a
    :class:`RayScene` or a mesh, as for :func:`rtao`."""
    if not isinstance(scene, RayScene):
        scene = ray_scene(scene, gbuffer, threads=threads)
    return _core.rtao_range(gbuffer, scene, radius, threads=threads)


def analytic_scene_mesh(name: str, extent: float = 1000.0, **params):
    """The built-in analytic scene ``name`` (the same ``params`` as ``aolab.analytic_scene``)
    as world-space triangles ``(vertices (V, 3) float32, triangles (T, 3) uint32)``: each
    face a square of half-side ``extent`` about the camera, clipped to the face, so unbounded
    planes end ``extent`` away."""
    params.pop("radius", None)  # the closed form's R; the geometry does not depend on it
    return _core.analytic_scene_mesh(name, params, float(extent))
