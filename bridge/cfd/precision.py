"""CFD floating-point precision: the one place it is chosen.

float64 throughout: on this project's CPU backend float32 is not faster per cell (the scalar loop
overhead dominates, docs/warp_cpu.md), the DCT pressure solve is exact to round-off only in float64, and
force histories feed flutter derivatives where phase errors matter. Kernels in ``kernels/cfd.py``
are typed ``wp.float64`` to match; changing precision means changing both (and the tests check the
dtype of every solver array against ``DTYPE``).
"""

import numpy as np
import warp as wp

DTYPE = np.float64
WP_DTYPE = wp.float64

__all__ = ["DTYPE", "WP_DTYPE"]
