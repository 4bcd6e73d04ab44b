"""Shared helpers: devices to run the Warp kernel on, and straight-line beam/string models."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

from bridge.structure.assembly import global_matrices
from bridge.structure.elements import (
    KIND_BEAM,
    KIND_CABLE,
    N_PROPS,
    PROP_AXIAL,
    PROP_EA,
    PROP_EI2,
    PROP_EI3,
    PROP_GJ,
    PROP_KIND,
    PROP_MASS,
    PROP_POLAR,
    ElementSet,
)


def _cuda_available() -> bool:
    try:
        import warp as wp

        wp.init()
        return wp.get_cuda_device_count() > 0
    except Exception:  # noqa: BLE001 - no warp/cuda means no cuda test, nothing else
        return False


DEVICES = ["cpu", pytest.param("cuda", marks=[pytest.mark.cuda,
                                               pytest.mark.skipif(not _cuda_available(), reason="no CUDA device")])]


def line_model(n: int, length: float, props: np.ndarray, direction=(0.0, 0.0, 1.0), orient=(0.0, 1.0, 0.0)):
    """n equal elements on a straight line from the origin; returns nodes, conn, ElementSet."""
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    nodes = np.outer(np.linspace(0.0, length, n + 1), d)
    conn = np.stack([np.arange(n), np.arange(1, n + 1)], axis=1)
    es = ElementSet(nodes[:-1].copy(), nodes[1:].copy(), np.tile(np.asarray(orient, dtype=np.float64), (n, 1)),
                    np.tile(props, (n, 1)))
    return nodes, conn, es


def props_row(ea=0.0, ei2=0.0, ei3=0.0, gj=0.0, mass=0.0, polar=0.0, axial=0.0, kind=KIND_BEAM) -> np.ndarray:
    p = np.zeros(N_PROPS)
    p[PROP_EA], p[PROP_EI2], p[PROP_EI3], p[PROP_GJ] = ea, ei2, ei3, gj
    p[PROP_MASS], p[PROP_POLAR], p[PROP_AXIAL], p[PROP_KIND] = mass, polar, axial, kind
    return p


def frequencies(nodes, conn, es, fixed_dofs, keep_dofs=None, n_modes=3, device="cpu"):
    """Lowest frequencies [Hz] of the line model with DOFs ``fixed_dofs`` (global indices) removed and,
    if given, only ``keep_dofs`` kept (to isolate one kind of motion)."""
    K, M, G = global_matrices(conn, es, len(nodes), device)
    ndof = 6 * len(nodes)
    keep = np.setdiff1d(np.arange(ndof) if keep_dofs is None else np.asarray(keep_dofs), fixed_dofs)
    Kr = (K + G).toarray()[np.ix_(keep, keep)]
    Mr = M.toarray()[np.ix_(keep, keep)]
    w2 = sla.eigh(Kr, Mr, eigvals_only=True)
    return np.sqrt(np.clip(np.sort(w2)[:n_modes], 0.0, None)) / (2 * np.pi)


def node_dofs(nodes_idx, dofs):
    return np.array([6 * i + d for i in np.atleast_1d(nodes_idx) for d in dofs], dtype=int)


def observed_order(hs, errors) -> float:
    """Slope of log(error) against log(h) by least squares."""
    return float(np.polyfit(np.log(hs), np.log(errors), 1)[0])


__all__ = ["DEVICES", "line_model", "props_row", "frequencies", "node_dofs", "observed_order",
           "KIND_BEAM", "KIND_CABLE"]
