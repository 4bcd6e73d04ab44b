"""Boundary conditions for external flow around a body on a Cartesian box.

Sides: left "inflow" (Dirichlet u = U(y, t), v = 0) or "slip"; right "outflow" (convective,
du/dt + U_c du/dx = 0 with U_c the mean inflow speed, then a uniform shift so the outflow volume
flux equals the inflow flux - needed for the Neumann pressure problem to be solvable) or "slip";
bottom/top "slip" (v = 0, du/dy = 0: far-field symmetry) or "noslip" (channel walls, u = v = 0).
Ghost values: mirror for zero gradient, antisymmetric for zero value, two layers (the limited
advection stencil reaches two points upstream).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import warp as wp

from kernels import cfd as _k

from .grids import GHOST, CartesianGrid
from .precision import DTYPE, WP_DTYPE

__all__ = ["BoundaryConditions", "BoundaryOperator"]

_CODES = {"slip": 0, "noslip": 1, "inflow": 2, "outflow": 3}


@dataclass(frozen=True)
class BoundaryConditions:
    """Kinds of the four sides and the inflow profile U(y, t) (default: uniform ``u_inf``)."""

    left: str = "inflow"
    right: str = "outflow"
    bottom: str = "slip"
    top: str = "slip"
    u_inf: float = 1.0
    inflow_profile: Callable[[np.ndarray, float], np.ndarray] | None = None

    def __post_init__(self):
        for side, allowed in (("left", ("inflow", "slip")), ("right", ("outflow", "slip")),
                              ("bottom", ("slip", "noslip")), ("top", ("slip", "noslip"))):
            val = getattr(self, side)
            if val not in allowed:
                raise ValueError(f"{side}: {val!r} not allowed; allowed: {allowed}")
        if (self.left == "inflow") != (self.right == "outflow"):
            raise ValueError(f"left/right: inflow needs an outflow and vice versa, got {self.left}/{self.right}")

    def inflow(self, y: np.ndarray, t: float) -> np.ndarray:
        if self.inflow_profile is None:
            return np.full_like(y, self.u_inf)
        return np.asarray(self.inflow_profile(y, t), dtype=DTYPE)


class BoundaryOperator:
    """Applies ``BoundaryConditions`` to the solver's arrays (mutates them in place)."""

    def __init__(self, bc: BoundaryConditions, grid: CartesianGrid, launcher):
        self.bc, self.grid, self.L = bc, grid, launcher
        self.codes = {s: _CODES[getattr(bc, s)] for s in ("left", "right", "bottom", "top")}
        self._y = grid.y_centres
        self._profile = wp.zeros(grid.ny, dtype=WP_DTYPE, device=launcher.device)
        self._flux = wp.zeros(2, dtype=WP_DTYPE, device=launcher.device)
        self._hy = wp.array(grid.hy_cells(), dtype=WP_DTYPE, device=launcher.device)
        self._profile_t = None
        # mean inflow speed for the convective outflow
        self.convective_speed = float(np.sum(bc.inflow(self._y, 0.0) * grid.dy) / np.sum(grid.dy)) \
            if bc.left == "inflow" else 0.0

    def fill_ghosts(self, u, v):
        """Ghost layers of u and v (in place) from the interior and the boundary faces."""
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        c = self.codes
        self.L.once(_k.bc_y_sides, max(u.shape[1], v.shape[1]), [u, v, g, nx, ny, c["bottom"], c["top"]])
        self.L.once(_k.bc_x_sides, max(u.shape[0], v.shape[0]), [u, v, g, nx, c["left"], c["right"]])

    def set_normal_faces(self, u0, u, ustar, t_new: float, dt: float, a: float, b: float):
        """Boundary-normal u-faces of the predicted field ``ustar`` at time t_new (in place):
        inflow profile, convective outflow, then the outflow shift that balances the volume flux."""
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        if self.bc.left != "inflow":
            return  # slip walls: normal faces stay 0 (never written)
        if self._profile_t != t_new:
            self._profile.assign(self.bc.inflow(self._y, t_new).astype(DTYPE))
            self._profile_t = t_new
        self.L.once(_k.set_inflow, ny, [ustar, self._profile, g])
        self.L.once(_k.convective_outflow, ny, [u0, u, ustar, self.grid.dx, dt, a, b,
                                                self.convective_speed, g, nx])
        self._flux.zero_()
        self.L.once(_k.boundary_fluxes, ny, [ustar, self._hy, g, nx, self._flux])
        fin, fout = self._flux.numpy()
        delta = (fin - fout) / float(self.grid.y_faces[-1] - self.grid.y_faces[0])
        self.L.once(_k.shift_outflow, ny, [ustar, float(delta), g, nx])

    def initial_normal_faces(self, u, t: float):
        """Set the inflow faces of a state (used when the state is initialised)."""
        if self.bc.left == "inflow":
            self._profile.assign(self.bc.inflow(self._y, t).astype(DTYPE))
            self._profile_t = t
            self.L.once(_k.set_inflow, self.grid.ny, [u, self._profile, GHOST])
