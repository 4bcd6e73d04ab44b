"""Assembly of element matrices into scipy.sparse matrices and reduction by the constraints.

Element matrices come from the Warp kernel (:func:`bridge.structure.elements.element_matrices`) as
(n, 12, 12) blocks; their COO triplets (row = 6 node + dof) are summed into CSR matrices by scipy.

Constraints are applied by a sparse transformation u_full = T q (q: independent DOFs):
* fixed DOFs (supports) have no column;
* rotations of nodes touched only by cable/hanger elements have no column (they carry no stiffness
  and no mass);
* slave nodes of rigid links (ABAQUS kinematic coupling): u_s = u_m + theta_m x r (r = x_s - x_m),
  theta_s = theta_m, so their rows are combinations of the master's columns.
Reduced matrices: K_r = T^T K T, M_r = T^T M T (master-slave elimination).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .elements import ElementSet, element_matrices
from .model import FrameModel

__all__ = ["AssembledModel", "assemble", "global_matrices", "coo_triplets", "constraint_transform"]


@dataclass(frozen=True)
class AssembledModel:
    """Full (6 DOFs per node) and reduced matrices; ``T`` maps reduced to full DOFs."""

    stiffness_elastic: sp.csr_matrix
    stiffness_geometric: sp.csr_matrix
    mass: sp.csr_matrix
    T: sp.csr_matrix
    stiffness_reduced: sp.csr_matrix
    mass_reduced: sp.csr_matrix

    @property
    def n_dof(self) -> int:
        return self.T.shape[1]


def coo_triplets(conn: np.ndarray, blocks: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows, columns and values of the element blocks (n, 12, 12) for 6-DOF nodes ``conn`` (n, 2)."""
    dofs = (6 * conn[:, :, None] + np.arange(6)[None, None, :]).reshape(len(conn), 12)
    rows = np.broadcast_to(dofs[:, :, None], blocks.shape).ravel()
    cols = np.broadcast_to(dofs[:, None, :], blocks.shape).ravel()
    return rows, cols, blocks.ravel()


def _to_csr(conn: np.ndarray, blocks: np.ndarray, n: int) -> sp.csr_matrix:
    r, c, v = coo_triplets(conn, blocks)
    return sp.coo_matrix((v, (r, c)), shape=(n, n)).tocsr()  # duplicates are summed


def constraint_transform(model: FrameModel) -> sp.csr_matrix:
    """T (6 n_nodes x n_free) of the module docstring."""
    n = model.n_nodes
    eliminated = np.zeros((n, 6), dtype=bool)
    for node, d in model.fixed:
        eliminated[node, d] = True
    eliminated[~model.rotational, 3:] = True
    slaves = np.array([s for s, _ in model.links], dtype=int)
    eliminated[slaves, :] = True
    col = -np.ones((n, 6), dtype=int)
    free = ~eliminated
    col[free] = np.arange(free.sum())
    rows, cols, vals = [], [], []
    fr = np.flatnonzero(free.ravel())
    rows.append(fr)
    cols.append(col.ravel()[fr])
    vals.append(np.ones(len(fr)))
    for s, m in model.links:
        r = model.nodes[s] - model.nodes[m]
        # u_s = u_m + theta_m x r ; theta x r = (ty rz - tz ry, tz rx - tx rz, tx ry - ty rx)
        coef = {(0, 0): 1.0, (1, 1): 1.0, (2, 2): 1.0,
                (0, 4): r[2], (0, 5): -r[1], (1, 5): r[0], (1, 3): -r[2], (2, 3): r[1], (2, 4): -r[0],
                (3, 3): 1.0, (4, 4): 1.0, (5, 5): 1.0}
        for (ds, dm), c in coef.items():
            if c != 0.0 and col[m, dm] >= 0:
                rows.append(np.array([6 * s + ds]))
                cols.append(np.array([col[m, dm]]))
                vals.append(np.array([c]))
    return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(6 * n, int(free.sum()))).tocsr()


def global_matrices(conn: np.ndarray, elements: ElementSet, n_nodes: int,
                    device: str = "cpu") -> tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix]:
    """Unconstrained global (K_elastic, M, K_geometric), 6 DOFs per node, from the Warp kernel."""
    k_e, m_e, g_e = element_matrices(elements, device=device)
    n = 6 * n_nodes
    return tuple(_to_csr(conn, blk, n) for blk in (k_e, m_e, g_e))


def assemble(model: FrameModel, device: str = "cpu") -> AssembledModel:
    """Element matrices (Warp) -> global CSR -> constraint reduction; K = K_elastic + K_geometric."""
    K, M, G = global_matrices(model.conn, model.elements, model.n_nodes, device)
    T = constraint_transform(model)
    Kr = (T.T @ (K + G) @ T).tocsr()
    Mr = (T.T @ M @ T).tocsr()
    # symmetrise against round-off of the triple products
    Kr = ((Kr + Kr.T) * 0.5).tocsr()
    Mr = ((Mr + Mr.T) * 0.5).tocsr()
    return AssembledModel(K, G, M, T, Kr, Mr)
