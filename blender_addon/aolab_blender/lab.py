"""The add-on's door to the compiled `aolab` module (no bpy).

`aolab` is found through the .pth that scripts/setup.sh writes into Debian's site directory
(Blender's Python reads it too), so the user never touches sys.path. If it does not import,
`available()` is False and `IMPORT_ERROR` says why; the panel then shows NOT_BUILT.

Scoring is the command line's: `aolab run METHOD reference.exr` computes with the settings
given (the others keep the method's C++ defaults), and scores with aolab.metrics over the
valid pixels where the reference is finite (cli._scored_mask). The same inputs give the same
bits here.
"""

from __future__ import annotations

import time

import numpy as np

try:
    import aolab
    IMPORT_ERROR = None
except ImportError as e:  # not built, or built for another Python
    aolab = None
    IMPORT_ERROR = str(e)

NOT_BUILT = "module not built: run scripts/setup.sh"
SHARED_SETTINGS = ("radius",)  # set once for every method (the panel's R)

# Signed error maps (method - reference), the report's colours: white at 0, blue where the
# method is lighter (under-occlusion), red where darker; full colour at |error| >= scale.
ERROR_SCALE = 0.25
LIGHTER_RGB = (0.1, 0.3, 0.9)
DARKER_RGB = (0.85, 0.1, 0.1)
BACKGROUND_GREY = 0.5


def available() -> bool:
    return aolab is not None


def methods() -> list[str]:
    return list(aolab.methods()) if aolab is not None else []


def method_settings(method: str) -> list[dict]:
    """The method's own settings (name, type, default, min, max, unit, description), without
    the shared radius."""
    return [s for s in aolab.method_info(method)["settings"] if s["name"] not in SHARED_SETTINGS]


def changed_settings(method: str, values: dict) -> dict:
    """The entries of `values` that differ from the method's defaults. Blender keeps floats in
    single precision: a value equal to float32(default) is the default, and is left to the
    C++ side, so that untouched settings give exactly what the command line gives."""
    out = {}
    for s in method_settings(method):
        if s["name"] not in values:
            continue
        v = values[s["name"]]
        if s["type"] == "float":
            if np.float32(v) != np.float32(s["default"]):
                out[s["name"]] = float(v)
        elif s["type"] == "bool":
            if bool(v) != bool(s["default"]):
                out[s["name"]] = bool(v)
        elif int(v) != int(s["default"]):
            out[s["name"]] = int(v)
    return out


def load(path: str):
    """A G-buffer (with .reference and .sidecar) from a reference EXR."""
    return aolab.load_gbuffer(path)


def compute(method: str, g, *, radius: float, settings: dict, blur: bool, threads: int):
    """(AO image, seconds). The GIL is released inside, so this runs in a worker thread."""
    t0 = time.perf_counter()
    ao = aolab.compute(method, g, radius=radius, threads=threads, blur=blur, **settings)
    return ao, time.perf_counter() - t0


def scored_mask(g) -> np.ndarray | None:
    """The command line's mask: valid pixels where the reference is finite (None: no
    reference to score against)."""
    ref = getattr(g, "reference", None)
    if ref is None:
        return None
    mask = g.valid_mask() & np.isfinite(ref)
    return mask if mask.any() else None


def score(ao: np.ndarray, g) -> dict | None:
    mask = scored_mask(g)
    return None if mask is None else dict(aolab.metrics(ao, g.reference, mask))


def signed_error_rgb(ao: np.ndarray, reference: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """(H, W, 3) float32 colour map of ao - reference; background pixels grey."""
    err = np.where(valid, ao - reference, 0.0).astype(np.float32)
    t = np.clip(np.abs(err) / ERROR_SCALE, 0, 1)[..., None]
    colour = np.where(err[..., None] < 0, np.float32(DARKER_RGB), np.float32(LIGHTER_RGB))
    rgb = (1 - t) + t * colour
    rgb[~valid] = BACKGROUND_GREY
    return rgb.astype(np.float32)
