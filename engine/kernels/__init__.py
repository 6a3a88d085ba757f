"""Compiled per-ray kernels: the tracer's work between Embree queries.

Every function here is scalar Python code, one ray or one hit at a time, compiled by
Numba to machine code that runs without the GIL (`jit.kernel`). They read like pbrt; the
batch drivers loop over a wavefront of rays, so threads running different work units use
every core while Embree queries (which release the GIL too) run between the stages.
"""
