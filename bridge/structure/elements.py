"""Two-node 3D frame elements: properties table, Warp launch and a vectorised NumPy twin.

The element maths is in :mod:`kernels.fem` (Warp, CPU device by default, float64).  This module
packs element data into the arrays the kernel reads, launches it, and offers
:func:`element_matrices_numpy`, the same matrices computed with NumPy array operations (used by the
tests to cross-check the kernel and by ``tools/bench_fem.py`` as the speed reference).

Conventions (see the :mod:`kernels.fem` docstring): 6 DOFs per node (u_x, u_y, u_z, theta_x,
theta_y, theta_z), local e1 along the element, orientation vector ``v`` in the local 1-2 plane.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ElementSet", "element_matrices", "element_matrices_numpy", "KIND_BEAM", "KIND_CABLE",
           "N_PROPS", "local_frames"]

KIND_BEAM, KIND_CABLE, N_PROPS = 0, 1, 10
(PROP_EA, PROP_EI2, PROP_EI3, PROP_GJ, PROP_MASS, PROP_ROT2, PROP_ROT3, PROP_POLAR, PROP_AXIAL,
 PROP_KIND) = range(N_PROPS)


@dataclass(frozen=True)
class ElementSet:
    """Elements of one model: end coordinates (n, 3), orientation vectors (n, 3), properties (n, 10)."""

    xa: np.ndarray
    xb: np.ndarray
    orient: np.ndarray
    props: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.xa)
        for name in ("xa", "xb", "orient"):
            a = getattr(self, name)
            if a.shape != (n, 3) or a.dtype != np.float64:
                raise ValueError(f"ElementSet.{name} must be float64 of shape ({n}, 3), got {a.dtype} {a.shape}")
        if self.props.shape != (n, N_PROPS) or self.props.dtype != np.float64:
            raise ValueError(f"ElementSet.props must be float64 of shape ({n}, {N_PROPS})")
        length = np.linalg.norm(self.xb - self.xa, axis=1)
        if n and np.any(length <= 0.0):
            raise ValueError(f"zero-length elements: {np.flatnonzero(length <= 0.0)[:10].tolist()}")
        par = np.linalg.norm(np.cross(self.xb - self.xa, self.orient), axis=1) <= 1e-9 * length
        if n and np.any(par):
            raise ValueError(f"orientation vector parallel to the element axis: {np.flatnonzero(par)[:10].tolist()}")

    def __len__(self) -> int:
        return len(self.xa)


def _warp(device: str = "cpu"):
    from ..warp_setup import init_warp

    return init_warp(device)


def element_matrices(elements: ElementSet, device: str = "cpu") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Global (K_elastic, M_consistent, K_geometric), each (n, 12, 12) float64, from the Warp kernel."""
    wp = _warp(device)
    from kernels import fem

    n = len(elements)
    with wp.ScopedDevice(device):
        xa = wp.array(elements.xa, dtype=wp.vec3d)
        xb = wp.array(elements.xb, dtype=wp.vec3d)
        ov = wp.array(elements.orient, dtype=wp.vec3d)
        props = wp.array(elements.props, dtype=wp.float64)
        scratch = wp.empty((n, 12, 12), dtype=wp.float64)
        k, m, g = (wp.empty((n, 12, 12), dtype=wp.float64) for _ in range(3))
        wp.launch(fem.element_matrices, dim=n, inputs=[xa, xb, ov, props, scratch, k, m, g])
        return k.numpy(), m.numpy(), g.numpy()


# ----------------------------------------------------------------------------- NumPy twin
def local_frames(xa: np.ndarray, xb: np.ndarray, orient: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation matrices R (n, 3, 3) with rows e1, e2, e3 and element lengths (n,)."""
    d = xb - xa
    length = np.linalg.norm(d, axis=1)
    e1 = d / length[:, None]
    e3 = np.cross(e1, orient)
    e3 /= np.linalg.norm(e3, axis=1)[:, None]
    e2 = np.cross(e3, e1)
    return np.stack([e1, e2, e3], axis=1), length


def _put2(mat, d0, d1, c, diag, off):
    mat[:, d0, d0] += c * diag
    mat[:, d1, d1] += c * diag
    mat[:, d0, d1] += c * off
    mat[:, d1, d0] += c * off


def _put4(mat, dofs, s, c, pattern):
    """mat += c * S P S on dofs, S = diag(1, s, 1, s); pattern (n, 4, 4) or (4, 4)."""
    sign = np.array([1.0, s, 1.0, s])
    block = (sign[:, None] * sign[None, :]) * pattern
    idx = np.ix_(np.arange(mat.shape[0]), dofs, dofs)
    mat[idx] += c[:, None, None] * block


def _hermite_patterns(L):
    one, z = np.ones_like(L), L
    def sym(k00, k01, k02, k03, k11, k12, k13, k22, k23, k33):
        return np.stack([np.stack([k00, k01, k02, k03], -1), np.stack([k01, k11, k12, k13], -1),
                         np.stack([k02, k12, k22, k23], -1), np.stack([k03, k13, k23, k33], -1)], -2)
    stiff = sym(12 * one, 6 * z, -12 * one, 6 * z, 4 * z * z, -6 * z, 2 * z * z, 12 * one, -6 * z, 4 * z * z)
    mass = sym(156 * one, 22 * z, 54 * one, -13 * z, 4 * z * z, 13 * z, -3 * z * z, 156 * one, -22 * z, 4 * z * z)
    slope = sym(36 * one, 3 * z, -36 * one, 3 * z, 4 * z * z, -3 * z, -z * z, 36 * one, -3 * z, 4 * z * z)
    return stiff, mass, slope


def element_matrices_numpy(elements: ElementSet) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Same matrices as :func:`element_matrices`, computed with vectorised NumPy (reference/benchmark)."""
    p = elements.props
    n = len(elements)
    R, L = local_frames(elements.xa, elements.xb, elements.orient)
    beam = p[:, PROP_KIND] < 0.5
    cable = ~beam
    stiff, mass, slope = _hermite_patterns(L)
    v_dofs, w_dofs = [1, 5, 7, 11], [2, 4, 8, 10]
    out = []
    zero = np.zeros(n)
    for which in ("k", "m", "g"):
        loc = np.zeros((n, 12, 12))
        b = beam.astype(np.float64)
        if which == "k":
            _put2(loc, 0, 6, p[:, PROP_EA] / L, 1.0, -1.0)
            _put2(loc, 3, 9, b * p[:, PROP_GJ] / L, 1.0, -1.0)
            _put4(loc, v_dofs, 1.0, b * p[:, PROP_EI2] / L**3, stiff)
            _put4(loc, w_dofs, -1.0, b * p[:, PROP_EI3] / L**3, stiff)
        elif which == "m":
            m = p[:, PROP_MASS]
            _put2(loc, 0, 6, m * L / 6, 2.0, 1.0)
            _put2(loc, 3, 9, b * p[:, PROP_POLAR] * L / 6, 2.0, 1.0)
            _put4(loc, v_dofs, 1.0, b * m * L / 420, mass)
            _put4(loc, w_dofs, -1.0, b * m * L / 420, mass)
            _put4(loc, v_dofs, 1.0, b * p[:, PROP_ROT2] / (30 * L), slope)
            _put4(loc, w_dofs, -1.0, b * p[:, PROP_ROT3] / (30 * L), slope)
            c = cable * m * L / 6
            _put2(loc, 1, 7, c, 2.0, 1.0)
            _put2(loc, 2, 8, c, 2.0, 1.0)
        else:
            nax = p[:, PROP_AXIAL]
            _put4(loc, v_dofs, 1.0, b * nax / (30 * L), slope)
            _put4(loc, w_dofs, -1.0, b * nax / (30 * L), slope)
            c = np.where(cable, nax / L, zero)
            _put2(loc, 1, 7, c, 1.0, -1.0)
            _put2(loc, 2, 8, c, 1.0, -1.0)
        # T^T loc T with T = blockdiag(R x4), via reshape to (n, 4, 3, 4, 3)
        l5 = loc.reshape(n, 4, 3, 4, 3)
        g5 = np.einsum("nki,nakbl,nlj->naibj", R, l5, R, optimize=True)
        out.append(g5.reshape(n, 12, 12))
    return out[0], out[1], out[2]
