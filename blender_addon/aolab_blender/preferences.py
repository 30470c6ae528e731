"""Add-on preferences: the reference cache folder and the worker thread count (bpy)."""

from pathlib import Path

import bpy

# `# noqa: F722` / `F821` below: pyflakes reads the strings in bpy property annotations
# (`name: bpy.props.StringProperty(name="Cache Folder")`) as forward references to types.


class AOLAB_AddonPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    cache_dir: bpy.props.StringProperty(
        name="Cache Folder", subtype="DIR_PATH", default="",  # noqa: F722,F821
        description="Where rendered references are kept (empty: $AOLAB_CACHE, else "  # noqa: F722
                    "~/.cache/aolab/references, as the aolab command)")
    threads: bpy.props.IntProperty(
        name="Threads", default=0, min=0, max=1024,  # noqa: F821
        description="Worker threads for the AO methods (0 = all cores; results do "  # noqa: F722
                    "not depend on it)")

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "cache_dir")
        layout.prop(self, "threads")
        layout.label(text=f"Cache in use: {cache_dir(context)}")


def get(context):
    """The preferences, or None when the package is imported without being enabled as an
    add-on (then the defaults apply)."""
    addon = context.preferences.addons.get(__package__)
    return addon.preferences if addon is not None else None


def cache_dir(context) -> Path:
    prefs = get(context)
    if prefs is not None and prefs.cache_dir:
        return Path(bpy.path.abspath(prefs.cache_dir))
    try:
        from aolab.cycles.cache import default_cache
    except ImportError:  # not built: the panel says so; the default folder, as aolab's
        return Path("~/.cache/aolab/references").expanduser()
    return default_cache()


def threads(context) -> int:
    prefs = get(context)
    return prefs.threads if prefs is not None else 0
