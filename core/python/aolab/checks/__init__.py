"""Checks of the study's inputs and of the kernels: ``rtao_check`` (the ray-traced peer
against the references), ``bridge_check`` (the bridge's renders against Cycles) and
``kernel_bench`` (each method's scalar code against its SIMD kernel, ``aolab bench-table``).
"""
