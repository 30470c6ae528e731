"""The Blender add-on's work that needs no Blender: ``jobs`` (preview, reference, compare and
report run in a thread off Blender's main thread) and ``reference_job`` (the child process the
add-on renders references with). The add-on (blender_addon/aolab_blender) imports them; they
import the study and the API, never bpy.
"""
