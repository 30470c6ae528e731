"""Checks of the study's inputs against Cycles: ``rtao_check`` (the ray-traced peer against
the references) and ``bridge_check`` (the bridge's renders against the committed references).
The kernels' benchmarks are in ``aolab.benchmarks``.
"""
