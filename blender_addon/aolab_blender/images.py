"""Results as Blender images (bpy; main thread only).

Images are named "AO Lab <method>", "AO Lab <method> error", "AO Lab reference" and "AO Lab
advise" (the front Advise draws): float RGBA buffers in Non-Color (the values are shown as
they are, like the command line's PNGs, which write value x 255 with no transfer curve). A
repeated Preview or Compare overwrites them in place (rescaled when the size changed), so an
Image Editor showing one updates. The front is also a preview icon (set_preview), which the
panel draws inside itself; release() frees the previews when the add-on is disabled.
"""

import bpy
import numpy as np

PREFIX = "AO Lab "
#: The front Advise draws: image_name(ADVICE), and the preview icon of that name.
ADVICE = "advise"


def image_name(method: str, kind: str = "") -> str:
    return PREFIX + method + (f" {kind}" if kind else "")


#: The RGBA scratch buffer of the last image size (alpha 1 throughout): a live update at
#: 640x360 writes 3.7 MB, and a fresh array per update costs more than the copy (page faults).
_scratch: dict[tuple[int, int], np.ndarray] = {}


def _rgba(h: int, w: int) -> np.ndarray:
    buf = _scratch.get((h, w))
    if buf is None:
        _scratch.clear()   # one size at a time
        buf = _scratch[(h, w)] = np.ones((h, w, 4), np.float32)
    return buf


def blender_rgba(pixels: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """An (H, W) grey or (H, W, 3) colour array (row 0 at the top, as aolab returns it) as
    Blender's float32 RGBA pixels (rows from the bottom, alpha 1), (H, W, 4). Numpy only, no
    bpy: a worker thread may call it (Live does, so that the main thread only copies)."""
    h, w = pixels.shape[:2]
    if out is None:
        out = np.empty((h, w, 4), np.float32)
        out[..., 3] = 1.0
    np.copyto(out[..., :3], pixels[::-1, :, None] if pixels.ndim == 2 else pixels[::-1, :, :3])
    return out


def set_image(name: str, pixels: np.ndarray, *, rgba: np.ndarray | None = None
              ) -> bpy.types.Image:
    """Writes an (H, W) grey or (H, W, 3) colour array (row 0 at the top, as aolab returns
    it) into the image `name`, creating or resizing it; `rgba`: blender_rgba(pixels),
    made already. No per-pixel Python: numpy flips the rows into a float32 RGBA buffer
    (reused) and one foreach_set copies it."""
    h, w = pixels.shape[:2]
    if rgba is None:
        rgba = blender_rgba(pixels, _rgba(h, w))
    image = bpy.data.images.get(name)
    if image is not None and (not image.is_float or image.type != "IMAGE"):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    elif tuple(image.size) != (w, h):
        image.scale(w, h)
    if image.colorspace_settings.name != "Non-Color":   # setting it frees the pixels
        image.colorspace_settings.name = "Non-Color"
    image.pixels.foreach_set(rgba.ravel())
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


#: The add-on's preview icons (bpy.utils.previews), made on first use.
_previews = {}


def set_preview(name: str, pixels: np.ndarray) -> int:
    """Writes an (H, W, 3 or 4) colour array (row 0 at the top) into the preview icon
    `name`, at its own size; returns its icon_id (UILayout.template_icon shows it)."""
    import bpy.utils.previews
    if "collection" not in _previews:
        _previews["collection"] = bpy.utils.previews.new()
    collection = _previews["collection"]
    preview = collection.get(name) or collection.new(name)
    h, w = pixels.shape[:2]
    preview.image_size = (w, h)
    preview.image_pixels_float.foreach_set(blender_rgba(pixels[..., :3]).ravel())
    return preview.icon_id


def preview(name: str):
    """The ImagePreview `name`, or None."""
    collection = _previews.get("collection")
    return collection.get(name) if collection is not None else None


def preview_icon(name: str) -> int:
    """The icon_id of the preview `name`; 0 when there is none, and in background mode
    (`blender -b`), where Blender makes no icons."""
    found = preview(name)
    return found.icon_id if found is not None else 0


def release() -> None:
    """Frees the preview icons (the add-on is being disabled)."""
    collection = _previews.pop("collection", None)
    if collection is not None:
        import bpy.utils.previews
        bpy.utils.previews.remove(collection)
