"""Warp kernels only: ``@wp.func`` for pointwise maths, thin ``@wp.kernel`` wrappers.

No orchestration and no I/O here; the ``bridge`` package launches these kernels.
"""
