"""Generalised eigenproblem K phi = omega^2 M phi by shift-invert Lanczos (scipy ARPACK).

The operator (K - sigma M)^-1 is given to ``eigsh`` as ``OPinv`` from one sparse LU factorisation
(``splu``), scipy's shift-invert mode (timings in docs/warp_cpu.md); sigma is slightly negative so that
the factorisation stays non-singular even if the model had a mechanism (a rigid-body mode would then
appear at ~0 Hz and be visible rather than crash the factorisation).  M may be semi-definite
(shift-invert mode allows it).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import ConvergenceError

__all__ = ["lowest_modes"]


def lowest_modes(K: sp.spmatrix, M: sp.spmatrix, n_modes: int, shift_hz: float = -0.01,
                 tol: float = 1e-10) -> tuple[np.ndarray, np.ndarray]:
    """The ``n_modes`` lowest (frequency_hz ascending, mode shapes (n_dof, n_modes)), M-orthonormal."""
    n = K.shape[0]
    n_modes = min(n_modes, n - 2)
    sigma = -(2.0 * np.pi * shift_hz) ** 2 if shift_hz < 0 else (2.0 * np.pi * shift_hz) ** 2
    lu = spla.splu((K - sigma * M).tocsc())
    op = spla.LinearOperator((n, n), matvec=lu.solve, dtype=np.float64)
    # a fixed start vector: ARPACK's own is drawn from a seed it carries from call to call, so the same model
    # gave modes differing in the last bits depending on what the process had solved before
    v0 = np.random.default_rng(0).standard_normal(n)
    try:
        lam, vec = spla.eigsh(K, k=n_modes, M=M, sigma=sigma, which="LM", OPinv=op, tol=tol, v0=v0,
                              ncv=min(n, max(2 * n_modes + 1, 60)))
    except spla.ArpackNoConvergence as err:
        raise ConvergenceError("shift-invert Lanczos (eigsh)", 0, float(len(err.eigenvalues)), tol) from None
    order = np.argsort(lam)
    lam, vec = lam[order], vec[:, order]
    freq = np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * np.pi)
    return freq, vec
