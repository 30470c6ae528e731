"""Rendering references with Blender: ``reference`` (``aolab reference``: the plan of each
render, its cache key and cache, running Blender in-process) and ``cluster`` (the same plans
on a Dask cluster). The caller chooses where the plans run; neither module imports the other's
caller (the ``aolab reference`` command in ``aolab.cli.reference``).
"""
