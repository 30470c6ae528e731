"""The add-on's headless half (bpy, no UI): what runs inside `blender -b` for `aolab
reference` and `aolab mesh`, and what the panel reads of a scene before it exports one.

- ``state``: SettingsRestorer, every changed setting put back;
- ``compat``: what differs between the Blender releases AO Lab supports;
- ``scene_record``: the camera, its record and the content hash that a reference, its mesh
  and its peers share (below them), and the bridge's errors;
- ``mesh``: the scene's triangles as rendered (the `mesh` pass);
- ``reference``: the G-buffer and the Cycles AO reference, two renders merged into one EXR;
- ``peers``: the comparison peers (the Cycles ladder and EEVEE);
- ``batch``: the entry point `aolab reference` runs inside Blender (a script, not imported).

Nothing here imports the panel's modules (operators, ui, properties, live...); the panel
imports scene_record (through its library.py: it needs `aolab`).
"""
