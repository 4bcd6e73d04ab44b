"""The k-omega SST model (2003 variant; its equations are in bridge/cfd/turbulence.py) on the body-fitted
O-grid (bridge/cfd/curvilinear.py), with the wall resolved: the first cell in the viscous sublayer.

Why its own discretisation: the O-grid's operators are its own (contravariant fluxes, the nine-point face
gradient, the thin wall cells whose normal diffusion must be implicit), so k and omega are carried by the
same operators as the velocity: van Leer's limited upwinding relative to the grid, diffusion with the full
metric, the faces' diffusivity the mean of their two cells'.

Wall (Menter 1994, AIAA J. 32: 1598; as NASA TMR's "SST" page recommends): k = 0 and
omega = 60 nu / (beta_1 d_1^2) on the wall face, d_1 the first cell centre's distance from the wall (the
Cartesian model takes the first cell's height, a quarter of the value: both are Menter's, and the result does
not depend on the factor while the first cell lies in the viscous sublayer); the
wall face's gradient the half-cell difference (omega ~ 1/d^2 next to a wall: a quadratic through the first
two rings would be worse than none).

Wall function (``walls="equilibrium"``; the Cartesian model's of the same name, kernels.transport.sst_body_walls):
for a first cell anywhere from the viscous sublayer to the log layer (y+ up to a few hundred), so that a grid
need not reach y+ ~ 1, where at Re 1e8 the wall cells are 1e-7 chords thick and, fanned out at a sharp corner,
set the O-grid's step.  From each first cell's speed U relative to the wall at its distance d (along the wall
face's normal), Spalding's law gives u_tau (kernels.curvilinear.wall_friction), and
* momentum: the wall face's shear is u_tau^2 in the direction of U, carried by the half-cell difference with
  the wall diffusivity nu_w = u_tau^2 d / U (nu in the sublayer, where Spalding's law is u+ = y+), so that the
  implicit diffusion, the line solves and the wall's force all take it;
* omega: the first cell held at sqrt(omega_vis^2 + omega_log^2), omega_vis = 6 nu / (beta_1 d^2),
  omega_log = sqrt(k) / (beta*^(1/4) kappa d) (the sublayer's and the log layer's solutions, blended);
* k: no flux into the wall, and where the first cell lies in the log layer (y+ > 10.8) the law's own
  production u_tau^3 / (kappa d) in it (below, the model's own), which does not scale with k: a layer turns
  turbulent wherever its first cell lies in the log layer, and k settles at u_tau^2 / sqrt(beta*);
* the first cells' nu_t = k / omega, without the strain limiter (their strain rate spans the wall's jump).
Below y+ ~ 5 the law is the linear profile, so the wall's shear stays right there too; k and omega still take
the wall function's values (no k flux into the wall, omega at the first centre's blend rather than Menter's
wall value), so a grid with its first cell in the sublayer takes ``walls="resolved"``.  Checked on TMR's plate
for first-cell centres at y+ 18-75 (docs/validation.md, row 17c).

Time step: one step per flow step, after it (segregated: the coefficients and nu_t from the flow's new
velocity; nu_t handed on is the new k and omega's), in delta form,
  (D - dt L_i) D^-1 (D - dt L_j) dq = dt R(q),   D = 1 + dt (the destruction rate),
R the whole explicit right-hand side (advection by van Leer's faces everywhere, diffusion, sources less sinks),
L_j with the flat cells' advection across the rings (its first-order upwind Jacobian, as the flow's line solve
has): the approximate factorisation makes the
thin wall cells' diffusion and advection and the stiff destruction implicit, and a settled state satisfies
R = 0 exactly, whatever the step.  First order in time (the flow's velocity is second order; the model lags it
by a step anyway).

The outer boundary's k and omega (two ghost rings): the freestream's, or the background's on the overset pair
(bridge.cfd.body_fitted.BodyFittedSST).
"""

from __future__ import annotations

import math

import numpy as np

from kernels import transport as _t

from .ogrid import _distance_to_polyline
from .turbulence import BETA_1

KAPPA = float(_t.KAPPA.value)

__all__ = ["CurvilinearSST", "first_height_for"]

_C = {name: float(getattr(_t, f"SST_{name}").value) for name in
      ("BETA_STAR", "A1", "SIGMA_K1", "SIGMA_K2", "SIGMA_W1", "SIGMA_W2", "BETA1", "BETA2", "GAMMA1", "GAMMA2",
       "HOLD", "YPLUS_LOG")}   # HOLD: the rate that holds a cell at a value; YPLUS_LOG: where u+ = y+ meets the log law


def first_height_for(reynolds: float, y_plus: float = 1.0, chord: float = 1.0) -> float:
    """The first cell height that puts y+ near ``y_plus`` on a turbulent flat plate of length ``chord`` at
    ``reynolds`` (on the chord): c_f = 0.026 Re^(-1/7) (White 2006, eq. 6-121), u_tau = U sqrt(c_f / 2)."""
    if not (reynolds > 0 and y_plus > 0 and chord > 0):
        raise ValueError(f"first_height_for: reynolds, y_plus, chord must be > 0, got {reynolds}, {y_plus}, {chord}")
    cf = 0.026 * reynolds ** (-1.0 / 7.0)
    return y_plus * chord / (reynolds * math.sqrt(cf / 2.0))


def _eddy_viscosity(kk, ww, sk, s2, d, nu):
    """SST's nu_t from k and omega (clipped: kk >= 0, ww > 0) and sk = sqrt(kk): the limiter by F2 and the strain."""
    c = _C
    arg2 = np.maximum(2.0 * sk / (c["BETA_STAR"] * ww * d), 500.0 * nu / (d * d * ww))
    f2 = np.tanh(arg2 ** 2)
    return c["A1"] * kk / np.maximum(c["A1"] * ww, np.sqrt(s2) * f2)


def sst_terms(k, w, s2, grad_kw, d, nu):
    """The SST-2003 coefficients of cells (turbulence.py's equations; the same as
    ``kernels.transport.sst_coefficients``): nu_t, the blending F1, k's source and sink rate, omega's source and
    sink rate (destruction and the negative part of the cross diffusion, implicit)."""
    c = _C
    kk = np.maximum(k, 0.0)
    ww = np.maximum(w, 1e-30)
    cd = np.maximum(2.0 * c["SIGMA_W2"] * grad_kw / ww, 1e-10)
    sk = np.sqrt(kk)
    arg1 = np.minimum(np.maximum(sk / (c["BETA_STAR"] * ww * d), 500.0 * nu / (d * d * ww)),
                      4.0 * c["SIGMA_W2"] * kk / (cd * d * d))
    f1 = np.tanh(arg1 ** 4)
    nu_t = _eddy_viscosity(kk, ww, sk, s2, d, nu)
    beta = f1 * c["BETA1"] + (1 - f1) * c["BETA2"]
    gamma = f1 * c["GAMMA1"] + (1 - f1) * c["GAMMA2"]
    cross = 2.0 * (1 - f1) * c["SIGMA_W2"] * grad_kw / ww
    src_k = np.minimum(nu_t * s2, 10.0 * c["BETA_STAR"] * kk * ww)
    snk_k = c["BETA_STAR"] * ww
    src_w = gamma * s2 + np.maximum(cross, 0.0)
    snk_w = beta * ww + np.maximum(-cross, 0.0) / ww
    return nu_t, f1, (src_k, snk_k), (src_w, snk_w)


class CurvilinearSST:
    """SST-2003 on a :class:`~bridge.cfd.curvilinear.CurvilinearFlow` (module doc), a turbulence model of
    bridge/cfd/flow.py: ``flow.step`` advances it after the velocity and it hands the flow nu_t.

    ``k_inf``, ``omega_inf``: the initial state and the freestream's; ``ghosts``: the two ghost rings' k and omega
    at a time, ``ghosts(t) -> ((2, ni), (2, ni))`` (default: the freestream's); ``attach=False`` leaves the
    stepping to a coupled model (the overset pair's); ``walls``: "resolved" (the first cell in the viscous
    sublayer) or "equilibrium" (Spalding's wall function, module doc)."""

    name = "sst"
    WALLS = ("resolved", "equilibrium")

    def __init__(self, flow, k_inf: float, omega_inf: float, ghosts=None, attach: bool = True,
                 walls: str = "resolved"):
        if not (k_inf >= 0 and omega_inf > 0):
            raise ValueError(f"k_inf >= 0 and omega_inf > 0 needed, got {k_inf}, {omega_inf}")
        if walls not in self.WALLS:
            raise ValueError(f"walls: one of {self.WALLS}, got {walls!r}")
        import warp as wp

        self.flow = flow
        self.walls = walls
        if walls == "equilibrium":
            flow.use_wall_gradient(1.0, 0.0)   # the half-cell difference, with the law's wall diffusivity
        g = flow.grid
        self.nu = flow.nu
        self.k_inf, self.omega_inf = float(k_inf), float(omega_inf)
        self._ghosts = ghosts
        wall = np.column_stack([g.x[0], g.y[0]])
        centres = np.column_stack([g.xc.ravel(), g.yc.ravel()])
        chunk = max(1, 2_000_000 // g.ni)   # points x wall segments at a time: the temporaries stay small
        self.wall_distance = np.concatenate([_distance_to_polyline(centres[k:k + chunk], wall)
                                             for k in range(0, len(centres), chunk)]).reshape(g.xc.shape)
        self.omega_wall = 60.0 * self.nu / (BETA_1 * self.wall_distance[0] ** 2)   # (ni,), on the wall faces
        self.k = np.full((g.nj, g.ni), self.k_inf)
        self.omega = np.full((g.nj, g.ni), self.omega_inf)
        self._ones = wp.array(np.ones(g.ni), dtype=wp.float64, device="cpu")     # the half-cell wall gradient
        self._zeros = wp.array(np.zeros(g.ni), dtype=wp.float64, device="cpu")
        self.update(flow.t)
        if attach:
            flow.use_turbulence(self)

    # --- boundary values ------------------------------------------------------------------------------
    def ghosts(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(2, ni) k and omega of the two ghost rings beyond the outer boundary."""
        if self._ghosts is None:   # a uniform stream: the freestream's
            shape = self.flow.grid.xg.shape
            return np.full(shape, self.k_inf), np.full(shape, self.omega_inf)
        return self._ghosts(t)

    def _walls(self):
        """((k on the wall faces, at the wall nodes), (omega ...)): node i lies between faces i-1 and i.  Under the
        wall function the first cells' own (no gradient into the wall; its faces carry no flux either)."""
        if self.walls == "equilibrium":
            return tuple((q[0], 0.5 * (q[0] + np.roll(q[0], 1))) for q in (self.k, self.omega))
        ni, ow = self.flow.grid.ni, self.omega_wall
        return (np.zeros(ni), np.zeros(ni)), (ow, 0.5 * (ow + np.roll(ow, 1)))

    def wall_law(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(u_tau, d, nu_w) of the wall faces under the wall function (module doc): the friction velocity from the
        first cell's speed relative to the wall on Spalding's law, the cell's distance from its wall face and the
        wall diffusivity u_tau^2 d / U (nu where the cell is at rest relative to the wall; never below nu, which
        the law gives in the sublayer but for round-off).  Kept until the flow's velocity or the time changes (a
        step asks twice)."""
        import warp as wp

        from kernels import curvilinear as _kc

        flow, g = self.flow, self.flow.grid
        c = getattr(self, "_wall_law_cache", None)
        if c is not None and c[0] is flow.u and c[1] is flow.v and c[2] == flow._when(t):
            return c[3]
        ug, vg = flow._grid_velocity(t, g.xc[0], g.yc[0])
        speed = np.hypot(flow.u[0] - ug, flow.v[0] - vg)
        d = np.maximum(g.wall_distance[0], 1e-300)
        out, u_tau = flow._buffer("wall_u_tau", (g.ni,))
        wp.launch(_kc.wall_friction, dim=g.ni, device="cpu",
                  inputs=[flow._warp("wall_speed", speed), flow._warp("wall_d", d), self.nu, out])
        u_tau = u_tau.copy()
        nu_w = np.where(speed > 0, u_tau * u_tau * d / np.where(speed > 0, speed, 1.0), self.nu)
        result = (u_tau, d, np.maximum(nu_w, self.nu))
        self._wall_law_cache = (flow.u, flow.v, flow._when(t), result)
        return result

    def _first_cells(self, t: float, nu_t: np.ndarray, terms=None) -> np.ndarray | None:
        """Under the wall function, the first cells' nu_t (k / omega, unlimited) put in ``nu_t``, their sources in
        ``terms`` (k's and omega's (source, sink) pairs: omega held at the blended wall value, k's production the
        law's where the cell lies in the log layer); returns the wall faces' diffusivity of the momentum; None for a
        resolved wall."""
        if self.walls != "equilibrium":
            return None
        u_tau, d, nu_w = self.wall_law(t)
        k0 = np.maximum(self.k[0], 0.0)
        nu_t[0] = k0 / np.maximum(self.omega[0], 1e-30)
        if terms is not None:
            w_vis = 6.0 * self.nu / (BETA_1 * d * d)
            w_log = np.sqrt(k0) / (_C["BETA_STAR"] ** 0.25 * KAPPA * d)
            (src_k, _), (src_w, snk_w) = terms
            log = d * u_tau > _C["YPLUS_LOG"] * self.nu
            src_k[0] = np.where(log, u_tau ** 3 / (KAPPA * d), src_k[0])
            src_w[0] = _C["HOLD"] * np.sqrt(w_vis * w_vis + w_log * w_log)
            snk_w[0] = _C["HOLD"]
        return nu_w

    # --- coefficients ---------------------------------------------------------------------------------
    def update(self, t: float, hand_on: bool = True) -> None:
        """The model's coefficients from the flow's velocity and k, omega now, and (``hand_on``) the flow's nu_t."""
        flow = self.flow
        kg, wg = self.ghosts(t)
        (kw, _), (ww, _) = self._walls()
        kx, ky = flow.cell_gradient(self.k, kw, 0.5 * (self.k[-1] + kg[0]))
        wx, wy = flow.cell_gradient(self.omega, ww, 0.5 * (self.omega[-1] + wg[0]))
        self.nu_t, self.f1, self.k_terms, self.w_terms = sst_terms(self.k, self.omega, self._strain(t),
                                                                   kx * wx + ky * wy, self.wall_distance, self.nu)
        nu_w = self._first_cells(t, self.nu_t, (self.k_terms, self.w_terms))
        if hand_on:
            flow.set_eddy_viscosity(self.nu_t, nu_w)

    def _strain(self, t: float) -> np.ndarray:
        """S^2 = 2 S_ij S_ij of the flow's velocity now."""
        (ux, uy), (vx, vy) = self.flow.velocity_gradients(t)
        return 2.0 * (ux * ux + vy * vy) + (uy + vx) ** 2

    def _hand_on(self, t: float) -> None:
        """The flow's nu_t from k and omega now: all of :meth:`update` that the flow's next step reads (nu_t alone:
        its limiter needs neither F1 nor grad k . grad omega); the rest waits for the next transport, which starts
        with :meth:`update`."""
        kk = np.maximum(self.k, 0.0)
        self.nu_t = _eddy_viscosity(kk, np.maximum(self.omega, 1e-30), np.sqrt(kk), self._strain(t),
                                    self.wall_distance, self.nu)
        self.flow.set_eddy_viscosity(self.nu_t, self._first_cells(t, self.nu_t))

    def _face_diffusivity(self, sigma_1: float, sigma_2: float):
        """nu + sigma nu_t on the i- and j-faces: the flow's rule for nu_t (``eddy_faces``) but on the outer
        face, which takes the outer ring's value."""
        sigma = self.f1 * sigma_1 + (1 - self.f1) * sigma_2
        gi, gj = self.flow.eddy_faces(sigma * self.nu_t)
        gj[-1] = (sigma * self.nu_t)[-1]   # the outer face: the outer ring's (no extrapolation)
        gj = self.nu + gj
        if self.walls == "equilibrium":
            gj[0] = 0.0   # no flux of k or omega into the wall
        return self.nu + gi, gj

    # --- the step -------------------------------------------------------------------------------------
    def residual(self, q, terms, sigmas, wall, ghosts, Fi_rel, Fj_rel):
        """R(q): -advection + diffusion + source - sink q per cell area (module doc), and the faces'
        diffusivities."""
        flow = self.flow
        gi, gj = self._face_diffusivity(*sigmas)
        wall_face, wall_node = wall
        adv = flow._advection(q, flow._ring_values(q, wall_face, ghosts), Fi_rel, Fj_rel, correct=False)
        one, zero = np.ones(flow.grid.ni), np.zeros(flow.grid.ni)
        cross, around, rings = flow.diffusion_parts(q, gi, gj, wall_face, wall_node, ghosts, one, zero)
        src, snk = terms
        return cross + around + rings - adv + src - snk * q, gi, gj

    def advance(self, dt: float) -> None:
        """The model over the step its flow has just taken (the flow calls it): :meth:`transport`."""
        self.transport(dt)

    def transport(self, dt: float) -> None:
        """k and omega over the step the flow has just taken (module doc), then nu_t for its next."""
        flow = self.flow
        t = flow.t
        self.update(t, hand_on=False)   # the flow has stepped: the coefficients from its new velocity
        Fi_rel, Fj_rel = flow.relative_fluxes(t)
        kg, wg = self.ghosts(t)
        kw, ww = self._walls()
        c = _C
        new = []
        for q, terms, sigmas, wall, gh in ((self.k, self.k_terms, (c["SIGMA_K1"], c["SIGMA_K2"]), kw, kg),
                                           (self.omega, self.w_terms, (c["SIGMA_W1"], c["SIGMA_W2"]), ww, wg)):
            R, gi, gj = self.residual(q, terms, sigmas, wall, gh, Fi_rel, Fj_rel)
            D = 1.0 + dt * terms[1]
            k_m, k_p, k_lo, k_hi, diag = flow.implicit_coefficients(dt, gi, gj, Fj_rel)
            dq = flow.line_solve(dt * R / D, k_m / D, k_p / D, k_lo / D, k_hi / D, diag / D, self._ones, self._zeros)
            new.append(q + dq)
        self.k = np.maximum(new[0], 0.0)
        self.omega = np.maximum(new[1], 1e-6 * self.omega_inf)
        self._hand_on(t)

    def stable_dt(self) -> float:
        """None of its own beyond the flow's: advection has the flow's Courant number, the rest is implicit but
        the cross-derivative diffusion of skewed cells, whose k and omega diffusivities nu + sigma nu_t (sigma
        <= 1) are about the momentum's nu + nu_t at most, by which the flow limits its step (on the outer face
        the ring's value against the flow's extrapolated one; and nu_t of the step's start: the limit lags the
        model by a step, as any segregated scheme's)."""
        return math.inf

    def state_arrays(self) -> dict[str, np.ndarray]:
        return {"k": self.k, "omega": self.omega}

    def restore(self, arrays: dict[str, np.ndarray]) -> None:
        for name in ("k", "omega"):
            value = np.asarray(arrays[name], dtype=np.float64)
            if value.shape != getattr(self, name).shape:
                raise ValueError(f"field {name!r}: saved shape {value.shape}, this grid's {getattr(self, name).shape}")
            setattr(self, name, value.copy())
        self.update(self.flow.t)
