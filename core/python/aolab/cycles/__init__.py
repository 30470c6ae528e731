"""Cycles references (and the EEVEE peers and scene meshes of the same Blender runs) rendered
by Blender in the background, cached. Lowest first:

- ``blender``: the Blender process (finding it, its release, the bridge script, running it
  under xvfb-run and dying with its parent);
- ``plan``: what a run renders (the scene, the plan) and its cache key;
- ``cache``: the cache's entries (verified, found by content, stale temporaries removed);
- ``console``: the lines a run of plans prints;
- ``run``: ``render`` and ``run_plans`` in this process (``aolab reference``, ``aolab mesh``);
- ``cluster``: the same plans on a Dask cluster.

The caller chooses where the plans run; ``run`` never imports ``cluster`` (the ``aolab
reference`` command in ``aolab.cli.reference`` chooses).
"""
