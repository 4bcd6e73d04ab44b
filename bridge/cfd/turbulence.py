"""k-omega SST turbulence model, the 2003 variant (Menter, Kuntz and Langtry 2003, "Ten years of
industrial experience with the SST turbulence model", Turbulence, Heat and Mass Transfer 4; NASA
Turbulence Modeling Resource: "SST-2003").

Equations (incompressible, kinematic; S = sqrt(2 S_ij S_ij) the strain-rate magnitude, d the wall
distance, phi = F1 phi_1 + (1 - F1) phi_2 for sigma_k, sigma_w, beta, gamma):
  dk/dt + div(u k) = P~ - beta* omega k + div((nu + sigma_k nu_t) grad k),
  dw/dt + div(u w) = gamma S^2 - beta w^2 + div((nu + sigma_w nu_t) grad w)
                     + 2 (1 - F1) sigma_w2 grad k . grad w / w,
  nu_t = a1 k / max(a1 w, S F2),    P~ = min(nu_t S^2, 10 beta* k w),
  F1 = tanh(arg1^4), arg1 = min(max(sqrt(k) / (beta* w d), 500 nu / (d^2 w)), 4 sigma_w2 k / (CD d^2)),
  CD = max(2 sigma_w2 grad k . grad w / w, 1e-10),
  F2 = tanh(arg2^2), arg2 = max(2 sqrt(k) / (beta* w d), 500 nu / (d^2 w)),
  beta* = 0.09, a1 = 0.31; set 1 (near wall): sigma_k 0.85, sigma_w 0.5, beta 0.075, gamma 5/9;
  set 2 (outer): sigma_k 1.0, sigma_w 0.856, beta 0.0828, gamma 0.44.
What makes this the 2003 variant rather than the 1994 one: nu_t and the production use the strain
rate S (not the vorticity), the production is limited by 10 beta* k omega, the omega production is
gamma S^2, and CD's floor is 1e-10.

Discretisation: k and omega are ``TransportedScalar``s (kernels/transport.py: conservative, van Leer
advection relative to the grid, positivity kept); the coefficients come from one Warp kernel
(``kernels.transport.sst_coefficients``), destruction terms implicit. The model is advanced after the
flow's step with that step's velocity (segregated) and hands nu + nu_t to the flow
(``Simulation.nu``, the plug-in point of the momentum stress), computed once per step from the new
velocity and the k, omega of the step's start.

Boundaries: an inflow side takes the freestream (k_inf, omega_inf); an outflow or slip side zero
gradient; a no-slip side k = 0 and omega = 60 nu / (beta_1 dy_1^2) on the wall (dy_1 the height of
the first cell: Menter's wall value, as TMR recommends), valid when the first cell is in the viscous
sublayer (y+ of order 1). Walls of immersed bodies and wall functions are not in this module yet.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from kernels import transport as _t

from .grids import GHOST
from .launch import ROW0
from .transport import TransportedScalar, advance_pair, wall_distance

__all__ = ["KOmegaSST", "freestream_turbulence"]

BETA_1 = 0.075


def freestream_turbulence(u_inf: float, nu: float, intensity: float = 0.001,
                          viscosity_ratio: float = 0.01) -> tuple[float, float]:
    """(k, omega) of a freestream of speed u_inf: k = 1.5 (I u_inf)^2, omega = k / (nu_t/nu * nu)."""
    if not (u_inf > 0 and nu > 0 and intensity > 0 and viscosity_ratio > 0):
        raise ValueError(f"freestream_turbulence: u_inf, nu, intensity, viscosity_ratio must be > 0, got "
                         f"{u_inf}, {nu}, {intensity}, {viscosity_ratio}")
    k = 1.5 * (intensity * u_inf) ** 2
    return k, k / (viscosity_ratio * nu)


class KOmegaSST:
    """SST-2003 on a ``Simulation``'s grid (module doc). ``polygons`` (with ``pose``): bodies for the
    wall distance only (their wall treatment is not implemented yet)."""

    def __init__(self, sim, k_inf: float, omega_inf: float, polygons=(), pose=(0.0, 0.0, 0.0)):
        if not (k_inf >= 0 and omega_inf > 0):
            raise ValueError(f"k_inf >= 0 and omega_inf > 0 needed, got {k_inf}, {omega_inf}")
        self.sim = sim
        grid, bc, nu = sim.grid, sim.config.bc, sim.config.nu
        self.nu = float(nu)
        sides_k, sides_w, walls = {}, {}, []
        first = {"bottom": float(grid.dy[0]), "top": float(grid.dy[-1])}
        for side in ("left", "right", "bottom", "top"):
            kind = getattr(bc, side)
            if kind == "inflow":
                sides_k[side], sides_w[side] = ("value", k_inf), ("value", omega_inf)
            elif kind == "noslip":
                walls.append(side)
                sides_k[side] = ("value", 0.0)
                sides_w[side] = ("value", 60.0 * self.nu / (BETA_1 * first[side] ** 2))
        d = wall_distance(grid, polygons, pose, walls, device=str(sim.L.device))
        self.wall_distance = d
        d_storage = np.pad(np.minimum(d, 1e100), GHOST, mode="edge")
        self._dist = wp.array(d_storage, dtype=wp.float64, device=sim.L.device)
        self._yc = wp.array(grid.storage_y_centres(), dtype=wp.float64, device=sim.L.device)
        self.k = TransportedScalar(sim, "k", sides_k, initial=k_inf)
        self.omega = TransportedScalar(sim, "omega", sides_w, initial=omega_inf)
        self.update()

    def update(self) -> None:
        """The model's coefficients and nu + nu_t from the current velocity, k and omega."""
        sim, g, grid = self.sim, GHOST, self.sim.grid
        k, w = self.k, self.omega
        sim.L.rows(_t.sst_coefficients, grid.ny, g,
                   [sim.u, sim.v, k.q, w.q, self._dist, self.nu, sim.hy_c, self._yc, grid.dx, g, grid.nx,
                    grid.ny, ROW0, sim.nu, k.gamma, w.gamma, k.source, k.sink, w.source, w.sink])
        nu = sim.nu.numpy()[g:g + grid.ny, g:g + grid.nx]
        sim.nu_rows = nu.max(axis=1)
        sim.nu_max = float(sim.nu_rows.max())

    def stable_dt(self) -> float:
        """The transport's limit for k and omega, from each row's largest diffusivity and the largest
        velocities (cheaper than ``TransportedScalar.stable_dt``'s cell by cell, and no larger)."""
        cfg, grid, g = self.sim.config, self.sim.grid, GHOST
        rows = slice(g, g + grid.ny), slice(g, g + grid.nx)
        gamma = np.maximum(self.k.gamma.numpy()[rows].max(axis=1), self.omega.gamma.numpy()[rows].max(axis=1))
        u = self.sim.u.numpy()[rows[0], g:g + grid.nx + 1]
        v = self.sim.v.numpy()[g:g + grid.ny + 1, rows[1]]
        adv = max(u.max(), -u.min()) / grid.dx + max(v.max(), -v.min()) / float(grid.dy.min())
        diff = float(np.max(2.0 * gamma * (1.0 / grid.dx ** 2 + 1.0 / grid.dy ** 2)))
        total = adv / cfg.cfl + diff / (2.0 * cfg.fourier)
        return 1.0 / total if total > 0 else float("inf")

    def advance(self, dt: float) -> None:
        """k and omega over dt (call after the flow's step): the coefficients and the flow's nu + nu_t
        from the flow's new velocity and the k, omega at the step's start (one coefficient pass per
        step; the flow's next step sees nu_t lagged by that step, as in any segregated scheme)."""
        self.update()
        advance_pair(self.k, self.omega, dt)

    def nu_t(self) -> np.ndarray:
        """(ny, nx) eddy viscosity of the current state."""
        g, grid = GHOST, self.sim.grid
        return self.sim.nu.numpy()[g:g + grid.ny, g:g + grid.nx] - self.nu
