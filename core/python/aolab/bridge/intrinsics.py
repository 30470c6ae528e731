"""Pinhole intrinsics of a Blender perspective camera (no bpy).

Blender's own camera projection, written out (the formulas and how they were measured:
docs/blender_facts.md, "Camera intrinsics"): verified against Cycles' Position pass by
tests/python/bridge/test_bridge.py (tests/blender/camera_check.py) for every sensor fit, with
shifts and non-square pixels.
"""

from __future__ import annotations

from .. import _core

SUPPORTED_CAMERA_TYPES = ("PERSP",)


def image_size(resolution_x: int, resolution_y: int, percentage: int) -> tuple[int, int]:
    """Rendered size in pixels: resolution × percentage / 100 (Blender truncates)."""
    return resolution_x * percentage // 100, resolution_y * percentage // 100


def intrinsics(width: int, height: int, *, lens: float, sensor_width: float,
               sensor_height: float, sensor_fit: str, shift_x: float = 0.0,
               shift_y: float = 0.0, pixel_aspect_x: float = 1.0,
               pixel_aspect_y: float = 1.0) -> dict:
    """fx, fy, cx, cy in pixels (cy from the top row) for a render of width × height.

    sensor_fit AUTO is horizontal when width·ax >= height·ay (and then always uses
    sensor_width); HORIZONTAL uses sensor_width, VERTICAL sensor_height.
    """
    if width < 1 or height < 1:
        raise ValueError(f"width and height must be >= 1, got {width}x{height}")
    if not lens > 0:
        raise ValueError(f"lens must be > 0 mm, got {lens}")
    ax, ay = float(pixel_aspect_x), float(pixel_aspect_y)
    ycor = ay / ax
    if sensor_fit == "AUTO":
        horizontal = width * ax >= height * ay
        sensor = sensor_width
    elif sensor_fit == "HORIZONTAL":
        horizontal, sensor = True, sensor_width
    elif sensor_fit == "VERTICAL":
        horizontal, sensor = False, sensor_height
    else:
        raise ValueError(f"sensor_fit must be AUTO, HORIZONTAL or VERTICAL, got {sensor_fit!r}")
    viewfac = width if horizontal else ycor * height
    fx = lens / sensor * viewfac
    fy = fx * ax / ay
    cx = width / 2 - shift_x * viewfac
    cy = height / 2 + shift_y * viewfac / ycor
    return {"fx": fx, "fy": fy, "cx": cx, "cy": cy}


def max_ray_coordinate() -> float:
    """The largest magnitude of a coordinate the ray tracers can take (Embree's FLT_LARGE,
    kMaxRayCoordinate in core/raytracing/ray_scene.h): Cycles, which traces with Embree, dies
    on a ray from beyond it, and rtao refuses it."""
    return _core.MAX_RAY_COORDINATE


def check_camera_to_world(matrix) -> None:
    """ValueError unless ``matrix`` (4x4, row-major, the camera's scale removed) is a
    rotation and a translation: a camera under an unevenly scaled, rotated parent is sheared,
    and neither its pinhole projection nor the move of triangles and normals into its view
    space holds. The ray tracer's own rule and tolerance (``RayScene``,
    core/raytracing/ray_scene.h), so that a camera the bridge renders from is one rtao takes."""
    _core.check_camera_to_world(matrix)
