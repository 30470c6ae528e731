"""The Blender bridge's bpy-free side: everything of the bridge and the AO Lab add-on that
does not need Blender's Python API.

- ``constants``: what both sides agree on (file names, bridge version, the peers' ladder);
- ``intrinsics``: pinhole intrinsics of a Blender camera;
- ``passes``: which render passes a reference needs;
- ``exr``: reading Blender's multilayer EXRs, writing the merged G-buffer and the peers;
- ``jobs``: the add-on's work off Blender's main thread (preview, reference, compare, report);
- ``reference_job``: the child process the add-on renders references with.

The bpy side (``blender_addon/aolab_blender``: export, peers, batch, the add-on's classes)
imports these modules; nothing in ``aolab`` imports bpy or ``aolab_blender``
(tests/python/test_import_direction.py).
"""
