"""AO Lab for Blender: compare screen-space AO methods with a Cycles AO reference, in Blender.

The package holds bpy-free logic (intrinsics, passes, exr, lab, study, work, reference_job)
beside the Blender glue (state, export, batch, peers; the add-on: preferences, properties,
images, operators, ui). The aolab command imports its bpy-free parts outside Blender, so the
add-on's classes are only imported where bpy is. docs/blender_addon.md.
"""

bl_info = {
    "name": "AO Lab",
    "author": "AO Lab",
    "version": (0, 2, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > Sidebar > AO Lab; Properties > View Layer > AO Lab",
    "description": "Screen-space AO methods scored against a Cycles AO reference",
    "category": "Render",
}

try:
    import bpy
except ImportError:  # imported by the aolab command for its bpy-free modules
    bpy = None
    classes = ()
else:
    from . import operators, preferences, properties, ui
    classes = (preferences.AOLAB_AddonPreferences, *operators.CLASSES, *ui.CLASSES)


def register():
    """The classes in order, then the property groups (properties.register builds one per
    method of aolab.methods() and hooks them onto Scene and WindowManager)."""
    for cls in classes:
        bpy.utils.register_class(cls)
    properties.register()


def unregister():
    properties.unregister()
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
