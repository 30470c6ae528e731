"""The background jobs the add-on's panel runs, off Blender's main thread (no bpy).

``runner`` (Job: a task in a thread, its progress, cancellation and child process: the one
worker mechanism), ``tasks`` (Preview, Render Reference, Compare, Quick Compare, Advise and
Write Report), ``live`` (Live's compute: LiveWorker) and ``reference_job`` (the child process
the add-on renders references with). The add-on (blender_addon/aolab_blender) imports them
through its library.py; they import the study and the API, never bpy.
"""
