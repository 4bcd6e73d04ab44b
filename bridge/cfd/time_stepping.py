"""Projection-method time stepping for 2D incompressible Navier-Stokes, assembled from parts.

Equations: du/dt + div(u u) = -grad p + div(nu_eff (grad u + grad u^T)), div u = 0, with
nu_eff(x, y) = nu + nu_t a cell-centred field (``Simulation.nu``, set by a turbulence model through
``Simulation.set_viscosity``).
Each stage of an explicit SSP Runge-Kutta method (Shu and Osher 1988; "heun" is second order) is a
projection step (Chorin 1968):
  u* = a u^n + b (u_k + dt (A(u_k) + D(u_k) [- G p]))   predictor (kernels yflux_* and predict_*)
  u* on the boundary faces (inflow, convective outflow), then direct forcing by the body
    (forced faces = target + b dt G p, so that the projection leaves them at the target; immersed.py)
  D G phi = D u* / (b dt)                                 direct Poisson solve (pressure.py)
  u_{k+1} = u* - b dt G phi,   p = phi [p <- p + phi]     projection (kernel project)
The bracketed terms are the incremental form (van Kan 1986, ``pressure="incremental"``); the default
"full" form leaves the pressure out of the predictor: with the incremental form the pressure inside an
immersed body grew without bound (interface blow-up at D/16) until the body's targets were closed
(immersed.py, Mass; it runs since), the full form is stable and the velocity stays second order in
time (tests/cfd/test_cfd_convergence.py).
State arrays are preallocated and mutated in place: stage 1 writes the stage buffers (u_k), the last
stage overwrites the state (u); ``u_star`` is scratch. Ghosts are refreshed after every projection.

Parts are swappable: the grid (object with metrics), the advection scheme (registry), the Poisson
solver (any object with ``solve_inplace(buf)`` and ``solve(rhs)``), the bodies (objects with ``update/apply/force``),
``nu`` (field), and the time scheme (registry of Shu-Osher coefficients).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import warp as wp

from kernels import cfd as _k

from .advection import scheme_code
from .boundaries import BoundaryConditions, BoundaryOperator
from .flow import LAMINAR, FlowBase, FlowDiverged
from .grids import GHOST, CartesianGrid
from .launch import ROW0, RowLauncher
from .precision import WP_DTYPE
from .pressure import PoissonSolver
from .state import FlowState

__all__ = ["FlowConfig", "Simulation", "SubstepHook", "TIME_SCHEMES", "FlowDiverged"]

# Shu-Osher form: stage k: u_{k+1} = a_k u^n + b_k (u_k + dt L(u_k)).
TIME_SCHEMES = {
    "euler": ((0.0, 1.0),),
    "heun": ((0.0, 1.0), (0.5, 0.5)),  # SSP-RK2, second order
}


class SubstepHook:
    """Called by ``Simulation.step`` in every stage (defaults do nothing): ``before_predict`` with the
    time of the stage's input, ``after_predict`` once the predicted ``u_star``/``v_star`` have their
    boundary faces (before the bodies' forcing and the projection), ``after_projection`` once the
    stage's result ``u``/``v`` has its ghosts. ``c`` = b dt, the stage's projection factor."""

    def before_predict(self, sim: Simulation, k: int, t_src: float) -> None:
        pass

    def after_predict(self, sim: Simulation, k: int, t_new: float, c: float) -> None:
        pass

    def after_projection(self, sim: Simulation, k: int, u, v, t_new: float) -> None:
        pass


@dataclass(frozen=True)
class FlowConfig:
    """Physical and numerical parameters (kinematic units; forces are scaled by ``rho``)."""

    nu: float
    rho: float = 1.0
    advection: str = "vanleer"
    time_scheme: str = "heun"
    cfl: float = 0.4
    fourier: float = 0.2  # viscous limit alone: dt <= fourier * h_min^2 / nu_max
    dt: float | None = None  # fixed step; None: 1/dt = rate/cfl + nu_max/(fourier h_min^2) (stable_dt)
    dt_max: float = np.inf
    pressure: str = "full"  # "full": predictor without grad p, p = phi of the last stage; or "incremental"
    bc: BoundaryConditions = field(default_factory=BoundaryConditions)
    threads: int = 2

    def __post_init__(self):
        if not self.nu > 0:
            raise ValueError(f"nu: must be > 0, got {self.nu}")
        if not self.rho > 0:
            raise ValueError(f"rho: must be > 0, got {self.rho}")
        scheme_code(self.advection)
        if self.time_scheme not in TIME_SCHEMES:
            raise ValueError(f"time_scheme: {self.time_scheme!r} unknown; allowed {sorted(TIME_SCHEMES)}")
        if not 0 < self.cfl <= 1.0:
            raise ValueError(f"cfl: allowed (0, 1], got {self.cfl}")
        if not 0 < self.fourier <= 0.25:
            raise ValueError(f"fourier: allowed (0, 0.25], got {self.fourier}")
        if self.dt is not None and not self.dt > 0:
            raise ValueError(f"dt: must be > 0 or None, got {self.dt}")
        if self.pressure not in ("incremental", "full"):
            raise ValueError(f"pressure: {self.pressure!r} unknown; allowed ('incremental', 'full')")
        if self.threads < 1:
            raise ValueError(f"threads: must be >= 1, got {self.threads}")


class Simulation(FlowBase):
    """Solver state on one grid plus the step assembled from its parts: a flow (bridge.cfd.flow.Flow).

    Public arrays (Warp, storage layout of ``grids``): ``u``, ``v``, ``p``, ``nu``. ``step(dt)``
    advances them in place by one time step, then the turbulence model the simulation owns, if any
    (``KOmegaSST(sim, ...)`` makes itself the simulation's model); ``t`` is the time of the state.
    """

    def __init__(self, grid: CartesianGrid, config: FlowConfig, bodies=(), device: str | None = None,
                 poisson=None):
        self.grid, self.config = grid, config
        self.turbulence = LAMINAR
        self.L = RowLauncher(device, config.threads)
        dev = self.L.device
        g, nx, ny = GHOST, grid.nx, grid.ny
        self.bc = BoundaryOperator(config.bc, grid, self.L)
        self.poisson = poisson if poisson is not None else PoissonSolver(grid, launcher=self.L)
        self.scheme = scheme_code(config.advection)
        self.substeps = TIME_SCHEMES[config.time_scheme]
        self.bodies = list(bodies)

        def z(shape):
            return wp.zeros(shape, dtype=WP_DTYPE, device=dev)

        ushape, vshape, pshape = (grid.storage_shape(f) for f in "uvp")
        self.u, self.v, self.p = z(ushape), z(vshape), z(pshape)
        self.state = FlowState()   # what a resumed run needs; models add their fields (bridge.cfd.state)
        for name in "uvp":
            self.state.register(name, getattr(self, name))
        self.u_sub, self.v_sub = z(ushape), z(vshape)
        self.u_star, self.v_star = z(ushape), z(vshape)
        # predictor row blocks: one per CPU thread (the y-flux carried up the block), short blocks on CUDA
        self.n_blocks = self.L.threads if dev.is_cpu else max(1, ny // 4)
        self.yflux_scratch = z((2 * self.n_blocks, nx + 1 + 2 * g))  # two y-flux rows per block
        self.nu = wp.full(pshape, config.nu, dtype=WP_DTYPE, device=dev)
        self.rhs = z((ny, nx))  # D u* / c, overwritten in place by phi (the Poisson solve)
        self.hy_c = wp.array(grid.hy_cells(), dtype=WP_DTYPE, device=dev)
        self.hy_f = wp.array(grid.hy_faces(), dtype=WP_DTYPE, device=dev)
        self._hf_inner = grid.hy_faces()[g + 1:g + ny]  # interior v-face spacings (stable_dt)
        self._host = dev.is_cpu
        if self._host:  # zero-copy views for the FFT solve
            self._rhs_np = self.rhs.numpy()
        # velocity of the grid (a moving frame, bridge.cfd.overset): zero for a fixed grid
        self.frame_x = z(pshape[0])    # x-velocity at the heights of storage rows: cell centres
        self.frame_xf = z(vshape[0])   # ... and v-faces
        self.frame_y = z(pshape[1])    # y-velocity at the x of storage columns: cell centres
        self.frame_yu = z(ushape[1])   # ... and u-faces
        self.frame_omega = 0.0
        self._frame = (0.0, 0.0, 0.0)
        self._frame_coords = (grid.storage_y_centres(), grid.storage_y_faces(),
                              grid.x_faces[0] + (np.arange(pshape[1]) - g + 0.5) * grid.dx,
                              grid.x_faces[0] + (np.arange(ushape[1]) - g) * grid.dx)
        self.hooks: list[SubstepHook] = []   # the overset coupling's frame and fringe (bridge.cfd.overset)
        self.last_force = [np.zeros(3) for _ in self.bodies]
        self.nu_max = config.nu
        self.nu_rows = None   # largest nu of each cell row (ny,), where a viscosity field sets it (stable_dt)
        self.last_dt = 0.0

    # the time of the state and the steps taken: kept with the fields (saved and loaded with them)
    t = property(lambda self: self.state.t, lambda self, value: setattr(self.state, "t", float(value)))
    n_steps = property(lambda self: self.state.n_steps,
                       lambda self, value: setattr(self.state, "n_steps", int(value)))

    def add_body(self, polygon, motion, margin: int = 3):
        """Immerse a rigid polygon moving with ``motion``; returns the ``ImmersedBody``."""
        from .immersed import ImmersedBody

        body = ImmersedBody(polygon, motion, self.grid, self.L, margin, substeps=len(self.substeps))
        self.bodies.append(body)
        self.last_force.append(np.zeros(3))
        return body

    def set_frame_velocity(self, vx: float, vy: float, omega: float) -> None:
        """The grid moves rigidly: its point (x, y) (grid coordinates) has the velocity
        (vx - omega y, vy + omega x) in the grid's axes, which turn at ``omega``. The state is then the
        absolute velocity in the grid's axes (the predictor advects it with the velocity relative to
        the grid and adds the turning axes' source, kernels.cfd.predict_u). (0, 0, 0): a fixed grid."""
        if (vx, vy, omega) == self._frame:
            return
        self._frame = (vx, vy, omega)
        yc, yf, xc, xu = self._frame_coords
        for arr, values in ((self.frame_x, vx - omega * yc), (self.frame_xf, vx - omega * yf),
                            (self.frame_y, vy + omega * xc), (self.frame_yu, vy + omega * xu)):
            if self._host:
                arr.numpy()[:] = values   # a view on the CPU: no copy
            else:
                arr.assign(values)
        self.frame_omega = float(omega)

    def relative_velocity(self, u, v, rows: slice, cols: slice):
        """(u, v) relative to the grid: the face velocities ``u`` (storage rows ``rows`` of the cells'
        heights) and ``v`` (storage columns ``cols`` of the cells' x) less the grid's own velocity there
        (``set_frame_velocity``); the arrays themselves for a fixed grid. What carries the flow through the
        cells, so what limits the time step: a grid moving against the stream sees more than |u|."""
        if self._frame == (0.0, 0.0, 0.0):
            return u, v
        return u - self.frame_x.numpy()[rows, None], v - self.frame_y.numpy()[None, cols]

    def set_viscosity(self, nu_eff) -> None:
        """Effective viscosity nu + nu_t on the cells (the turbulence-model plug-in).

        ``nu_eff``: a Warp or NumPy array of the cell storage shape (ny+2G, nx+2G), ghosts included
        (the stress uses the first ghost layer), or an (ny, nx) interior array whose ghosts are then
        copied from the nearest interior cell. Updates ``nu_max`` for the viscous time-step limit.
        """
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        host = nu_eff.numpy() if isinstance(nu_eff, wp.array) else np.asarray(nu_eff, dtype=float)
        if host.shape == (ny, nx):
            host = np.pad(host, g, mode="edge")
        if host.shape != self.nu.shape or not np.all(host > 0):
            raise ValueError(f"nu_eff: need positive values of shape {(ny, nx)} or {self.nu.shape}, "
                             f"got shape {host.shape}")
        self.nu.assign(host)
        self.nu_max = float(host.max())
        self.nu_rows = host[g:g + ny, g:g + nx].max(axis=1)

    # --- initialisation ---------------------------------------------------------------------------
    def set_state(self, u=None, v=None, p=None, t: float = 0.0):
        """Set the interior/boundary faces from (ny, nx+1), (ny+1, nx), (ny, nx) arrays or scalars."""
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        for arr, val, sl in ((self.u, u, (slice(g, g + ny), slice(g, g + nx + 1))),
                             (self.v, v, (slice(g, g + ny + 1), slice(g, g + nx))),
                             (self.p, p, (slice(g, g + ny), slice(g, g + nx)))):
            if val is None:
                continue
            host = arr.numpy()
            host[sl] = val
            arr.assign(host)
        self.t = float(t)
        self.bc.initial_normal_faces(self.u, self.t)
        self._zero_wall_normals(self.v)
        self.bc.fill_ghosts(self.u, self.v)

    def _zero_wall_normals(self, v):
        g, ny = GHOST, self.grid.ny
        host = v.numpy()
        host[g, :] = 0.0
        host[g + ny, :] = 0.0
        if self.config.bc.left == "slip":
            hu = self.u.numpy()
            hu[:, g] = 0.0
            hu[:, g + self.grid.nx] = 0.0
            self.u.assign(hu)
        v.assign(host)

    def interior(self):
        """NumPy copies (u (ny, nx+1), v (ny+1, nx), p (ny, nx)) without ghosts."""
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        return (self.u.numpy()[g:g + ny, g:g + nx + 1].copy(), self.v.numpy()[g:g + ny + 1, g:g + nx].copy(),
                self.p.numpy()[g:g + ny, g:g + nx].copy())

    # --- time step ---------------------------------------------------------------------------------
    def stable_dt(self) -> float:
        """The fixed dt if configured; else the flow's limit (below) and the turbulence model's, the smaller."""
        return self.config.dt if self.config.dt is not None else super().stable_dt()

    def _flow_dt(self) -> float:
        """dt from the convective and viscous limits together; the fixed dt if configured.

        1/dt = rate/cfl + nu_max/(fourier h_min^2), rate = max|u|/dx + max|v|/hy (velocities relative to
        the grid, ``relative_velocity``): the viscous limit
        alone with the fluid at rest, close to the convective limit where viscosity is negligible, and
        stricter than the smaller of the two where both matter. Taking only the smaller one let DFG
        2D-1 at D/32 (viscous limit 1.95e-3, convective about 2.6e-3) settle into a bounded
        oscillation one diameter above the cylinder (max u 0.59 against 0.40) with c_L -0.006
        instead of 0.011 (docs/validation.md).
        """
        c = self.config
        if c.dt is not None:
            return c.dt
        # NumPy reductions on views (zero-copy on the CPU), max|q| = max(max q, -min q): 0.48 ms at
        # 1024 x 512 where a Warp row kernel took 0.86 ms (scalar loop; bench_cfd's flow, 2026-11-30)
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        u, v = self.relative_velocity(self.u.numpy()[g:g + ny, g:g + nx + 1], self.v.numpy()[g + 1:g + ny, g:g + nx],
                                      rows=slice(g, g + ny), cols=slice(g, g + nx))
        h = self.grid.min_spacing
        rate = max(u.max(), -u.min()) / self.grid.dx \
            + (np.maximum(v.max(axis=1), -v.min(axis=1)) / self._hf_inner).max()
        if not np.isfinite(rate):  # non-finite fields: the viscous limit; a NaNMonitor, if attached, stops the run
            rate = 0.0
        if self.nu_rows is None:
            viscous = self.nu_max / (c.fourier * h * h)
        else:   # a viscosity field (a turbulence model): each row's largest nu over its own spacing
            viscous = float(np.max(self.nu_rows / np.minimum(self.grid.dx, self.grid.dy) ** 2)) / c.fourier
        inv_dt = rate / c.cfl + viscous
        return float(min(1.0 / inv_dt, c.dt_max))

    def _predict(self, src_u, src_v, u0, v0, dt, a, b):
        """Predicted u*, v* (interior faces) from the stage input (src) and the step start (u0, v0)."""
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        dx, s, nb = self.grid.dx, self.scheme, self.n_blocks
        use_p = int(self.config.pressure == "incremental")
        common = [self.hy_c, self.hy_f, dx, dt, a, b]
        frame = [self.frame_x, self.frame_xf, self.frame_y, self.frame_yu, self.frame_omega]
        self.L.rows(_k.predict_u, nb, 0, [src_u, src_v, self.p, self.nu, u0, self.u_star, *common,
                                          g + 1, g + nx, g, ny, nb, use_p, s, ROW0, self.yflux_scratch, *frame],
                    min_split=2)
        self.L.rows(_k.predict_v, nb, 0, [src_u, src_v, self.p, self.nu, v0, self.v_star, *common,
                                          g, g + nx, g + 1, ny - 1, nb, use_p, s, ROW0, self.yflux_scratch, *frame],
                    min_split=2)

    def _project(self, dst_u, dst_v, c):
        g, nx, ny = GHOST, self.grid.nx, self.grid.ny
        self.L.rows(_k.divergence, ny, 0, [self.u_star, self.v_star, self.hy_c, self.grid.dx, 1.0 / c,
                                           g, nx, ROW0, self.rhs])
        if self._host:
            self.poisson.solve_inplace(self._rhs_np)
        else:
            self.rhs.assign(self.poisson.solve(self.rhs.numpy()))
        acc = int(self.config.pressure == "incremental")
        self.L.rows(_k.project, ny, 0, [self.u_star, self.v_star, self.rhs, self.hy_f, self.grid.dx, c,
                                        g, nx, ny, acc, ROW0, dst_u, dst_v, self.p])

    def _advance_flow(self, dt: float) -> None:
        """Advance the velocity and pressure by one step of ``dt`` (in place); ``step`` then advances the
        turbulence model."""
        t_new = self.t + dt
        for body in self.bodies:
            body.update(t_new)
            body.reset_impulse()
        src_u, src_v = self.u, self.v
        n = len(self.substeps)
        p_comp = self.p if self.config.pressure == "full" else None  # forcing compensation (immersed.py)

        for k, (a, b) in enumerate(self.substeps):
            last = k == n - 1
            dst_u, dst_v = (self.u, self.v) if last else (self.u_sub, self.v_sub)
            for hook in self.hooks:   # the stage's input is at t (first stage) or t_new (SSP RK2/Euler)
                hook.before_predict(self, k, self.t if k == 0 else t_new)
            self._predict(src_u, src_v, self.u, self.v, dt, a, b)
            self.bc.set_normal_faces(self.u, src_u, self.u_star, t_new, dt, a, b)
            for hook in self.hooks:
                hook.after_predict(self, k, t_new, b * dt)
            for body in self.bodies:
                body.apply(self.u_star, self.v_star, k, p_comp, b * dt)
            self._project(dst_u, dst_v, b * dt)
            self.bc.fill_ghosts(dst_u, dst_v)
            for hook in self.hooks:
                hook.after_projection(self, k, dst_u, dst_v, t_new)
            src_u, src_v = dst_u, dst_v
        weights = [float(np.prod([bb for _, bb in self.substeps[k + 1:]])) for k in range(n)]
        self.last_force = [body.force(weights, dt, self.t, t_new, self.config.rho) for body in self.bodies]
        self.last_dt = dt
        self.t = t_new
        self.n_steps += 1

    # --- the rest of the Flow protocol (bridge.cfd.flow) -------------------------------------------
    @property
    def total_force(self) -> np.ndarray:
        """(F_x, F_y, M_z) on all the bodies over the last step (``last_force`` holds each body's)."""
        return np.sum(self.last_force, axis=0) if self.last_force else np.zeros(3)

    @property
    def simulations(self) -> list[Simulation]:
        return [self]

    @property
    def n_cells(self) -> int:
        return self.grid.nx * self.grid.ny

    def describe(self) -> str:
        model = "" if self.turbulence is LAMINAR else f", {self.turbulence.name.upper()}"
        return f"{self.grid.nx} x {self.grid.ny} cells{model}"

    def checkpoint_arrays(self) -> dict[str, np.ndarray]:
        """The state a resumed run needs to continue bit for bit: the flow's and its turbulence model's
        fields (bridge.cfd.state)."""
        return self.state.arrays()

    def restore_arrays(self, arrays: dict[str, np.ndarray], t: float, n_steps: int) -> None:
        self.state.assign(arrays)
        self.t, self.n_steps = float(t), int(n_steps)
