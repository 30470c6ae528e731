"""AO Lab for Blender: compare screen-space AO methods with a Cycles AO reference, in Blender.

This package holds only what needs bpy, in two halves that import one way
(docs/blender_addon.md, "Modules"):
- the panel (the add-on's UI, main thread): preferences, hooks, library (its one guarded
  door to `aolab`), properties, inputs, live, operators, ui, images;
- export/, headless (what runs under `blender -b`): the bridge's Blender glue (state,
  compat, scene_record, mesh, reference, peers) and batch.py, the entry point `aolab
  reference` runs inside Blender. It imports nothing of the panel.
Everything else comes from the `aolab` package (`aolab.bridge`, `aolab.jobs`: the panel's
background jobs, and the study's modules), which never imports this one.
"""

import bpy

from . import images, live, operators, preferences, properties, ui

bl_info = {
    "name": "AO Lab",
    "author": "AO Lab",
    "version": (0, 3, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > Sidebar > AO Lab; Properties > View Layer > AO Lab",
    "description": "Screen-space AO methods scored against a Cycles AO reference",
    "category": "Render",
}

classes = (preferences.AOLAB_AddonPreferences, *operators.CLASSES, *ui.CLASSES)


def register():
    """The classes in order, then the property groups (properties.register builds one per
    method of aolab.methods() and hooks them onto Scene and WindowManager), then Live's
    handlers."""
    for cls in classes:
        bpy.utils.register_class(cls)
    properties.register()
    live.register()


def unregister():
    live.unregister()   # first: no timer may fire into unregistered properties
    images.release()    # the preview icons (the front Advise draws)
    properties.unregister()
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
