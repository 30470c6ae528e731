"""What every layer of ``aolab`` may use, and which uses nothing of ``aolab`` but the compiled
core: ``files`` (the one way to write a file durably and atomically, to check a file before
reading it, and to hold an output folder for one run), ``provenance`` (the machine and commit a
result records), ``markdown`` (the generated blocks of a committed Markdown page) and
``arguments`` (argparse types that check a value and name the option, shared by the ``aolab``
command and the bridge's entry point inside Blender).
"""
