"""AO Lab for Blender: exports G-buffers and renders Cycles AO references for AO Lab.

The package holds bpy-free logic (intrinsics, passes, exr) beside the Blender glue (state,
export, batch). The artist panel arrives with issue 7; for now the add-on registers nothing
and its modules are used by `aolab reference` through `blender -b`.
"""

bl_info = {
    "name": "AO Lab",
    "author": "AO Lab",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Used by the aolab command (aolab reference)",
    "description": "Screen-space AO methods scored against a Cycles AO reference",
    "category": "Render",
}

# Registered from a tuple in a loop, unregistered in reverse (the panel comes in issue 7).
classes = ()


def register():
    import bpy
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    import bpy
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
