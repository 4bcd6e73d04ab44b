"""Element matrices of kernels/fem.py: closed-form identities on single elements."""

from __future__ import annotations

import numpy as np
import pytest
from fem_helpers import DEVICES, KIND_BEAM, KIND_CABLE, props_row

from bridge.structure.elements import ElementSet, element_matrices, element_matrices_numpy


def random_elements(n: int, seed: int = 1) -> ElementSet:
    rng = np.random.default_rng(seed)
    xa = rng.normal(size=(n, 3)) * 10
    xb = xa + rng.normal(size=(n, 3)) * 5
    ov = rng.normal(size=(n, 3))
    p = rng.uniform(0.5, 2.0, size=(n, 10)) * np.array([1e9, 1e8, 2e8, 5e7, 1e3, 10, 20, 1e4, 1e6, 1.0])
    p[:, 9] = np.arange(n) % 2  # beams and cables alternately
    return ElementSet(xa, xb, ov, p)


def rigid_body_modes(xa: np.ndarray, xb: np.ndarray) -> np.ndarray:
    """(12, 6): three translations and three small rotations about the origin."""
    out = np.zeros((12, 6))
    for node, x in enumerate((xa, xb)):
        for d in range(3):
            out[6 * node + d, d] = 1.0
        for r in range(3):
            axis = np.zeros(3)
            axis[r] = 1.0
            out[6 * node:6 * node + 3, 3 + r] = np.cross(axis, x)
            out[6 * node + 3 + r, 3 + r] = 1.0
    return out


@pytest.mark.parametrize("device", DEVICES)
def test_warp_matches_numpy_twin(device):
    es = random_elements(40)
    for a, b in zip(element_matrices(es, device=device), element_matrices_numpy(es), strict=False):
        assert np.allclose(a, b, rtol=1e-13, atol=1e-13 * np.abs(b).max())


@pytest.mark.parametrize("device", DEVICES)
def test_symmetric_and_six_rigid_body_modes(device):
    es = random_elements(20)
    K, M, G = element_matrices(es, device=device)
    for e in range(len(es)):
        for A in (K[e], M[e], G[e]):
            assert np.allclose(A, A.T, rtol=0, atol=1e-12 * np.abs(A).max())
        R = rigid_body_modes(es.xa[e], es.xb[e])
        scale = np.abs(K[e]).max() * np.abs(R).max()
        assert np.abs(K[e] @ R).max() < 1e-9 * scale
        ev = np.linalg.eigvalsh(K[e])
        if es.props[e, 9] == KIND_BEAM:  # exactly six zero eigenvalues, the other six positive
            assert np.sum(np.abs(ev) < 1e-9 * ev.max()) == 6
            assert np.sum(ev > 1e-9 * ev.max()) == 6
        else:  # cable: axial stiffness only
            assert np.sum(ev > 1e-9 * ev.max()) == 1
        assert np.linalg.eigvalsh(M[e]).min() > -1e-9 * np.abs(M[e]).max()


def test_mass_integrates_to_total_mass():
    es = random_elements(10)
    _, M, _ = element_matrices(es)
    length = np.linalg.norm(es.xb - es.xa, axis=1)
    for e in range(len(es)):
        for d in range(3):
            u = np.zeros(12)
            u[d] = u[6 + d] = 1.0
            assert u @ M[e] @ u == pytest.approx(es.props[e, 4] * length[e], rel=1e-12)
        if es.props[e, 9] == KIND_BEAM:  # uniform twist: the polar mass moment times length
            t = np.zeros(12)
            t[3:6] = t[9:12] = (es.xb[e] - es.xa[e]) / length[e]
            assert t @ M[e] @ t == pytest.approx(es.props[e, 7] * length[e], rel=1e-12)


def test_frame_invariance():
    """Rotating an element and its orientation vector rotates its global matrices: T^T K' T = K."""
    es = random_elements(6)
    th = 0.7
    Q = np.array([[np.cos(th), -np.sin(th), 0], [np.sin(th), np.cos(th), 0], [0, 0, 1.0]]) @ \
        np.array([[1, 0, 0], [0, np.cos(1.1), -np.sin(1.1)], [0, np.sin(1.1), np.cos(1.1)]])
    rot = ElementSet(es.xa @ Q.T, es.xb @ Q.T, es.orient @ Q.T, es.props.copy())
    T = np.kron(np.eye(4), Q)
    for a, b in zip(element_matrices(es), element_matrices(rot), strict=False):
        for e in range(len(es)):
            assert np.allclose(T.T @ b[e] @ T, a[e], rtol=1e-12, atol=1e-12 * np.abs(a[e]).max())


def test_cable_without_tension_has_no_transverse_stiffness():
    p0 = props_row(ea=1e10, mass=100.0, axial=0.0, kind=KIND_CABLE)
    p1 = props_row(ea=1e10, mass=100.0, axial=2e6, kind=KIND_CABLE)
    es = ElementSet(np.zeros((2, 3)), np.tile([0.0, 0.0, 10.0], (2, 1)), np.tile([0.0, 1.0, 0.0], (2, 1)),
                    np.stack([p0, p1]))
    K, _, G = element_matrices(es)
    transverse = [0, 1, 6, 7]  # u_x, u_y of both nodes for an element along z
    assert np.abs((K[0] + G[0])[np.ix_(transverse, transverse)]).max() == 0.0
    assert (K[1] + G[1])[0, 0] == pytest.approx(2e6 / 10.0, rel=1e-14)   # N / L
    assert (K[1] + G[1])[2, 2] == pytest.approx(1e10 / 10.0, rel=1e-14)  # EA / L along the axis
