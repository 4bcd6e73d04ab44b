"""NumPy implementation of the same projection step (no immersed body): the benchmark's baseline
and an independent check of the Warp kernels (tests compare the two to round-off).

Same discretisation as ``kernels/cfd.py`` and ``time_stepping.py``, written with array slices:
predictor (limited/central advection, variable-viscosity stress, incremental pressure gradient),
inflow / convective outflow / slip boundaries, divergence, the same direct Poisson solver, projection.
Arrays use the storage layout of ``grids`` and are mutated in place.
"""

from __future__ import annotations

import numpy as np

from .advection import scheme_code
from .grids import GHOST, CartesianGrid
from .pressure import PoissonSolver
from .time_stepping import TIME_SCHEMES, FlowConfig

__all__ = ["NumpyFlow"]


def _limited(qu, qc, qd, duc, dcd, w, scheme):
    dq = qd - qc
    if scheme == 0:
        return qc + w * dq
    # van Leer: psi(r) dq with r = ((qc - qu)/duc) / (dq/dcd), psi = (r + |r|)/(1 + |r|)
    a = (qc - qu) / duc
    b = dq / dcd
    ok = a * b > 0
    r = np.where(ok, a / np.where(ok, b, 1.0), 0.0)
    psi = (r + np.abs(r)) / (1.0 + np.abs(r))
    return qc + w * psi * dq


def _flux(vel, qm2, qm1, qp1, qp2, dm, d0, dp, wm, scheme):
    pos = _limited(qm2, qm1, qp1, dm, d0, wm, scheme)
    neg = _limited(qp2, qp1, qm1, dp, d0, 1.0 - wm, scheme)
    return vel * np.where(vel >= 0, pos, neg)


class NumpyFlow:
    """State (u, v, p, nu as NumPy storage arrays) and ``step(dt)`` of the reference implementation."""

    def __init__(self, grid: CartesianGrid, config: FlowConfig):
        bc = config.bc
        if not (bc.left == "inflow" and bc.bottom == "slip" and bc.top == "slip" and bc.inflow_profile is None):
            raise ValueError("bc: the NumPy reference implements uniform inflow, outflow and slip sides only")
        self.grid, self.config = grid, config
        self.u, self.v, self.p = (np.zeros(grid.storage_shape(f)) for f in "uvp")
        self.nu = np.full_like(self.p, config.nu)
        self.hc = grid.hy_cells()
        self.hf = grid.hy_faces()
        self.scheme = scheme_code(config.advection)
        self.poisson = PoissonSolver(grid)
        self.uin = bc.u_inf
        self.t = 0.0

    def fill_ghosts(self, u, v):
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        for k in range(1, g + 1):  # slip bottom/top
            u[g - k] = u[g + k - 1]
            u[g + ny - 1 + k] = u[g + ny - k]
            v[g - k] = -v[g + k]
            v[g + ny + k] = -v[g + ny - k]
        v[g] = 0.0
        v[g + ny] = 0.0
        for k in range(1, g + 1):  # inflow left, outflow right
            u[:, g - k] = u[:, g]
            u[:, g + nx + k] = u[:, g + nx]
            v[:, g - k] = -v[:, g + k - 1]
            v[:, g + nx + k - 1] = v[:, g + nx - k]

    def _predict(self, u, v, u0, v0, us, vs, dt, a, b):
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        dx, s, nu, hc, hf = self.grid.dx, self.scheme, self.nu, self.hc, self.hf
        inc = self.config.pressure == "incremental"  # the "full" form has no pressure in the predictor
        p = self.p
        # u-faces: rows g..g+ny-1, columns g+1..g+nx-1
        J0, J1, I0, I1 = g, g + ny, g + 1, g + nx

        def A(arr, dj, di):
            return arr[J0 + dj:J1 + dj, I0 + di:I1 + di]

        def H(arr, dj):
            return arr[J0 + dj:J1 + dj, None]

        def fx(sh):
            uc = 0.5 * (A(u, 0, sh) + A(u, 0, sh + 1))
            return _flux(uc, A(u, 0, sh - 1), A(u, 0, sh), A(u, 0, sh + 1), A(u, 0, sh + 2), dx, dx, dx, 0.5, s) \
                - 2 * A(nu, 0, sh) * (A(u, 0, sh + 1) - A(u, 0, sh)) / dx

        def gy(sh):  # corner flux on v-face row J+sh (sh = 1 top, 0 bottom)
            vt = 0.5 * (A(v, sh, -1) + A(v, sh, 0))
            nut = 0.25 * (A(nu, sh - 1, -1) + A(nu, sh - 1, 0) + A(nu, sh, -1) + A(nu, sh, 0))
            return _flux(vt, A(u, sh - 2, 0), A(u, sh - 1, 0), A(u, sh, 0), A(u, sh + 1, 0),
                         H(hf, sh - 1), H(hf, sh), H(hf, sh + 1), 0.5 * H(hc, sh - 1) / H(hf, sh), s) \
                - nut * ((A(u, sh, 0) - A(u, sh - 1, 0)) / H(hf, sh) + (A(v, sh, 0) - A(v, sh, -1)) / dx)

        rhs = -(fx(0) - fx(-1)) / dx - (gy(1) - gy(0)) / H(hc, 0)
        if inc:
            rhs -= (A(p, 0, 0) - A(p, 0, -1)) / dx
        us[J0:J1, I0:I1] = a * A(u0, 0, 0) + b * (A(u, 0, 0) + dt * rhs)

        # v-faces: rows g+1..g+ny-1, columns g..g+nx-1
        J0, J1, I0, I1 = g + 1, g + ny, g, g + nx
        wl = 0.5 * H(hc, 0) / H(hf, 0)
        wu = 0.5 * H(hc, -1) / H(hf, 0)

        def fxv(sh):  # corner flux at u-column I+sh (sh = 1 right, 0 left)
            ucr = wl * A(u, -1, sh) + wu * A(u, 0, sh)
            nur = 0.25 * (A(nu, -1, sh - 1) + A(nu, -1, sh) + A(nu, 0, sh - 1) + A(nu, 0, sh))
            return _flux(ucr, A(v, 0, sh - 2), A(v, 0, sh - 1), A(v, 0, sh), A(v, 0, sh + 1), dx, dx, dx, 0.5, s) \
                - nur * ((A(v, 0, sh) - A(v, 0, sh - 1)) / dx + (A(u, 0, sh) - A(u, -1, sh)) / H(hf, 0))

        def gyv(sh):  # flux at cell centre row J+sh (sh = 0 top, -1 bottom)
            vt = 0.5 * (A(v, sh, 0) + A(v, sh + 1, 0))
            return _flux(vt, A(v, sh - 1, 0), A(v, sh, 0), A(v, sh + 1, 0), A(v, sh + 2, 0),
                         H(hc, sh - 1), H(hc, sh), H(hc, sh + 1), 0.5, s) \
                - 2 * A(nu, sh, 0) * (A(v, sh + 1, 0) - A(v, sh, 0)) / H(hc, sh)

        rhs = -(fxv(1) - fxv(0)) / dx - (gyv(0) - gyv(-1)) / H(hf, 0)
        if inc:
            rhs -= (A(p, 0, 0) - A(p, -1, 0)) / H(hf, 0)
        vs[J0:J1, I0:I1] = a * A(v0, 0, 0) + b * (A(v, 0, 0) + dt * rhs)

    def _boundary(self, u0, u, us, dt, a, b):
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        rows = slice(g, g + ny)
        us[rows, g] = self.uin
        I = g + nx
        us[rows, I] = a * u0[rows, I] + b * (u[rows, I] - dt * self.uin * (u[rows, I] - u[rows, I - 1]) / self.grid.dx)
        h = self.hc[rows]
        delta = (np.dot(us[rows, g], h) - np.dot(us[rows, I], h)) / h.sum()
        us[rows, I] += delta

    def _project(self, us, vs, du, dv, c):
        g, nx, ny, dx = GHOST, self.grid.nx, self.grid.ny, self.grid.dx
        rows, cols = slice(g, g + ny), slice(g, g + nx)
        div = ((us[rows, g + 1:g + nx + 1] - us[rows, cols]) / dx
               + (vs[g + 1:g + ny + 1, cols] - vs[rows, cols]) / self.hc[rows, None]) / c
        phi = self.poisson.solve(div)
        if self.config.pressure == "full":
            self.p[...] = 0.0
        du[rows, :] = us[rows, :]
        du[rows, g + 1:g + nx] -= c * np.diff(phi, axis=1) / dx
        dv[:, :] = vs
        dv[g + 1:g + ny, cols] -= c * np.diff(phi, axis=0) / self.hf[g + 1:g + ny, None]
        self.p[rows, cols] += phi

    def step(self, dt: float):
        """Advance (u, v, p) by one step in place (same stages as ``Simulation.step``)."""
        stages = TIME_SCHEMES[self.config.time_scheme]
        if not hasattr(self, "_scratch"):
            self._scratch = [np.zeros_like(self.u), np.zeros_like(self.v), np.zeros_like(self.u),
                             np.zeros_like(self.v)]
        uk, vk, us, vs = self._scratch
        src_u, src_v = self.u, self.v
        for k, (a, b) in enumerate(stages):
            last = k == len(stages) - 1
            du, dv = (self.u, self.v) if last else (uk, vk)
            self._predict(src_u, src_v, self.u, self.v, us, vs, dt, a, b)
            self._boundary(self.u, src_u, us, dt, a, b)
            self._project(us, vs, du, dv, b * dt)
            self.fill_ghosts(du, dv)
            src_u, src_v = du, dv
        self.t += dt
