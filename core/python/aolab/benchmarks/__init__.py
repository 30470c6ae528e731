"""Benchmarks of the kernels, timed on analytic and reference scenes (docs/benchmarks.md):
``kernel_bench`` (each method's scalar code against its SIMD kernel), ``geometry_bench``
(each method's time against the geometry on screen, ``aolab bench-table``) and ``mip_bench``
(the mip-mapped depth's effect, ``aolab bench-table --mip``).
"""
