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
sublayer (y+ of order 1). Walls of immersed bodies: ``KOmegaSST``'s ``body_walls`` (Spalding's wall
function, the same blended with the resolved wall's linear profile where the layer is laminar, the same
with the log layer's own production so the layer is turbulent from the front, or a resolved wall;
``kernels.transport.sst_body_walls``, ``kernels.cfd.ib_targets``). On an overset pair: ``OversetSST``.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from kernels import transport as _t

from .grids import GHOST
from .launch import ROW0
from .transport import TransportedScalar, advance_pair, wall_distance

__all__ = ["KOmegaSST", "OversetSST", "freestream_turbulence", "bilinear"]

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
    """SST-2003 on a ``Simulation``'s grid (module doc), with the walls of its immersed bodies
    (``sim.bodies``) treated by ``body_walls``: "function" (Spalding's wall function: for walls whose
    first fluid point may lie in the log layer, the deck at full scale), "blended" (the same k and omega at
    the wall, but the velocity forced to Spalding's profile only as far as the eddy viscosity next to the wall
    reaches the law's, the linear no-slip profile where the layer is laminar: a laminar layer can then
    separate at a corner, where the wall function lets it slip; docs/cfd.md), "equilibrium" (the wall
    function with the log layer's own k production, u_tau^3 / (kappa d), whatever the cell's k: the layer is
    turbulent wherever its first cell lies in the log layer, as a deck's at Re 1e8 is from its nose, where
    the wall function's production, which scales with sqrt(k), leaves it laminar) or "resolved" (k = 0 at the
    wall, for grids with the first point in the viscous sublayer). ``far_walls``: (polygon, pose) pairs of walls
    that are not bodies of this grid but count in its wall distance (an overset background: the body of
    the body grid at its starting pose).

    The model makes itself ``sim``'s turbulence model, which the simulation advances at the end of each of
    its steps (bridge.cfd.flow); ``attach=False`` leaves it to a coupled model that advances it itself
    (``OversetSST``)."""

    BODY_WALLS = ("function", "resolved", "blended", "equilibrium")
    _KERNEL_WALLS = {"resolved": 0, "function": 1, "blended": 1, "equilibrium": 2}   # sst_body_walls' ``function``

    name = "sst"

    def __init__(self, sim, k_inf: float, omega_inf: float, body_walls: str = "function", far_walls=(),
                 attach: bool = True):
        if not (k_inf >= 0 and omega_inf > 0):
            raise ValueError(f"k_inf >= 0 and omega_inf > 0 needed, got {k_inf}, {omega_inf}")
        if attach and sim.turbulence.name != "laminar":
            raise ValueError(f"this flow already has a turbulence model ({sim.turbulence.name}); a flow owns one")
        if body_walls not in self.BODY_WALLS:
            raise ValueError(f"body_walls: one of {', '.join(self.BODY_WALLS)}, got {body_walls!r}")
        self.sim = sim
        grid, bc, nu = sim.grid, sim.config.bc, sim.config.nu
        self.nu = float(nu)
        self.body_walls = body_walls
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
        dev = sim.L.device
        bodies = list(sim.bodies)
        d_sides = wall_distance(grid, (), walls=walls, device=str(dev))
        d = d_sides.copy()
        for b in bodies:   # the bodies' distances at the starting pose, everywhere
            d = np.minimum(d, wall_distance(grid, [b.polygon], tuple(float(c) for c in b.motion.pose(sim.t)),
                                            device=str(dev)))
        for polygon, pose in far_walls:
            d = np.minimum(d, wall_distance(grid, [polygon], tuple(float(c) for c in pose), device=str(dev)))
        self.wall_distance = d
        pad = lambda a: np.pad(np.minimum(a, 1e100), GHOST, mode="edge")  # noqa: E731
        self._dist = wp.array(pad(d), dtype=wp.float64, device=dev)
        self._dist_sides = wp.array(pad(d_sides), dtype=wp.float64, device=dev)
        self._yc = wp.array(grid.storage_y_centres(), dtype=wp.float64, device=dev)
        self._poses = None
        self._boxes = [{"verts": wp.array(b.polygon.vertices, dtype=wp.vec2d, device=dev), "i0": 0, "j0": 0, "ni": 0,
                        "nj": 0, "pose": None, "phi": wp.zeros((1, 1), dtype=wp.float64, device=dev),
                        "ext": wp.zeros((1, 1), dtype=wp.float64, device=dev)} for b in bodies]
        for b in bodies:
            b.set_wall_function(None if body_walls == "resolved" else self.nu,
                                sim.nu if body_walls == "blended" else None)
        self.k = TransportedScalar(sim, "k", sides_k, initial=k_inf)
        self.omega = TransportedScalar(sim, "omega", sides_w, initial=omega_inf)
        self.update()
        for name in self.state_arrays():   # saved and loaded with the flow (bridge.cfd.state)
            sim.state.register(name, lambda name=name: self.state_arrays()[name], after_load=self.restored)
        if attach:   # the simulation owns the model and advances it in its step (bridge.cfd.flow)
            sim.use_turbulence(self)

    def _box(self, body, pose) -> tuple[int, int, int, int]:
        """(i0, j0, ni, nj) in storage indices: the cells within the body's radius and 4 cells of its
        reference point at ``pose``."""
        grid, m = self.sim.grid, 4
        radius = float(body.polygon.radius)
        i = np.nonzero(np.abs(grid.x_centres - pose[0]) <= radius + m * grid.dx)[0]
        j = np.nonzero(np.abs(grid.y_centres - pose[1]) <= radius + m * float(grid.dy.max()))[0]
        if i.size == 0 or j.size == 0:
            raise ValueError(f"an immersed body at pose {pose} lies outside the grid")
        return int(i[0]) + GHOST, int(j[0]) + GHOST, int(i[-1] - i[0] + 1), int(j[-1] - j[0] + 1)

    def _refresh_bodies(self) -> None:
        """Each body's box at its pose of the flow's time: signed distance, cell extent, and the wall
        distance (the minimum over the sides and every body; outside the boxes it keeps the starting
        pose's, off by at most the motion's amplitude far from the body). Nothing is done while no body
        has moved."""
        sim, grid, dev = self.sim, self.sim.grid, self.sim.L.device
        poses = [tuple(float(c) for c in body.motion.pose(sim.t)) for body in sim.bodies]
        if poses == self._poses:
            return
        boxes = [self._box(body, pose) for body, pose in zip(sim.bodies, poses, strict=True)]
        # every old and new box back to the sides' distance first, then each body's minimum
        jobs = [(1, box["verts"], old, box) for box, old in zip(self._boxes, self._old_boxes(), strict=True)]
        for box, pose, new in zip(self._boxes, poses, boxes, strict=True):
            if box["phi"].shape != (new[3], new[2]):
                box["phi"] = wp.zeros((new[3], new[2]), dtype=wp.float64, device=dev)
                box["ext"] = wp.zeros((new[3], new[2]), dtype=wp.float64, device=dev)
            box.update(i0=new[0], j0=new[1], ni=new[2], nj=new[3], pose=pose)
            jobs.append((1, box["verts"], new, box))
        jobs += [(0, box["verts"], (box["i0"], box["j0"], box["ni"], box["nj"]), box) for box in self._boxes]
        for reset, verts, (i0, j0, ni, nj), box in jobs:
            if ni == 0:
                continue
            sim.L.once(_t.body_wall_cells, nj,
                       [verts, wp.vec3d(*(box["pose"] or (0.0, 0.0, 0.0))), float(grid.x_faces[0]), grid.dx, self._yc,
                        sim.hy_c, GHOST, i0, j0, ni, reset, box["phi"], box["ext"], self._dist_sides, self._dist])
        self._poses = poses

    def _old_boxes(self) -> list:
        return [(b["i0"], b["j0"], b["ni"], b["nj"]) for b in self._boxes]

    def update(self) -> None:
        """The model's coefficients and nu + nu_t from the current velocity, k and omega."""
        sim, g, grid = self.sim, GHOST, self.sim.grid
        k, w = self.k, self.omega
        self._refresh_bodies()
        sim.L.rows(_t.sst_coefficients, grid.ny, g,
                   [sim.u, sim.v, k.q, w.q, self._dist, self.nu, sim.hy_c, self._yc, grid.dx, g, grid.nx,
                    grid.ny, ROW0, sim.nu, k.gamma, w.gamma, k.source, k.sink, w.source, w.sink])
        for b, body in zip(self._boxes, sim.bodies, strict=True):
            vel = wp.vec3d(*(float(c) for c in body.motion.velocity(sim.t)))
            sim.L.once(_t.sst_body_walls, b["nj"],
                       [b["phi"], b["ext"], b["i0"], b["j0"], b["ni"], k.q, w.q, sim.u, sim.v, float(grid.x_faces[0]),
                        grid.dx, self._yc, g, wp.vec3d(*b["pose"]), vel, self.nu, self._KERNEL_WALLS[self.body_walls],
                        k.source, k.sink, w.source, w.sink, sim.nu, k.gamma, w.gamma])
        self.restored()

    def stable_dt(self) -> float:
        """The transport's limit for k and omega, from each row's largest diffusivity and the largest
        velocities relative to the grid (cheaper than ``TransportedScalar.stable_dt``'s cell by cell, and no larger)."""
        cfg, grid, g = self.sim.config, self.sim.grid, GHOST
        rows = slice(g, g + grid.ny), slice(g, g + grid.nx)
        gamma = np.maximum(self.k.gamma.numpy()[rows].max(axis=1), self.omega.gamma.numpy()[rows].max(axis=1))
        u, v = self.sim.relative_velocity(self.sim.u.numpy()[rows[0], g:g + grid.nx + 1],
                                          self.sim.v.numpy()[g:g + grid.ny + 1, rows[1]], *rows)
        adv = max(u.max(), -u.min()) / grid.dx + max(v.max(), -v.min()) / float(grid.dy.min())
        diff = float(np.max(2.0 * gamma * (1.0 / grid.dx ** 2 + 1.0 / grid.dy ** 2)))
        total = adv / cfg.cfl + diff / (2.0 * cfg.fourier)
        return 1.0 / total if total > 0 else float("inf")

    def advance(self, dt: float) -> None:
        """k and omega over dt (the flow calls it after its own step): the coefficients and the flow's nu + nu_t
        from the flow's new velocity and the k, omega at the step's start (one coefficient pass per
        step; the flow's next step sees nu_t lagged by that step, as in any segregated scheme)."""
        self.update()
        advance_pair(self.k, self.omega, dt)

    def state_arrays(self) -> dict:
        """What a resumed run needs to continue bit for bit: k, omega and what the last coefficient pass
        left for the next step (from the previous step's k and omega): the flow's nu + nu_t and the
        diffusivities of the time-step limit (Warp arrays, registered in the flow's ``state``, whose load
        calls ``restored``)."""
        return {"k": self.k.q, "omega": self.omega.q, "nu_eff": self.sim.nu, "k_gamma": self.k.gamma,
                "omega_gamma": self.omega.gamma}

    def restored(self) -> None:
        """The flow's viscous time-step limit from its nu + nu_t (after ``update``, and after
        ``state_arrays`` were assigned)."""
        g, grid = GHOST, self.sim.grid
        rows = self.sim.nu.numpy()[g:g + grid.ny, g:g + grid.nx].max(axis=1)
        self.sim.nu_rows, self.sim.nu_max = rows, float(rows.max())

    def hold(self, J: np.ndarray, I: np.ndarray, k: np.ndarray, omega: np.ndarray) -> None:
        """Hold the cells (storage indices J, I) at k and omega over the next ``advance_pair`` (after
        ``update``): source R q, sink R, as the walls' cells (``kernels.transport.SST_HOLD``)."""
        hold = float(_t.SST_HOLD.value)
        for scalar, values in ((self.k, k), (self.omega, omega)):
            src, snk = scalar.source.numpy(), scalar.sink.numpy()
            src[J, I] = hold * np.asarray(values)
            snk[J, I] = hold
            if not self.sim.L.device.is_cpu:   # .numpy() was a copy
                scalar.source.assign(src)
                scalar.sink.assign(snk)

    def nu_t(self) -> np.ndarray:
        """(ny, nx) eddy viscosity of the current state."""
        g, grid = GHOST, self.sim.grid
        return self.sim.nu.numpy()[g:g + grid.ny, g:g + grid.nx] - self.nu


def bilinear(field: np.ndarray, xc: np.ndarray, yc: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """Bilinear interpolation of a cell field (ny, nx) on the centres xc (uniform), yc (increasing) at the
    points (px, py), clamped to the lattice: second order, and it keeps k and omega positive."""
    dx = xc[1] - xc[0]
    fi = np.clip((px - xc[0]) / dx, 0.0, xc.size - 1.0)
    i = np.minimum(fi.astype(int), xc.size - 2)
    a = fi - i
    j = np.clip(np.searchsorted(yc, py) - 1, 0, yc.size - 2)
    b = np.clip((py - yc[j]) / (yc[j + 1] - yc[j]), 0.0, 1.0)
    return ((1 - b) * ((1 - a) * field[j, i] + a * field[j, i + 1])
            + b * ((1 - a) * field[j + 1, i] + a * field[j + 1, i + 1]))


class OversetSST:
    """SST-2003 on an overset pair (``bridge.cfd.overset.OversetPair``): one ``KOmegaSST`` per grid,
    coupled as the velocity is, by cells whose k and omega come from the other grid.

    * Background: the cells whose centres lie in the hole (the body grid's rectangle less ``overlap``
      background cells, where the background's faces take the body grid's velocity) are held at the body
      grid's k and omega of the step's start (bilinear; one step behind, as the background steps first).
      The background's wall distance counts the body at its starting pose (off by the motion's amplitude,
      far from the wall: it only enters the blending functions there).
    * Body grid: its outer ``ring`` cells (two: the advection stencil's reach) are held at the
      background's k and omega of the step's end, at the cells' places at that time. The ring lies
      ``overlap`` background cells outside the hole, so those values are the background's own solution.
    k and omega are the same in either frame (scalars); the body grid advects them relative to itself
    (``TransportedScalar``: the grid's velocity). Holding is the walls' mechanism (``KOmegaSST.hold``), so
    positivity and the stage scheme are untouched; bilinear interpolation keeps the values positive."""

    name = "sst"

    def __init__(self, pair, k_inf: float, omega_inf: float, body_walls: str = "function", ring: int = 2):
        self.pair = pair
        pose0 = pair.motion.pose(pair.t)
        polygons = [b.polygon for b in pair.body.bodies]
        self.background = KOmegaSST(pair.background, k_inf, omega_inf, body_walls,
                                    far_walls=[(p, pose0) for p in polygons], attach=False)
        self.body = KOmegaSST(pair.body, k_inf, omega_inf, body_walls, attach=False)
        g, gb = GHOST, pair.body.grid
        j, i = np.meshgrid(np.arange(gb.ny), np.arange(gb.nx), indexing="ij")
        edge = (i < ring) | (i >= gb.nx - ring) | (j < ring) | (j >= gb.ny - ring)
        self.ring_cells = (j[edge] + g, i[edge] + g)
        self.ring_xy = (gb.x_centres[i[edge]], gb.y_centres[j[edge]])
        pair.use_turbulence(self)   # the pair advances it at the end of its step (bridge.cfd.flow)

    def hole_cells(self, t: float):
        """Background cells (storage J, I) whose centres lie in the hole at t, and their body coordinates."""
        pair, g = self.pair, GHOST
        grid, gb = pair.background.grid, pair.body.grid
        cx = np.array([gb.x_faces[0], gb.x_faces[-1]])[[0, 1, 0, 1]]
        cy = np.array([gb.y_faces[0], gb.y_faces[-1]])[[0, 0, 1, 1]]
        X, Y = pair.to_background(cx, cy, t)
        i = np.nonzero((grid.x_centres >= X.min()) & (grid.x_centres <= X.max()))[0]
        j = np.nonzero((grid.y_centres >= Y.min()) & (grid.y_centres <= Y.max()))[0]
        JJ, II = np.meshgrid(j, i, indexing="ij")
        xi, eta = pair.to_body(grid.x_centres[II], grid.y_centres[JJ], t)
        hx0, hx1, hy0, hy1 = pair.hole
        inside = (xi >= hx0) & (xi <= hx1) & (eta >= hy0) & (eta <= hy1)
        return (JJ[inside] + g, II[inside] + g), xi[inside], eta[inside]

    def advance(self, dt: float) -> None:
        """k and omega of both grids over the step just taken by both flows (``OversetPair.step``)."""
        pair = self.pair
        t = pair.t
        bg, body = self.background, self.body
        gb = pair.body.grid
        bg.update()
        (J, I), xi, eta = self.hole_cells(t)
        if J.size:
            bg.hold(J, I, *(bilinear(s.interior(), gb.x_centres, gb.y_centres, xi, eta)
                            for s in (body.k, body.omega)))
        advance_pair(bg.k, bg.omega, dt)
        body.update()
        grid = pair.background.grid
        X, Y = pair.to_background(*self.ring_xy, t)
        body.hold(*self.ring_cells, *(bilinear(s.interior(), grid.x_centres, grid.y_centres, X, Y)
                                 for s in (bg.k, bg.omega)))
        advance_pair(body.k, body.omega, dt)

    def stable_dt(self) -> float:
        return min(self.background.stable_dt(), self.body.stable_dt())
