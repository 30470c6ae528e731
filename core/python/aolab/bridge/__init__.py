"""The Blender bridge's bpy-free side: the files and facts both halves of the bridge share,
as pure I/O that needs neither Blender nor the study.

- ``constants``: what both sides agree on (file names, bridge version, the peers' ladder);
- ``intrinsics``: pinhole intrinsics of a Blender camera;
- ``passes``: which render passes a reference needs;
- ``exr``: reading Blender's multilayer EXRs, writing the merged G-buffer and the peers;
- ``mesh``: the ``.mesh`` scene-geometry file;
- ``motion``: Cycles' Vector pass in AO Lab's motion convention, the Motion pass read back;
- ``outputs``: the files an export writes, checked not to be the scene or one another.

The bpy side (``blender_addon/aolab_blender``: its export package, the panel's classes)
imports these modules; nothing in ``aolab`` imports bpy or ``aolab_blender``
(tests/python/repository/test_import_direction.py). The panel's work off Blender's main thread is in
``aolab.jobs``.
"""
