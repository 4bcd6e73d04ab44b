"""Cell-centred transported scalars on a ``Simulation``'s grid, and the wall distance.

``TransportedScalar``: q(x, y, t) obeying
    dq/dt + div(q w) = div(Gamma grad q) + S_e - S_i q,
w the flow's velocity relative to the grid, Gamma > 0 a diffusivity field, S_e a source and
S_i >= 0 a sink rate (each a cell field the caller sets before a step). The equation's discretisation
and its positivity are in ``kernels.transport``; the time scheme is the flow's (``FlowConfig.time_scheme``).
A turbulence model's k and omega are two such scalars with Gamma, S_e and S_i from the model.

Boundaries, per side: ``("gradient",)`` zero normal gradient (outflow, slip walls, far field) or
``("value", q_b)`` the value on the boundary face (inflow, walls).

``wall_distance``: the exact distance of every cell centre to the nearest wall, polygons (the body,
in its own pose) and no-slip sides of the box; the distance a turbulence model needs (in a body grid
the body does not move, so it is computed once).
"""

from __future__ import annotations

import numpy as np
import warp as wp

from bridge.errors import InternalError
from kernels import transport as _t

from .grids import GHOST
from .launch import ROW0
from .precision import DTYPE, WP_DTYPE

__all__ = ["TransportedScalar", "advance_pair", "wall_distance"]

_SIDES = ("left", "right", "bottom", "top")


class TransportedScalar:
    """A scalar carried by the flow of ``sim`` (module doc). ``sides``: {side: ("gradient",) or
    ("value", q_b)}, missing sides zero-gradient; ``initial``: a number or an (ny, nx) array."""

    def __init__(self, sim, name: str, sides: dict | None = None, initial=0.0, diffusivity=0.0):
        self.sim, self.name = sim, name
        grid, dev = sim.grid, sim.L.device
        sides = dict(sides or {})
        unknown = set(sides) - set(_SIDES)
        if unknown:
            raise ValueError(f"{name}.sides: unknown side(s) {sorted(unknown)}; allowed {_SIDES}")
        kinds, values = [], []
        for side in _SIDES:
            spec = tuple(sides.get(side, ("gradient",)))
            if spec[0] == "gradient" and len(spec) == 1:
                kinds.append(0)
                values.append(0.0)
            elif spec[0] == "value" and len(spec) == 2:
                kinds.append(1)
                values.append(float(spec[1]))
            else:
                raise ValueError(f"{name}.sides[{side!r}]: {spec!r}; allowed ('gradient',) or ('value', q_b)")
        self._kinds, self._values = wp.vec4i(*kinds), wp.vec4d(*values)
        shape = grid.storage_shape("p")

        def z():
            return wp.zeros(shape, dtype=WP_DTYPE, device=dev)

        self.q, self._stage, self._next = z(), z(), z()
        self.gamma, self.source, self.sink = z(), z(), z()
        self.set(initial)
        self.set_coefficients(gamma=diffusivity)

    # --- state and coefficients ---------------------------------------------------------------
    def _assign(self, arr, value) -> None:
        g, nx, ny = GHOST, self.sim.grid.nx, self.sim.grid.ny
        host = np.zeros(arr.shape, dtype=DTYPE)
        value = np.asarray(value, dtype=DTYPE)
        if value.shape not in ((), (ny, nx), arr.shape):
            raise ValueError(f"{self.name}: need a number or shape {(ny, nx)} or {arr.shape}, got {value.shape}")
        if value.shape == arr.shape:
            host[:] = value
        else:
            host[g:g + ny, g:g + nx] = value
            host = np.pad(host[g:g + ny, g:g + nx], g, mode="edge")
        arr.assign(host)

    def set(self, value) -> None:
        """The interior cells (a number or (ny, nx)); ghosts from the boundary conditions."""
        self._assign(self.q, value)
        self.fill_ghosts(self.q)

    def set_coefficients(self, gamma=None, source=None, sink=None) -> None:
        """Gamma (> 0 where diffusion acts, >= 0), S_e and S_i (>= 0): numbers, (ny, nx) interior arrays
        (ghosts copied from the nearest cell) or full storage arrays; None leaves one as it is."""
        for arr, value, label in ((self.gamma, gamma, "gamma"), (self.source, source, "source"),
                                  (self.sink, sink, "sink")):
            if value is None:
                continue
            if label != "source" and np.min(value) < 0:
                raise ValueError(f"{self.name}.{label}: must be >= 0, got min {np.min(value)}")
            self._assign(arr, value)

    def interior(self) -> np.ndarray:
        g, nx, ny = GHOST, self.sim.grid.nx, self.sim.grid.ny
        return self.q.numpy()[g:g + ny, g:g + nx].copy()

    def fill_ghosts(self, q) -> None:
        g, grid, L = GHOST, self.sim.grid, self.sim.L
        L.once(_t.scalar_ghosts_x, grid.ny + 2 * g, [q, g, grid.nx, grid.ny, self._kinds, self._values])
        L.once(_t.scalar_ghosts_y, grid.nx + 2 * g, [q, g, grid.ny, self._kinds, self._values])

    # --- time step ----------------------------------------------------------------------------
    def stable_dt(self, u=None, v=None) -> float:
        """The largest dt for which a step keeps q non-negative and bounded: advection and diffusion
        together, cell by cell, 1 / max(rate_adv / cfl + rate_diff / (2 fourier)) with rate_adv =
        |u|/dx + |v|/dy (relative to the grid) and rate_diff = 2 Gamma (1/dx^2 + 1/dy^2) (forward Euler, each stage;
        ``FlowConfig.cfl`` and ``fourier``), for the velocity (u, v) (default: the flow's) and this
        scalar's Gamma."""
        cfg, grid = self.sim.config, self.sim.grid
        g, nx, ny = GHOST, grid.nx, grid.ny
        u, v = self.sim.relative_velocity((self.sim.u if u is None else u).numpy()[g:g + ny, g:g + nx + 1],
                                          (self.sim.v if v is None else v).numpy()[g:g + ny + 1, g:g + nx],
                                          slice(g, g + ny), slice(g, g + nx))
        dy = grid.dy[:, None]
        adv = np.maximum(np.abs(u[:, :-1]), np.abs(u[:, 1:])) / grid.dx \
            + np.maximum(np.abs(v[:-1]), np.abs(v[1:])) / dy
        diff = 2.0 * self.gamma.numpy()[g:g + ny, g:g + nx] * (1.0 / grid.dx ** 2 + 1.0 / dy ** 2)
        total = float(np.max(adv / cfg.cfl + diff / (2.0 * cfg.fourier)))
        return 1.0 / total if total > 0 else float("inf")

    def advance(self, dt: float, u=None, v=None) -> None:
        """One step of the flow's time scheme with the velocity (u, v) (default: the flow's current
        one) and the coefficients held over the step."""
        sim, g, grid = self.sim, GHOST, self.sim.grid
        u = sim.u if u is None else u
        v = sim.v if v is None else v
        substeps = sim.substeps
        src = self.q
        for k, (a, b) in enumerate(substeps):
            out = self._next if k == len(substeps) - 1 else self._stage
            sim.L.rows(_t.scalar_stage, grid.ny, g,
                       [src, u, v, self.gamma, self.source, self.sink, self.q, out, sim.hy_c, sim.hy_f,
                        sim.frame_x, sim.frame_y, grid.dx, float(dt), float(a), float(b), g, g + grid.nx,
                        ROW0, sim.scheme])
            self.fill_ghosts(out)
            src = out
        self.q, self._next = self._next, self.q


def advance_pair(first: TransportedScalar, second: TransportedScalar, dt: float, u=None, v=None) -> None:
    """``advance`` of two scalars on the same flow in one sweep per stage (k and omega): the same
    numbers as advancing each alone (``kernels.transport.scalar_pair_stage``), the velocity read once."""
    sim, g = first.sim, GHOST
    if second.sim is not sim:
        raise InternalError("advance_pair: both scalars must live on the same Simulation")
    grid = sim.grid
    u = sim.u if u is None else u
    v = sim.v if v is None else v
    src1, src2 = first.q, second.q
    for k, (a, b) in enumerate(sim.substeps):
        last = k == len(sim.substeps) - 1
        out1 = first._next if last else first._stage
        out2 = second._next if last else second._stage
        sim.L.rows(_t.scalar_pair_stage, grid.ny, g,
                   [src1, first.gamma, first.source, first.sink, first.q, out1,
                    src2, second.gamma, second.source, second.sink, second.q, out2,
                    u, v, sim.hy_c, sim.hy_f, sim.frame_x, sim.frame_y, grid.dx, float(dt), float(a), float(b),
                    g, g + grid.nx, ROW0, sim.scheme])
        first.fill_ghosts(out1)
        second.fill_ghosts(out2)
        src1, src2 = out1, out2
    first.q, first._next = first._next, first.q
    second.q, second._next = second._next, second.q


def wall_distance(grid, polygons=(), pose=(0.0, 0.0, 0.0), walls=(), device: str | None = None) -> np.ndarray:
    """(ny, nx) distance of each cell centre to the nearest wall: the ``polygons`` (body
    coordinates, moved to ``pose`` = (x, y, theta)) and the box sides named in ``walls`` ("left",
    "right", "bottom", "top"); inf where there is no wall at all."""
    bad = set(walls) - set(_SIDES)
    if bad:
        raise ValueError(f"walls: unknown side(s) {sorted(bad)}; allowed {_SIDES}")
    xc, yc = grid.x_centres, grid.y_centres
    out = np.full((grid.ny, grid.nx), np.inf)
    for side in walls:
        d = {"left": xc[None, :] - grid.x_faces[0], "right": grid.x_faces[-1] - xc[None, :],
             "bottom": yc[:, None] - grid.y_faces[0], "top": grid.y_faces[-1] - yc[:, None]}[side]
        out = np.minimum(out, np.broadcast_to(d, out.shape))
    if polygons:
        dev = wp.get_device(device)
        dist = wp.array(np.where(np.isfinite(out), out, 1e300), dtype=wp.float64, device=dev)
        y = wp.array(yc, dtype=wp.float64, device=dev)
        for poly in polygons:
            verts = wp.array(poly.vertices, dtype=wp.vec2d, device=dev)
            wp.launch(_t.cell_wall_distance, dim=grid.ny, device=dev,
                      inputs=[verts, float(grid.x_faces[0]), float(grid.dx), y, grid.nx, wp.vec3d(*pose), dist])
        out = dist.numpy().astype(float)
    return out
