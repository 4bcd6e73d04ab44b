"""Incompressible flow on a body-fitted curvilinear grid (an O-grid around a section), in the body's frame.

Why: on a Cartesian grid the immersed wall converges at order 1.4-1.6 and only uniform refinement helps; a
grid that follows the wall, graded away from it, puts second-order accurate cells where the boundary layer
is, and few elsewhere (issue "A body-fitted body grid").

Grid.  Nodes ``x[j, i]``, ``y[j, i]``: j = 0 on the wall to j = nj on the outer boundary, i around the body,
periodic.  Cell (j, i) has the corners (j, i), (j, i+1), (j+1, i+1), (j+1, i).  "i-faces" separate the cells
i-1 and i of a ring (nodes (j, i) to (j+1, i)); "j-faces" separate the rings j-1 and j (nodes (j, i) to
(j, i+1)), j-face 0 is the wall and j-face nj the outer boundary.  The grid moves rigidly with the body, so
every metric below is computed once.

Equations (Beddhu, Taylor and Whitfield 1996: the absolute velocity in the body's axes, as the Cartesian
overset pair's body grid, bridge/cfd/overset.py), with u_g = R^T V_O + Omega x xi the grid's velocity:
  du/dt + div(u (u - u_g)) + Omega x u = -grad p + div((nu + nu_t)(grad u + grad u^T)),   div u = 0,
  u = u_g on the wall,
nu_t a turbulence model's eddy viscosity (bridge/cfd/curvilinear_sst.py; zero when laminar, where the stress is
nu lap u): nu + nu_t on the faces, the mean of the two cells' (the wall face nu, the outer face's extrapolated
from the last two rings), its transpose part nu_t grad u^T explicit.

Finite volumes (Zang, Street and Koseff 1994, J. Comput. Phys. 114: Cartesian velocity at the cell centres,
volume fluxes F = u . S on the faces): the divergence of a cell is the sum of its faces' fluxes; a face's
gradient comes from the two cells beside it (difference along d, the line between their centres) and the
face's two nodes (difference along the face, t; node values the mean of the four cells around), so that
grad q . S = alpha (q_E - q_P) + beta (q_n1 - q_n0) with alpha, beta from the face's geometry: the full
metric, second order on smooth grids, and a nine-point pressure stencil.  The explicit stencils (advection,
diffusion, cell gradients) and the line solves are Warp kernels (kernels/curvilinear.py); the pressure's
constant matrix is factorised once by SuperLU.

Time step: second-order backward differences (BDF2) with the explicit terms extrapolated from the last two steps
(SBDF2; Ascher, Ruuth and Wetton 1995) - advection (van Leer's limited upwinding along the grid lines), the
frame's term and the diffusion's cross-derivative terms explicit, the rest of the diffusion implicit: around each
ring and across the rings, approximately factorised into one line solve per grid line each way
(kernels/curvilinear.py), so that neither the thin wall cells nor the fine spacing along the wall limit the step;
BDF2 damps the stiff modes that Crank-Nicolson would leave ringing.  Between cells flatter than
IMPLICIT_ASPECT = 2 (along the wall over across it; ``grid.implicit_j``) the advection across the rings is
implicit too, by deferred correction: first-order upwind in the same line solves, and van Leer's face value less
the upwind one explicit, so that the scheme in space stays van Leer's (Khosla and Rubin 1974; what OpenFOAM's
bounded schemes do): at Re 1e8 the flow crossing the thin cells near a sharp corner would otherwise set a step a
hundred times shorter (with the implicit faces only in cells flatter than 10:1 and the two rates' maxima added,
the Great Belt deck's O-grid took 16 steps to the background's one; 5 now).  Not in cells barely flat: there the
implicit upwind part costs time accuracy (at 1 instead of 2 the start-up lift of a rotating cylinder's O-grid,
cells of aspect 1-2.5, moved 3.6 % at Courant 0.5), and they do not limit the step.  Then the projection,
incremental (van Kan 1986): the predicted face fluxes (Rhie and Chow's interpolation: the cell pressure gradient
taken out, the face's put back, both weighted by c / A_P, A_P the diagonal of the implicit operator the predictor
solved: SIMPLE's d = V / a_P, OpenFOAM's rAU), D G phi = D F* / c with the nine-point face gradient (a constant
matrix, factorised once), F = F* - c G phi on the faces, u = u* - c grad phi at the centres (Green-Gauss, the
boundary faces' values extrapolated along the grid lines), p += phi, c = dt over BDF2's leading coefficient.  Why
that weight: in the thin wall cells the implicit diffusion makes A_P a hundred or more, so the predictor took out
only c / A_P times the cell gradient; put back with c, the surplus entered the faces' fluxes, and at a sharp
convex corner, where the two wall cells' normal gradients meet across one face, it pumped a spurious loop of
several U through the first rings, growing with the step and setting it (the Great Belt's nose).  The step: each
cell's explicit rates added (the convective Courant number of its explicit faces, and the cross terms of skewed
cells where they are not small beside its implicit diffusion: ``_flow_dt``), the fastest cell's.

The outer boundary's velocity (two rings of ghost cells) and face fluxes come from an ``outer`` provider:
:class:`Farfield` (a uniform stream), or the Cartesian background of an overset pair.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .flow import LAMINAR, FlowBase

__all__ = ["CurvilinearGrid", "CurvilinearFlow", "Farfield", "polar_grid"]

IMPLICIT_ASPECT = 2.0   # cells flatter than this (along the wall / across) advect across the rings implicitly


def _rot(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def polar_grid(radius: float, outer_radius: float, n_around: int, first_height: float, growth: float,
               centre: tuple[float, float] = (0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Nodes of the O-grid of a circle: rings at radius + first_height (growth^j - 1) / (growth - 1) up to
    ``outer_radius`` (the last ring put on it), ``n_around`` nodes counter-clockwise from the +x axis."""
    if not (1.0 <= growth <= 1.3):
        raise ValueError(f"growth: allowed 1.0 .. 1.3, got {growth}")
    heights = [0.0]
    h = first_height
    while radius + heights[-1] + h < outer_radius:
        heights.append(heights[-1] + h)
        h *= growth
    heights[-1] = outer_radius - radius if len(heights) > 1 else outer_radius - radius
    if heights[-1] <= heights[-2] if len(heights) > 1 else True:
        heights.append(outer_radius - radius)
    r = radius + np.array(heights)
    th = 2 * np.pi * np.arange(n_around) / n_around
    return centre[0] + r[:, None] * np.cos(th)[None, :], centre[1] + r[:, None] * np.sin(th)[None, :]


@dataclass(frozen=True)
class _Faces:
    """One family of faces: area vectors S (n, 2), midpoints xm (n, 2), the gradient coefficients alpha and
    beta, and for each face its minus- and plus-side cells and its two nodes (flat indices; -1: none)."""

    S: np.ndarray
    xm: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray


class CurvilinearGrid:
    """The geometry of an O-grid (module doc): cell centres and areas, faces' area vectors, the gradient
    coefficients, and the ghost cells' centres beyond the outer boundary (mirrors of the last two rings)."""

    def __init__(self, x: np.ndarray, y: np.ndarray):
        x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        if x.ndim != 2 or x.shape != y.shape or x.shape[0] < 3 or x.shape[1] < 8:
            raise ValueError(f"x, y: need equal shapes (nj + 1 >= 3, ni >= 8), got {x.shape}, {y.shape}")
        self.x, self.y = x, y
        self.nj, self.ni = x.shape[0] - 1, x.shape[1]
        nj, ni = self.nj, self.ni
        xp, yp = np.hstack([x, x[:, :1]]), np.hstack([y, y[:, :1]])   # node i = ni is node 0
        xa, ya = xp[:-1, :-1], yp[:-1, :-1]     # corners a (j, i), b (j, i+1), c (j+1, i+1), d (j+1, i)
        xb, yb = xp[:-1, 1:], yp[:-1, 1:]
        xc, yc = xp[1:, 1:], yp[1:, 1:]
        xd, yd = xp[1:, :-1], yp[1:, :-1]
        cross = [(xa * yb - xb * ya), (xb * yc - xc * yb), (xc * yd - xd * yc), (xd * ya - xa * yd)]
        signed = 0.5 * sum(cross)
        self.orientation = 1.0 if signed.sum() > 0 else -1.0
        if not np.all(signed * self.orientation > 0):
            j, i = np.argwhere(signed * self.orientation <= 0)[0]
            raise ValueError(f"grid: cell (j={j}, i={i}) at ({xa[j, i]:.4g}, {ya[j, i]:.4g}) is folded or empty")
        self.area = np.abs(signed)
        cx = sum(c * (u + v) for c, u, v in zip(cross, (xa, xb, xc, xd), (xb, xc, xd, xa), strict=True)) / (6 * signed)
        cy = sum(c * (u + v) for c, u, v in zip(cross, (ya, yb, yc, yd), (yb, yc, yd, ya), strict=True)) / (6 * signed)
        self.xc, self.yc = cx, cy
        s = self.orientation
        # i-faces [j, i] (nj, ni): nodes (j, i) -> (j+1, i), normal towards +i; between cells (j, i-1) and (j, i)
        tx, ty = x[1:, :] - x[:-1, :], y[1:, :] - y[:-1, :]
        self.Si = s * np.stack([ty, -tx], axis=-1)
        self.xmi = np.stack([0.5 * (x[1:] + x[:-1]), 0.5 * (y[1:] + y[:-1])], axis=-1)
        dx = cx - np.roll(cx, 1, axis=1)
        dy = cy - np.roll(cy, 1, axis=1)
        self.alpha_i, self.beta_i = self._coefficients(self.Si, dx, dy, tx, ty)
        # j-faces [j, i] (nj+1, ni): nodes (j, i) -> (j, i+1), normal towards +j; between rings j-1 and j
        tx, ty = xp[:, 1:] - xp[:, :-1], yp[:, 1:] - yp[:, :-1]
        self.Sj = s * np.stack([-ty, tx], axis=-1)
        self.xmj = np.stack([0.5 * (xp[:, 1:] + xp[:, :-1]), 0.5 * (yp[:, 1:] + yp[:, :-1])], axis=-1)
        # ghost centres beyond the outer boundary: mirrors of the last two rings' centres in the outer faces
        fx, fy = self.xmj[nj, :, 0], self.xmj[nj, :, 1]
        self.xg = np.stack([2 * fx - cx[nj - 1], 2 * fx - cx[nj - 2]])   # (2, ni): ghost rings 1 and 2
        self.yg = np.stack([2 * fy - cy[nj - 1], 2 * fy - cy[nj - 2]])
        # d of each j-face: wall face from its midpoint to cell 0; interior from ring j-1 to ring j; outer from
        # ring nj-1 to ghost ring 1
        below_x = np.vstack([self.xmj[0, :, 0][None], cx])
        below_y = np.vstack([self.xmj[0, :, 1][None], cy])
        above_x = np.vstack([cx, self.xg[:1]])
        above_y = np.vstack([cy, self.yg[:1]])
        self.alpha_j, self.beta_j = self._coefficients(self.Sj, above_x - below_x, above_y - below_y, tx, ty)
        # each cell's distance from its column's wall face, along the face's normal: at a convex corner the grid
        # lines fan out, and the centres of the first rings lie beside their wall face rather than above it, where
        # the distance to its midpoint made the first two rings' distances nearly equal and the one-sided
        # gradients below (and the wall's pressure and shear) divide by their difference
        nx_, ny_ = self.Sj[0, :, 0], self.Sj[0, :, 1]
        length = np.hypot(nx_, ny_)
        self.wall_distance = ((cx - self.xmj[0, :, 0]) * nx_ + (cy - self.xmj[0, :, 1]) * ny_) / length   # (nj, ni)
        # the wall face's normal gradient from a quadratic through the wall and the first two rings (second
        # order: the half-cell difference alone leaves the wall's shear first order):
        # dq/dn d0 = w0 (q0 - q_w) + w1 (q1 - q_w)
        d0, d1 = self.wall_distance[0], self.wall_distance[1]
        self.wall_w0, self.wall_w1 = d1 / (d1 - d0), -d0 * d0 / (d1 * (d1 - d0))
        # the j-faces whose advection is implicit: between two cells flatter than IMPLICIT_ASPECT (along the wall
        # over across), where the flow crossing the thin cells would set the step (module doc)
        along = 0.5 * (np.hypot(*self.Sj[:-1].transpose(2, 0, 1)) + np.hypot(*self.Sj[1:].transpose(2, 0, 1)))
        aspect = along * along / self.area
        self.implicit_j = np.zeros((nj + 1, ni), dtype=bool)
        self.implicit_j[1:nj] = np.minimum(aspect[1:], aspect[:-1]) > IMPLICIT_ASPECT
        self.n_cells = nj * ni

    @staticmethod
    def _coefficients(S, dx, dy, tx, ty):
        """grad q . S = alpha (q_E - q_P) + beta (q_n1 - q_n0) from d = x_E - x_P and the face's t (module doc)."""
        det = dx * ty - dy * tx
        return (S[..., 0] * ty - S[..., 1] * tx) / det, (S[..., 1] * dx - S[..., 0] * dy) / det

    def cell(self, j, i) -> int:
        return j * self.ni + i % self.ni


class Farfield:
    """The outer boundary in a uniform stream: velocity (u_inf, v_inf) in the inertial axes on the ghost cells
    and the outer faces (rotated into the body's axes, which turn with the body)."""

    def __init__(self, u_inf: float = 1.0, v_inf: float = 0.0):
        self.u_inf, self.v_inf = float(u_inf), float(v_inf)

    def attach(self, flow: CurvilinearFlow) -> None:
        self.flow = flow

    def ghost_velocity(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(2, ni) u and v of the two ghost rings, body axes."""
        ub, vb = _rot(self.flow.motion.pose(t)[2]).T @ np.array([self.u_inf, self.v_inf])
        shape = self.flow.grid.xg.shape
        return np.full(shape, ub), np.full(shape, vb)

    def outer_fluxes(self, t: float) -> np.ndarray:
        """(ni,) volume fluxes through the outer faces (outwards); they sum to zero (a closed curve)."""
        ub, vb = _rot(self.flow.motion.pose(t)[2]).T @ np.array([self.u_inf, self.v_inf])
        S = self.flow.grid.Sj[-1]
        return ub * S[:, 0] + vb * S[:, 1]


class CurvilinearFlow(FlowBase):
    """The incompressible flow on a body-fitted grid (module doc): a flow of bridge/cfd/flow.py.

    ``grid``: a :class:`CurvilinearGrid` in the body's coordinates (the reference point at 0); ``nu``; ``motion``:
    the body's rigid motion (pose(t), velocity(t)); ``outer``: the outer boundary's provider (``Farfield``, or
    an overset background); ``cfl``: the convective Courant number of the step; ``rho`` scales the forces."""

    def __init__(self, grid: CurvilinearGrid, nu: float, motion, outer=None, cfl: float = 0.5, rho: float = 1.0,
                 fourier: float = 0.4):
        if not nu > 0:
            raise ValueError(f"nu: must be > 0, got {nu}")
        if not 0 < cfl <= 1.0:
            raise ValueError(f"cfl: allowed (0, 1], got {cfl}")
        self.grid, self.nu, self.motion, self.cfl, self.rho, self.fourier = grid, float(nu), motion, cfl, rho, fourier
        self._gradients = None   # the caches of velocity_gradients, relative_fluxes and frame_velocity
        self._relative = None
        self._frame = None
        self._p_gradients = None
        self.outer = outer if outer is not None else Farfield()
        self.outer.attach(self)
        self.turbulence = LAMINAR
        nj, ni = grid.nj, grid.ni
        self.set_eddy_viscosity(np.zeros((nj, ni)))
        self.u = np.zeros((nj, ni))
        self.v = np.zeros((nj, ni))
        self.p = np.zeros((nj, ni))
        self.Fi = np.zeros((nj, ni))          # volume fluxes through the i-faces (towards +i)
        self.Fj = np.zeros((nj + 1, ni))      # ... and the j-faces (towards +j: out of the wall, outwards)
        self.t, self.n_steps = 0.0, 0
        self._H = None                        # the explicit terms of the last step (extrapolated)
        self._dt_old = None
        self._q_old = None                    # the velocity of the last step (BDF2)
        self.last_force = np.zeros(3)
        self.last_dt = 0.0
        self._build_operators()
        import warp as wp

        from ..warp_setup import init_warp

        init_warp("cpu")
        self.use_wall_gradient(grid.wall_w0, grid.wall_w1)
        # the kernels' constant geometry, and their work arrays with their NumPy views (``_buffer``: allocated once;
        # the inputs are copied in through the views, where a new Warp array per input and call cost a tenth of a
        # step)
        const = lambda a, dtype=wp.float64: wp.array(np.ascontiguousarray(a), dtype=dtype, device="cpu")  # noqa: E731
        self._geo = {"area": const(grid.area), "alpha_i": const(grid.alpha_i), "beta_i": const(grid.beta_i),
                     "alpha_j": const(grid.alpha_j), "beta_j": const(grid.beta_j),
                     "six": const(grid.Si[..., 0]), "siy": const(grid.Si[..., 1]),
                     "sjx": const(grid.Sj[..., 0]), "sjy": const(grid.Sj[..., 1]),
                     "implicit_j": const(grid.implicit_j.astype(np.int32), wp.int32)}
        self._work = {}

    # --- operators ------------------------------------------------------------------------------
    def _node_matrix(self) -> sp.csr_matrix:
        """Nodes (nj + 1) x ni from the cells: the mean of the four cells around; on the wall and the outer
        boundary the mean of the two cells of the ring beside it."""
        g, nj, ni = self.grid, self.grid.nj, self.grid.ni
        rows, cols, vals = [], [], []
        for j in range(nj + 1):
            rings = [r for r in (j - 1, j) if 0 <= r < nj]
            for i in range(ni):
                k = j * ni + i
                for r in rings:
                    for c in (i - 1, i):
                        rows.append(k)
                        cols.append(g.cell(r, c))
                        vals.append(1.0 / (2 * len(rings)))
        return sp.csr_matrix((vals, (rows, cols)), shape=((nj + 1) * ni, nj * ni))

    def _build_operators(self) -> None:
        g, nj, ni = self.grid, self.grid.nj, self.grid.ni
        n = nj * ni
        J, I = np.meshgrid(np.arange(nj), np.arange(ni), indexing="ij")
        P_i = (J * ni + (I - 1) % ni).ravel()          # i-face [j, i]: minus side (j, i-1), plus side (j, i)
        E_i = (J * ni + I).ravel()
        n0_i = (J * ni + I).ravel()                    # nodes (j, i) and (j+1, i)
        n1_i = ((J + 1) * ni + I).ravel()
        Jj, Ij = np.meshgrid(np.arange(1, nj), np.arange(ni), indexing="ij")   # interior j-faces
        P_j = ((Jj - 1) * ni + Ij).ravel()
        E_j = (Jj * ni + Ij).ravel()
        n0_j = (Jj * ni + Ij).ravel()
        n1_j = (Jj * ni + (Ij + 1) % ni).ravel()
        N = self._node_matrix()
        # pressure: face gradients (times S) of the interior faces; the boundary faces' fluxes are given
        def face_gradient(alpha, beta, P, E, n0, n1):
            m = len(P)
            A = sp.csr_matrix((np.concatenate([alpha, -alpha]), (np.r_[np.arange(m), np.arange(m)], np.r_[E, P])),
                              shape=(m, n))
            B = sp.diags(beta) @ (N[n1] - N[n0])
            return (A + B).tocsr()
        Gi = face_gradient(g.alpha_i.ravel(), g.beta_i.ravel(), P_i, E_i, n0_i, n1_i)
        Gj = face_gradient(g.alpha_j[1:nj].ravel(), g.beta_j[1:nj].ravel(), P_j, E_j, n0_j, n1_j)
        # divergence: cells x (i-faces, all j-faces)
        rows = np.r_[P_i, E_i, P_j, E_j]
        cols = np.r_[np.arange(n), np.arange(n), n + ni + np.arange(len(P_j)), n + ni + np.arange(len(P_j))]
        vals = np.r_[np.ones(n), -np.ones(n), np.ones(len(P_j)), -np.ones(len(P_j))]
        self._Dint = sp.csr_matrix((vals, (rows, cols)), shape=(n, n + (nj + 1) * ni))
        L = (self._Dint[:, :n] @ Gi + self._Dint[:, n + ni:n + ni + len(P_j)] @ Gj).tolil()
        # D G phi: the outflow minus inflow of each cell, so L phi = -div(G phi); pinned in cell 0 (pure Neumann)
        L[0, :] = 0.0
        L[0, 0] = 1.0
        # minimum degree on A + A^T: the O-grid's rings wrap round, and COLAMD's order fills the factor about 1.8 times
        # as much (a cylinder's 23 808 cells: 2.9e6 against 1.7e6 entries, the solve 6.0 against 2.7 ms)
        self._poisson = spla.splu(L.tocsc(), permc_spec="MMD_AT_PLUS_A")
        # cell gradient by Green-Gauss: face values the mean of the two cells (boundary faces: the cell's)
        Sx_i, Sy_i = g.Si[..., 0].ravel(), g.Si[..., 1].ravel()
        Sx_j, Sy_j = g.Sj[..., 0], g.Sj[..., 1]
        rows, cols, vx, vy = [], [], [], []
        for (P, E, sx, sy) in ((P_i, E_i, Sx_i, Sy_i), (P_j, E_j, Sx_j[1:nj].ravel(), Sy_j[1:nj].ravel())):
            for a, b, sgn in ((P, P, 1), (P, E, 1), (E, P, -1), (E, E, -1)):
                rows.append(a)
                cols.append(b)
                vx.append(0.5 * sgn * sx)
                vy.append(0.5 * sgn * sy)
        # boundary faces: the value extrapolated linearly along the grid line from the first (last) two rings,
        # so that the wall cells' and the outer ring's gradients stay second order (a face value equal to the
        # cell's would halve the normal gradient there)
        wall = np.arange(ni)                    # the wall face of cell (0, i): outward normal -S_j[0]
        top = (nj - 1) * ni + np.arange(ni)     # the outer face of cell (nj-1, i): +S_j[nj]
        d0, d1 = g.wall_distance[0], g.wall_distance[1]
        e1 = np.hypot(g.xmj[nj, :, 0] - g.xc[nj - 1], g.xmj[nj, :, 1] - g.yc[nj - 1])
        e2 = np.hypot(g.xc[nj - 1] - g.xc[nj - 2], g.yc[nj - 1] - g.yc[nj - 2])
        for cells, next_cells, w_in, w_next, sx, sy in (
                (wall, wall + ni, d1 / (d1 - d0), -d0 / (d1 - d0), -Sx_j[0], -Sy_j[0]),
                (top, top - ni, 1 + e1 / e2, -e1 / e2, Sx_j[nj], Sy_j[nj])):
            rows += [cells, cells]
            cols += [cells, next_cells]
            vx += [w_in * sx, w_next * sx]
            vy += [w_in * sy, w_next * sy]
        inv_a = sp.diags(1.0 / g.area.ravel())
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        Gcx = (inv_a @ sp.csr_matrix((np.concatenate(vx), (rows, cols)), shape=(n, n))).tocsr()
        Gcy = (inv_a @ sp.csr_matrix((np.concatenate(vy), (rows, cols)), shape=(n, n))).tocsr()
        # linear interpolation of centre values to the interior faces (by distance along d)
        def weights(xm, P, E):
            dP = np.hypot(xm[..., 0].ravel() - g.xc.ravel()[P], xm[..., 1].ravel() - g.yc.ravel()[P])
            dE = np.hypot(xm[..., 0].ravel() - g.xc.ravel()[E], xm[..., 1].ravel() - g.yc.ravel()[E])
            w = dP / (dP + dE)
            m = len(P)
            return sp.csr_matrix((np.r_[1 - w, w], (np.r_[np.arange(m), np.arange(m)], np.r_[P, E])), shape=(m, n))
        # each family stacked, so that a projection makes four sparse products instead of twelve: the interior
        # faces' interpolation (i-faces, then j-faces) and every gradient of a cell field (the faces', then the
        # centres' x and y: ``_gradient_parts`` splits it)
        self._I_faces = sp.vstack([weights(g.xmi, P_i, E_i), weights(g.xmj[1:nj], P_j, E_j)]).tocsr()
        self._G_all = sp.vstack([Gi, Gj, Gcx, Gcy]).tocsr()
        self._Nmat = N
        # the grid's own velocity at the face midpoints is Vb + Omega x xm: its flux through each face
        self._faces_i, self._faces_j = (P_i, E_i, n0_i, n1_i), (P_j, E_j, n0_j, n1_j)

    # --- boundary values --------------------------------------------------------------------------
    def _when(self, t: float) -> tuple:
        """The key of what the caches below keep for time t: t and the motion's revision (a motion whose path can
        change at a time already asked for, bridge.aero.free_vibration.FreeMotion, counts its changes)."""
        return t, getattr(self.motion, "revision", 0)

    def frame_velocity(self, t: float) -> tuple[float, float, float]:
        """(R^T V_O, Omega): the grid's translation in its own axes and its rotation rate (the last time's kept:
        a step asks for it about a dozen times)."""
        if self._frame is not None and self._frame[0] == self._when(t):
            return self._frame[1]
        u, v, om = self.motion.velocity(t)
        ub, vb = _rot(self.motion.pose(t)[2]).T @ np.array([u, v])
        out = (float(ub), float(vb), float(om))
        self._frame = (self._when(t), out)
        return out

    def _grid_velocity(self, t, px, py):
        ub, vb, om = self.frame_velocity(t)
        return ub - om * py, vb + om * px

    def _grid_flux(self, t, xm, S):
        ux, uy = self._grid_velocity(t, xm[..., 0], xm[..., 1])
        return ux * S[..., 0] + uy * S[..., 1]

    def relative_fluxes(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """The face fluxes now relative to the grid's own motion at t, (nj, ni) through the i-faces and
        (nj + 1, ni) through the j-faces, the wall face's zero; kept until the fluxes or the time (``_when``) change
        (the arrays are the caller's to read, not to change)."""
        c = self._relative
        if c is not None and c[0] is self.Fi and c[1] is self.Fj and c[2] == self._when(t):
            return c[3]
        g = self.grid
        Fi_rel = self.Fi - self._grid_flux(t, g.xmi, g.Si)
        Fj_rel = self.Fj - self._grid_flux(t, g.xmj, g.Sj)
        Fj_rel[0] = 0.0
        self._relative = (self.Fi, self.Fj, self._when(t), (Fi_rel, Fj_rel))
        return Fi_rel, Fj_rel

    # --- the explicit terms ---------------------------------------------------------------------
    def _ring_values(self, q, q_wall_face, ghosts):
        """q with the wall's reflection below ring 0 and the two ghost rings above: (nj + 3, ni), rows -1 .. nj+1."""
        return np.vstack([2 * q_wall_face[None] - q[:1], q, ghosts])

    def _buffer(self, name: str, shape: tuple) -> tuple:
        """A work array of the Warp kernels (allocated once per name and shape) and its NumPy view."""
        import warp as wp

        entry = self._work.get(name)
        if entry is None or entry[1].shape != tuple(shape):
            a = wp.zeros(tuple(shape), dtype=wp.float64, device="cpu")
            entry = self._work[name] = (a, a.numpy())
        return entry

    def _warp(self, name: str, value) -> object:
        """``value`` copied into the work array ``name`` (a Warp array is passed as it is)."""
        if not isinstance(value, np.ndarray) and hasattr(value, "device"):
            return value
        a, view = self._buffer(name, np.shape(value))
        view[...] = value
        return a

    def _advection(self, q, ext, Fi_rel, Fj_rel, correct: bool):
        """div(q (u - u_g)) per cell area: van Leer's limited upwind face values along the grid lines; with
        ``correct``, on the implicit j-faces (``grid.implicit_j``) van Leer's less first-order upwind (the
        deferred correction: the line solve carries the upwind part), else van Leer's there too (the residual of
        a delta form whose line solve has the upwind Jacobian);
        ``ext`` is q with the wall's reflection and the two ghost rings (``_ring_values``).  Kernel
        ``kernels.curvilinear.advection``."""
        import warp as wp

        from kernels import curvilinear as _kc

        g = self.grid
        out, view = self._buffer("advection", q.shape)
        wp.launch(_kc.advection, dim=g.nj, device="cpu",
                  inputs=[self._warp("ext", ext), self._warp("Fi_rel", Fi_rel), self._warp("Fj_rel", Fj_rel),
                          self._geo["implicit_j"], int(correct), self._geo["area"], g.ni, out])
        return view.copy()

    def use_wall_gradient(self, w0: np.ndarray, w1: np.ndarray) -> None:
        """The wall face's normal gradient of the velocity, dq/dn d0 = w0 (q0 - q_w) + w1 (q1 - q_w), in the
        diffusion, the line solves and the wall's shear: by default the grid's quadratic through the wall and the
        first two rings; a wall function (bridge/cfd/curvilinear_sst.py) takes the half-cell difference (1, 0)
        with its own wall diffusivity (:meth:`set_eddy_viscosity`'s ``nu_wall``)."""
        import warp as wp

        self.wall_w0 = np.ascontiguousarray(np.broadcast_to(np.asarray(w0, dtype=np.float64), (self.grid.ni,)))
        self.wall_w1 = np.ascontiguousarray(np.broadcast_to(np.asarray(w1, dtype=np.float64), (self.grid.ni,)))
        self._w0 = wp.array(self.wall_w0, dtype=wp.float64, device="cpu")
        self._w1 = wp.array(self.wall_w1, dtype=wp.float64, device="cpu")

    def set_eddy_viscosity(self, nu_t: np.ndarray, nu_wall: np.ndarray | None = None) -> None:
        """The eddy viscosity of the cells (nj, ni), from a turbulence model: the momentum's diffusivity becomes
        nu + nu_t on the faces (the mean of the two cells; the wall face nu alone, the outer face's extrapolated
        from the last two rings), and its stress nu_t (grad u + grad u^T) (the transpose part explicit).
        ``nu_wall`` (ni,): the wall faces' diffusivity instead of nu, a wall function's (its shear over the
        wall gradient's estimate)."""
        nu_t = np.asarray(nu_t, dtype=np.float64)
        self.nu_t = nu_t
        face_i, face_j = self.eddy_faces(nu_t)
        self.nu_i, self.nu_j = self.nu + face_i, self.nu + face_j
        if nu_wall is not None:
            self.nu_j[0] = nu_wall
        self._turbulent = bool(np.any(nu_t != 0.0))

    def eddy_faces(self, cell: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A cell field of eddy diffusivity on the i-faces (nj, ni) and j-faces (nj + 1, ni): the mean of the two
        cells, zero on the wall face, extrapolated along the grid lines on the outer face (not below zero)."""
        g = self.grid
        e1 = np.hypot(g.xmj[-1, :, 0] - g.xc[-1], g.xmj[-1, :, 1] - g.yc[-1])
        e2 = np.hypot(g.xc[-1] - g.xc[-2], g.yc[-1] - g.yc[-2])
        outer = np.maximum(cell[-1] + (cell[-1] - cell[-2]) * e1 / e2, 0.0)
        return (0.5 * (cell + np.roll(cell, 1, axis=1)),
                np.vstack([np.zeros((1, g.ni)), 0.5 * (cell[1:] + cell[:-1]), outer[None]]))

    def cell_gradient(self, q, q_wall_face, q_outer_face) -> tuple[np.ndarray, np.ndarray]:
        """grad q at the cell centres by Green-Gauss: interior faces the mean of their two cells, the wall and
        outer faces the values given ((ni,) each).  Kernel ``kernels.curvilinear.cell_gradient``."""
        import warp as wp

        from kernels import curvilinear as _kc

        g, geo = self.grid, self._geo
        (gx, vx), (gy, vy) = self._buffer("grad_x", q.shape), self._buffer("grad_y", q.shape)
        wp.launch(_kc.cell_gradient, dim=g.nj, device="cpu",
                  inputs=[self._warp("q", q), self._warp("wall_face", q_wall_face),
                          self._warp("outer_face", q_outer_face), geo["six"], geo["siy"], geo["sjx"], geo["sjy"],
                          geo["area"], g.nj, g.ni, gx, gy])
        return vx.copy(), vy.copy()

    def diffusion_parts(self, q, gam_i, gam_j, q_wall_face, q_wall_node, ghosts, w0=None, w1=None):
        """div(Gamma grad q) per cell area in three parts, Gamma on the faces (gam_i (nj, ni), gam_j (nj + 1, ni)):
        every face's cross term (beta, explicit), the alpha terms of the i-faces (around each ring) and of the
        j-faces (ring to ring, the wall and outer faces with their boundary values), both implicit; each as its
        value now.  Face gradients as the module doc's (node values: the wall's given, the others the mean of the
        four cells around, the outer nodes' with ghost ring 1); the wall face's normal gradient
        w0 (q0 - q_w) + w1 (q1 - q_w) (default: the quadratic through the wall and the first two rings).  Kernel
        ``kernels.curvilinear.diffusion_parts``."""
        import warp as wp

        from kernels import curvilinear as _kc

        g, geo = self.grid, self._geo
        w0 = self._w0 if w0 is None else self._warp("w0", w0)
        w1 = self._w1 if w1 is None else self._warp("w1", w1)
        parts = [self._buffer(name, q.shape) for name in ("cross", "around", "rings")]
        wp.launch(_kc.diffusion_parts, dim=g.nj, device="cpu",
                  inputs=[self._warp("q", q), self._warp("gam_i", gam_i), self._warp("gam_j", gam_j),
                          self._warp("wall_face", q_wall_face), self._warp("wall_node", q_wall_node),
                          self._warp("ghost", ghosts[0]), w0, w1, geo["alpha_i"], geo["beta_i"], geo["alpha_j"],
                          geo["beta_j"], geo["area"], g.nj, g.ni, *(a for a, _ in parts)])
        return tuple(view.copy() for _, view in parts)

    def velocity_gradients(self, t: float) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
        """((du/dx, du/dy), (dv/dx, dv/dy)) of the velocity now at the cell centres (:meth:`cell_gradient`: the
        wall faces' the wall's velocity at t, the outer faces' the mean of the outer ring and ghost ring 1).  The
        stress's transpose part and the turbulence model's strain both need them: kept until the velocity or the
        time (``_when``) changes (the arrays are the caller's to read, not to change)."""
        c = self._gradients
        if c is not None and c[0] is self.u and c[1] is self.v and c[2] == self._when(t):
            return c[3]
        (wfu, wfv), _, (gu, gv) = self._boundary(t)
        out = tuple(self.cell_gradient(q, wf, 0.5 * (q[-1] + gh[0]))
                    for q, wf, gh in ((self.u, wfu, gu), (self.v, wfv, gv)))
        self._gradients = (self.u, self.v, self._when(t), out)
        return out

    def _transpose_stress(self, t: float):
        """div(nu_t (grad u)^T) per cell area of the velocity now, both components (explicit; zero while laminar):
        the cells' gradients averaged to the faces, nu_t on them as the momentum's (the wall face none)."""
        g = self.grid
        (ux, uy), (vx, vy) = self.velocity_gradients(t)
        nt_i, nt_j = self.nu_i - self.nu, self.nu_j - self.nu
        nt_j[0] = 0.0   # the wall face: none (a wall function's diffusivity there is the shear's, not nu_t's)
        out = []
        for a, b in ((ux, vx), (uy, vy)):   # row x: (du/dx, dv/dx) . S; row y: (du/dy, dv/dy) . S
            fa = lambda q: 0.5 * (q + np.roll(q, 1, axis=1))  # noqa: E731
            ja = lambda q: np.vstack([q[:1], 0.5 * (q[1:] + q[:-1]), q[-1:]])  # noqa: E731
            fi = nt_i * (fa(a) * g.Si[..., 0] + fa(b) * g.Si[..., 1])
            fj = nt_j * (ja(a) * g.Sj[..., 0] + ja(b) * g.Sj[..., 1])
            out.append((np.roll(fi, -1, axis=1) - fi + fj[1:] - fj[:-1]) / g.area)
        return out

    def line_solve(self, rhs, k_m, k_p, k_lo, k_hi, diag, w0, w1):
        """(I - L_i)(I + diag - L_j) x = rhs with the implicit coefficients given (already times the step): around
        the rings, then across them (kernels/curvilinear.py); x is zero on the wall and the ghost ring (an
        increment)."""
        import warp as wp

        from kernels import curvilinear as _kc

        nj, ni = self.grid.nj, self.grid.ni
        given = {"k_m": k_m, "k_p": k_p, "rhs": rhs, "k_lo": k_lo, "k_hi": k_hi, "diag": diag}
        for name, value in given.items():
            if np.shape(value) != (nj, ni):
                raise ValueError(f"line_solve: {name} has shape {np.shape(value)}, the grid's is {(nj, ni)}")
        w = {name: self._warp(f"line_{name}", value) for name, value in given.items()}
        w.update({name: self._buffer(f"line_{name}", (nj, ni))[0] for name in ("cp_i", "y", "z", "x_i", "cp_j")})
        x, x_view = self._buffer("line_x_j", (nj, ni))
        wp.launch(_kc.line_solve_around, dim=nj, device="cpu",
                  inputs=[w["k_m"], w["k_p"], w["rhs"], ni, w["cp_i"], w["y"], w["z"], w["x_i"]])
        wp.launch(_kc.line_solve_rings, dim=ni, device="cpu",
                  inputs=[w["k_lo"], w["k_hi"], w["diag"], w0, w1, w["x_i"], nj, w["cp_j"], x])
        return x_view.copy()

    def line_diagonal(self, k_m, k_p, k_lo, k_hi, diag):
        """The diagonal of the operator ``line_solve`` inverts, unfactorised: 1 plus every coefficient, the wall's in
        ring 0 times wall_w0 as the line solve weighs it (kernels/curvilinear.py)."""
        a = 1.0 + k_m + k_p + k_lo + k_hi + diag
        a[0] += k_lo[0] * (self.wall_w0 - 1.0)
        return a

    def implicit_coefficients(self, c, gam_i, gam_j, Fj_rel):
        """The line solves' coefficients (k_m, k_p, k_lo, k_hi, diag) of c div(Gamma grad q)'s alpha terms and of
        the implicit j-faces' first-order upwind advection by the relative fluxes Fj_rel (the cell's outflow
        F+ q_P + F- q_E on its upper face, less the same on its lower face)."""
        g = self.grid
        scale = c / g.area
        k_i = scale * g.alpha_i * gam_i
        k_j = g.alpha_j * gam_j
        F = np.where(g.implicit_j, Fj_rel, 0.0)
        Fp, Fm = np.maximum(F, 0.0), np.minimum(F, 0.0)
        k_lo = scale * (k_j[:-1] + Fp[:-1])
        k_hi = scale * (k_j[1:] - Fm[1:])
        diag = scale * (F[1:] - F[:-1])
        return k_i, scale * np.roll(g.alpha_i * gam_i, -1, axis=1), k_lo, k_hi, diag

    def upwind_implicit(self, q, Fj_rel):
        """The implicit j-faces' first-order upwind advection of q per cell area (the part of the line solve's
        operator, applied to q)."""
        F = np.where(self.grid.implicit_j, Fj_rel, 0.0)
        rings = np.vstack([q[:1], q, q[-1:]])   # the wall and outer faces carry no implicit flux
        f = F * np.where(F > 0, rings[:-1], rings[1:])
        return (f[1:] - f[:-1]) / self.grid.area

    # --- the step ---------------------------------------------------------------------------------
    def set_uniform_flow(self, u_inf: float = 1.0, v_inf: float = 0.0) -> None:
        """Start from a uniform stream (inertial axes) and project it onto the grid's divergence-free fluxes."""
        ub, vb = _rot(self.motion.pose(self.t)[2]).T @ np.array([u_inf, v_inf])
        self.u[:], self.v[:] = ub, vb
        self.p[:] = 0.0
        self._project(self.u, self.v, self.t, dt=1.0, accumulate=False)

    def _boundary(self, t):
        g = self.grid
        wall_face = self._grid_velocity(t, g.xmj[0, :, 0], g.xmj[0, :, 1])
        wall_node = self._grid_velocity(t, g.x[0], g.y[0])
        ghosts = self.outer.ghost_velocity(t)
        return wall_face, wall_node, ghosts

    def _explicit(self, t):
        """The explicit terms of both components of the velocity now (time t): -advection + explicit diffusion
        - Omega x u."""
        u, v = self.u, self.v
        (wfu, wfv), (wnu, wnv), (gu, gv) = self._boundary(t)
        Fi_rel, Fj_rel = self.relative_fluxes(t)
        om = self.frame_velocity(t)[2]
        tr = self._transpose_stress(t) if self._turbulent else (0.0, 0.0)
        out = []
        for q, wf, wn, gh, frame, extra in ((u, wfu, wnu, gu, om * v, tr[0]), (v, wfv, wnv, gv, -om * u, tr[1])):
            adv = self._advection(q, self._ring_values(q, wf, gh), Fi_rel, Fj_rel, correct=True)
            cross, around, rings = self.diffusion_parts(q, self.nu_i, self.nu_j, wf, wn, gh)
            out.append((cross - adv + frame + extra, around + rings, (wf, gh[0])))
        return out

    def _project(self, us, vs, t_new, dt, accumulate=True, weight=None):
        """Face fluxes of (us, vs) with the pressure's face gradient put back, the projection, and the
        corrected centres, fluxes and pressure (module doc).  ``weight``: Rhie and Chow's, per cell (default
        ``dt`` everywhere)."""
        g, nj, ni = self.grid, self.grid.nj, self.grid.ni
        n = nj * ni                              # cells, and i-faces
        if accumulate:
            gp_i, gp_j, gpx, gpy = self._gradient_parts(self._gradients_of_p())
            w_cells = np.full(n, dt) if weight is None else weight.ravel()
            w_faces = self._I_faces @ w_cells
            uh = us.ravel() + w_cells * gpx.ravel()
            vh = vs.ravel() + w_cells * gpy.ravel()
        else:
            uh, vh = us.ravel(), vs.ravel()
        uv = self._I_faces @ np.column_stack([uh, vh])
        Fi = uv[:n, 0] * g.Si[..., 0].ravel() + uv[:n, 1] * g.Si[..., 1].ravel()
        Fj_in = uv[n:, 0] * g.Sj[1:nj, :, 0].ravel() + uv[n:, 1] * g.Sj[1:nj, :, 1].ravel()
        if accumulate:
            Fi -= w_faces[:n] * gp_i.ravel()
            Fj_in -= w_faces[n:] * gp_j.ravel()
        Fj = np.empty((nj + 1, ni))
        Fj[0] = self._grid_flux(t_new, g.xmj[0], g.Sj[0])
        Fj[1:nj] = Fj_in.reshape(nj - 1, ni)
        Fj[nj] = self.outer.outer_fluxes(t_new)
        Fi = Fi.reshape(nj, ni)
        div = np.roll(Fi, -1, axis=1) - Fi + Fj[1:] - Fj[:-1]    # outflow of each cell
        rhs = div.ravel() / dt
        rhs[0] = 0.0
        # L phi = D G phi (outflow of the gradient's flux) = div / dt
        phi = self._poisson.solve(rhs)
        gphi_i, gphi_j, gphi_x, gphi_y = self._gradient_parts(self._G_all @ phi)
        Fi -= dt * gphi_i
        Fj[1:nj] -= dt * gphi_j
        self.Fi, self.Fj = Fi, Fj
        self.u = us - dt * gphi_x
        self.v = vs - dt * gphi_y
        self.p = (self.p + phi.reshape(nj, ni)) if accumulate else np.zeros((nj, ni))

    @property
    def last_divergence(self) -> float:
        """The largest net outflow of a cell through the face fluxes now (round-off after a projection)."""
        Fi, Fj = self.Fi, self.Fj
        return float(np.abs(np.roll(Fi, -1, axis=1) - Fi + Fj[1:] - Fj[:-1]).max())

    def diffusion_sums(self) -> tuple[np.ndarray, np.ndarray]:
        """Each cell's sums over its faces of |beta| Gamma (the explicit cross terms) and of |alpha| Gamma (the
        implicit diffusion), the momentum's Gamma = nu_i, nu_j; the wall face's cross term none (its differences
        are the wall's own values, given).  Over the cell's area, the rates that :meth:`_flow_dt` weighs."""
        g = self.grid
        bi, bj = np.abs(g.beta_i * self.nu_i), np.abs(g.beta_j * self.nu_j)
        bj[0] = 0.0
        ai, aj = np.abs(g.alpha_i * self.nu_i), np.abs(g.alpha_j * self.nu_j)
        return (bi + np.roll(bi, -1, axis=1) + bj[1:] + bj[:-1]), (ai + np.roll(ai, -1, axis=1) + aj[1:] + aj[:-1])

    def _flow_dt(self) -> float:
        g = self.grid
        t = self.t
        Fi_rel, Fj_rel = self.relative_fluxes(t)
        Fi_rel, Fj_rel = np.abs(Fi_rel), np.where(g.implicit_j, 0.0, np.abs(Fj_rel))
        rate = (Fi_rel + np.roll(Fi_rel, -1, axis=1) + Fj_rel[1:] + Fj_rel[:-1]) / (2 * g.area)
        # the explicit cross-derivative diffusion (skewed cells only; at a corner's fan its beta is large).  SBDF2
        # with the diffusion's alpha terms implicit (rate a) and the cross terms explicit (rate b) is stable at any
        # step while |b| <= a / 3 (the test equation y' = (-a + b) y: the roots of its recursion stay in the unit
        # circle; Frank, Hundsdorfer and Verwer 1997, Appl. Numer. Math. 25).  For the operators the bound is on
        # the eigenvalues of (-L_alpha)^-1 C, which a cell's sums only indicate: a mode along the wall feels less of
        # the implicit diffusion across the rings than the cell's sum holds.  So a per-cell rule, checked on the
        # operators of the Great Belt deck's O-grid (0.13 there, under 1/3: tests/cfd/test_curvilinear.py): a cell
        # counts its cross terms only where they exceed a third of its implicit diffusion (in the wall cells at the
        # deck's corners, counted, they set a step 6 times the background's shorter); each cell's two explicit
        # rates add, and the fastest cell sets the step
        cross, implicit = self.diffusion_sums()
        cross = np.where(3.0 * cross > implicit, cross, 0.0)
        fastest = float((rate / self.cfl + cross / (g.area * self.fourier)).max())
        return 1.0 / fastest if fastest != 0 else math.inf   # (a NaN state stays NaN)

    def _advance_flow(self, dt: float) -> None:
        g = self.grid
        t, t_new = self.t, self.t + dt
        terms = self._explicit(t)
        H = [e for e, _, _ in terms]
        # BDF2 with extrapolated explicit terms (SBDF2: second order, and its implicit part damps the stiff
        # diffusion modes of the thin wall cells, where Crank-Nicolson's ring for long); a variable step
        # (ratio w); the first step backward Euler
        if self._H is None:
            w, a0 = 0.0, 1.0
            ex = H
        else:
            w = dt / self._dt_old
            a0 = (1 + 2 * w) / (1 + w)
            ex = [(1 + w) * h - w * h0 for h, h0 in zip(H, self._H, strict=True)]
        c = dt / a0
        (wfu1, wfv1), _, (gu1, gv1) = self._boundary(t_new)
        gpx, gpy = self.pressure_gradient()
        Fj_rel = self.relative_fluxes(t)[1]   # the implicit j-faces' advection: by the fluxes now
        wall_k = self.nu_j[0] * g.alpha_j[0] * (self.wall_w0 + self.wall_w1) / g.area[0]
        top_k = self.nu_j[-1] * g.alpha_j[-1] / g.area[-1]
        new = []
        coefficients = self.implicit_coefficients(c, self.nu_i, self.nu_j, Fj_rel)
        olds = (None, None) if self._q_old is None else self._q_old
        for q, q_old, e, (_, impl, (wf0, gh0)), gp, wf1, gh1 in (
                (self.u, olds[0], ex[0], terms[0], gpx, wfu1, gu1[0]),
                (self.v, olds[1], ex[1], terms[1], gpy, wfv1, gv1[0])):
            rhs = c * (e + impl - self.upwind_implicit(q, Fj_rel)) - c * gp   # the implicit terms now ...
            rhs[0] += c * wall_k * (wf1 - wf0)   # ... moved to the step's end
            rhs[-1] += c * top_k * (gh1 - gh0)
            if q_old is not None:
                rhs += (w * w / (1 + w)) / a0 * (q - q_old)
            # (I - c L_i)(I - c L_j) x = rhs: the implicit diffusion around the rings, then across them with the
            # implicit j-faces' advection (an approximate factorisation, second order in time as Crank-Nicolson's)
            new.append(q + self.line_solve(rhs, *coefficients, self._w0, self._w1))
        self._H, self._dt_old, self._q_old = H, dt, (self.u.copy(), self.v.copy())
        # Rhie and Chow's weight: the step over the implicit operator's diagonal (module doc)
        self._project(new[0], new[1], t_new, c, weight=c / self.line_diagonal(*coefficients))
        self.t, self.n_steps, self.last_dt = t_new, self.n_steps + 1, dt
        self.last_force = self._force(t_new)

    def _gradients_of_p(self) -> np.ndarray:
        """The pressure's face gradients (times S; i-faces, interior j-faces) and its centres' gradient (x, y),
        one vector; kept until p changes (a step reads it twice)."""
        c = self._p_gradients
        if c is None or c[0] is not self.p:
            c = self._p_gradients = (self.p, self._G_all @ self.p.ravel())
        return c[1]

    def _gradient_parts(self, stacked: np.ndarray) -> tuple[np.ndarray, ...]:
        """``_G_all``'s product split (views): the i-faces' (nj, ni), the interior j-faces' (nj - 1, ni), the
        centres' x and y (nj, ni)."""
        nj, ni = self.grid.nj, self.grid.ni
        n, m = nj * ni, (nj - 1) * ni
        return (stacked[:n].reshape(nj, ni), stacked[n:n + m].reshape(nj - 1, ni),
                stacked[n + m:2 * n + m].reshape(nj, ni), stacked[2 * n + m:].reshape(nj, ni))

    def pressure_gradient(self) -> tuple[np.ndarray, np.ndarray]:
        """grad p at the cell centres (Green-Gauss, the boundary faces' values extrapolated), body axes."""
        _, _, gx, gy = self._gradient_parts(self._gradients_of_p())
        return gx.copy(), gy.copy()

    # --- loads ------------------------------------------------------------------------------------
    def wall_pressure(self) -> np.ndarray:
        """p on the wall faces, extrapolated linearly from the first two rings along the grid lines."""
        d0, d1 = self.grid.wall_distance[0], self.grid.wall_distance[1]
        return self.p[0] - (self.p[1] - self.p[0]) * d0 / (d1 - d0)

    def wall_shear(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """d(u - u_g)/dn on the wall faces (both components, body axes): the velocity relative to the rigid
        grid, zero on the wall, from the wall gradient the momentum's diffusion takes (:meth:`use_wall_gradient`:
        by default one-sided and second order from the first two rings), times the wall faces' diffusivity over
        nu (1 but under a wall function).  Times rho nu it is the wall's traction (the rigid motion's own
        gradient carries no stress, and div u = 0 leaves only the normal derivative of the relative velocity)."""
        g = self.grid
        d0 = g.wall_distance[0]
        scale = self.nu_j[0] / (self.nu * d0)
        out = []
        for q, k in ((self.u, 0), (self.v, 1)):
            r0 = q[0] - self._grid_velocity(t, g.xc[0], g.yc[0])[k]
            r1 = q[1] - self._grid_velocity(t, g.xc[1], g.yc[1])[k]
            out.append(scale * (self.wall_w0 * r0 + self.wall_w1 * r1))
        return out[0], out[1]

    def _force(self, t: float) -> np.ndarray:
        """(F_x, F_y, M_z) on the body from the wall's pressure and shear, inertial axes, M_z about the
        reference point (the body coordinates' origin)."""
        g = self.grid
        S = g.Sj[0]                                   # into the fluid: the body's outward normal times length
        length = np.hypot(S[:, 0], S[:, 1])
        pw = self.wall_pressure()
        su, sv = self.wall_shear(t)
        fx = -pw * S[:, 0] + self.rho * self.nu * su * length
        fy = -pw * S[:, 1] + self.rho * self.nu * sv * length
        xm, ym = g.xmj[0, :, 0], g.xmj[0, :, 1]
        mz = float(np.sum(xm * fy - ym * fx))
        F = _rot(self.motion.pose(t)[2]) @ np.array([fx.sum(), fy.sum()])
        return np.array([F[0], F[1], mz])

    # --- the rest of the Flow protocol -------------------------------------------------------------
    @property
    def total_force(self) -> np.ndarray:
        return self.last_force

    @property
    def simulations(self) -> list:
        return []

    @property
    def n_cells(self) -> int:
        return self.grid.n_cells

    def describe(self) -> str:
        return f"O-grid {self.grid.ni} x {self.grid.nj} cells"

    def checkpoint_arrays(self) -> dict[str, np.ndarray]:
        out = {"u": self.u, "v": self.v, "p": self.p, "Fi": self.Fi, "Fj": self.Fj}
        if self._H is not None:
            out.update(H_u=self._H[0], H_v=self._H[1], dt_old=np.array(self._dt_old), u_old=self._q_old[0],
                       v_old=self._q_old[1])
        if self.turbulence is not LAMINAR:
            out.update({f"turbulence/{name}": a for name, a in self.turbulence.state_arrays().items()})
        return out

    def restore_arrays(self, arrays: dict[str, np.ndarray], t: float, n_steps: int) -> None:
        for name in ("u", "v", "p", "Fi", "Fj"):
            value = np.asarray(arrays[name], dtype=np.float64)
            if value.shape != getattr(self, name).shape:
                raise ValueError(f"field {name!r}: saved shape {value.shape}, this grid's {getattr(self, name).shape}")
            setattr(self, name, value.copy())
        if "H_u" in arrays:
            self._H = [np.asarray(arrays["H_u"]), np.asarray(arrays["H_v"])]
            self._dt_old = float(arrays["dt_old"])
            self._q_old = (np.asarray(arrays["u_old"]).copy(), np.asarray(arrays["v_old"]).copy())
        self.t, self.n_steps = float(t), int(n_steps)
        if self.turbulence is not LAMINAR:
            self.turbulence.restore({k[11:]: v for k, v in arrays.items() if k.startswith("turbulence/")})
