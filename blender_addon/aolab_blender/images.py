"""Results as Blender images (bpy; main thread only).

Images are named "AO Lab <method>", "AO Lab <method> error" and "AO Lab reference": float
RGBA buffers in Non-Color (the values are shown as they are, like the command line's PNGs,
which write value x 255 with no transfer curve). A repeated Preview or Compare overwrites
them in place (rescaled when the size changed), so an Image Editor showing one updates.
"""

import bpy
import numpy as np

PREFIX = "AO Lab "


def image_name(method: str, kind: str = "") -> str:
    return PREFIX + method + (f" {kind}" if kind else "")


def set_image(name: str, pixels: np.ndarray) -> bpy.types.Image:
    """Writes an (H, W) grey or (H, W, 3) colour array (row 0 at the top, as aolab returns
    it) into the image `name`, creating or resizing it."""
    h, w = pixels.shape[:2]
    rgba = np.ones((h, w, 4), np.float32)
    if pixels.ndim == 2:
        rgba[..., :3] = pixels[..., None]
    else:
        rgba[..., :3] = pixels[..., :3]
    image = bpy.data.images.get(name)
    if image is not None and (not image.is_float or image.type != "IMAGE"):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    elif tuple(image.size) != (w, h):
        image.scale(w, h)
    image.colorspace_settings.name = "Non-Color"
    image.pixels.foreach_set(rgba[::-1].ravel())  # Blender's rows start at the bottom
    image.update()
    return image


def read_image(name: str) -> np.ndarray:
    """The image's RGBA pixels as (H, W, 4) float32, row 0 at the top (tests, checks)."""
    image = bpy.data.images[name]
    w, h = image.size
    out = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(out)
    return out.reshape(h, w, 4)[::-1]


def show(context, name: str) -> str | None:
    """Shows image `name` in an Image Editor: one of the current screen, else a new window.
    Returns an error message, or None."""
    image = bpy.data.images.get(name)
    if image is None:
        return f"no image {name!r}: run Preview or Compare first"
    screen = context.screen
    area = None
    if screen is not None:
        area = next((a for a in screen.areas if a.type == "IMAGE_EDITOR"), None)
    if area is None:
        if bpy.app.background or context.window is None:
            return "no window to open an Image Editor in (Blender runs in the background)"
        before = set(context.window_manager.windows[:])
        try:
            bpy.ops.wm.window_new()
        except RuntimeError as e:
            return f"could not open a window for the Image Editor: {e}"
        new = [w for w in context.window_manager.windows if w not in before]
        if not new:
            return "could not open a window for the Image Editor"
        area = new[0].screen.areas[0]
        area.type = "IMAGE_EDITOR"
    area.spaces.active.image = image
    area.tag_redraw()
    return None
