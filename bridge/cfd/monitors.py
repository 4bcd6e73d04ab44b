"""Monitors: small objects the time loop calls after every step (PyFR-plugin style).

Each monitor has ``__call__(sim)``; ``every`` sets how often it works. ``run`` is the loop.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable

import numpy as np

from kernels import cfd as _k

from .grids import GHOST
from .launch import ROW0
from .time_stepping import FlowDiverged, Simulation

__all__ = ["ForceHistory", "CFLMonitor", "DivergenceMonitor", "NaNMonitor", "ProgressNote", "run",
           "max_divergence"]


class ForceHistory:
    """Records (t, F_x, F_y, M_z) of every body after every step."""

    def __init__(self):
        self.t, self.forces = [], []

    def __call__(self, sim: Simulation):
        self.t.append(sim.t)
        self.forces.append(np.array(sim.last_force))

    def array(self) -> tuple[np.ndarray, np.ndarray]:
        """times (n,), forces (n, n_bodies, 3)."""
        return np.array(self.t), np.array(self.forces)


class ProgressNote:
    """Writes a line at every ``fraction`` of the way to ``t_end``: time reached, steps, ``detail(sim)`` if
    given, and the wall time left at the rate so far - to ``sink`` (a callable taking the line) if given,
    else to ``stream`` (stderr by default). Works with anything that has ``t`` and ``n_steps`` (a
    ``Simulation`` or an ``OversetPair``); the rate counts from the first call, so a resumed run's
    estimate is not skewed by the time it did not spend, and the lines come at every ``fraction`` of what is
    left at the first call (of the whole run when it starts at t = 0), so that a resumed run shows its
    progress as often as a fresh one."""

    def __init__(self, label: str, t_end: float, fraction: float = 0.1, stream=None,
                 sink: Callable[[str], None] | None = None, detail: Callable[[object], str] | None = None):
        if not 0 < fraction <= 1:
            raise ValueError(f"fraction: allowed (0, 1], got {fraction}")
        self.label, self.t_end, self.fraction, self.detail = label, float(t_end), fraction, detail
        self.stream = sys.stderr if stream is None else stream
        self.sink = self._print if sink is None else sink
        self._start = None   # (wall clock, t) at the first call
        self._next = None

    def _print(self, line: str) -> None:
        print(line, file=self.stream, flush=True)

    def __call__(self, sim) -> None:
        now = time.perf_counter()
        if self._start is None:
            self._start = (now, sim.t)
            # nothing left (a run resumed at its end): steps of the whole run, which _next can move by
            remaining = self.t_end - sim.t
            self._step = self.fraction * (remaining if remaining > 1e-9 * self.t_end else self.t_end)
            self._next = sim.t + self._step
        if sim.t < self._next:
            return
        wall0, t0 = self._start
        left = (now - wall0) / max(sim.t - t0, 1e-300) * max(self.t_end - sim.t, 0.0)
        extra = f"{self.detail(sim)}, " if self.detail is not None else ""
        self.sink(f"{self.label}: t = {sim.t:.4g} of {self.t_end:.4g} ({100 * sim.t / self.t_end:.0f} %), "
                  f"{sim.n_steps} steps, {extra}about {left:.0f} s left")
        while self._next <= sim.t:
            self._next += self._step


class CFLMonitor:
    """Records the convective Courant number max(|u| dt/dx + |v| dt/dy) of the state, with the velocity
    relative to the grid (``Simulation.relative_velocity``): what crosses the cells of a moving body grid."""

    def __init__(self, every: int = 10, limit: float = 1.0):
        self.every, self.limit, self.history = every, limit, []

    def __call__(self, sim: Simulation):
        if sim.n_steps % self.every:
            return
        u, v, _ = sim.interior()
        u, v = sim.relative_velocity(u, v, rows=slice(GHOST, GHOST + sim.grid.ny),
                                     cols=slice(GHOST, GHOST + sim.grid.nx))
        dy = sim.grid.hy_faces()[GHOST:GHOST + sim.grid.ny + 1][:, None]
        dt = sim.last_dt
        c = float(np.abs(u).max() * dt / sim.grid.dx + (np.abs(v) / dy).max() * dt)
        self.history.append((sim.t, c))
        if c > self.limit:
            raise FlowDiverged(f"CFL {c:.3g} > {self.limit} at t={sim.t:.6g} (step {sim.n_steps})")


def max_divergence(sim: Simulation) -> float:
    """max |D u| over the cells of the current state (uses the solver's rhs scratch array)."""
    g = GHOST
    sim.L.rows(_k.divergence, sim.grid.ny, 0, [sim.u, sim.v, sim.hy_c, sim.grid.dx, 1.0, g, sim.grid.nx,
                                              ROW0, sim.rhs])
    return float(np.abs(sim.rhs.numpy()).max())


class DivergenceMonitor:
    """Records max |div u| (scaled by h / U_ref it is the relative mass error per cell)."""

    def __init__(self, every: int = 50):
        self.every, self.history = every, []

    def __call__(self, sim: Simulation):
        if sim.n_steps % self.every == 0:
            self.history.append((sim.t, max_divergence(sim)))


class NaNMonitor:
    """Stops the run on a non-finite velocity: restores the last good state (checked every
    ``every`` steps, copies kept on the host) and raises ``FlowDiverged`` with where and when."""

    def __init__(self, every: int = 20):
        self.every = every
        self.good = None

    def __call__(self, sim: Simulation):
        if sim.n_steps % self.every:
            return
        arrays = {name: getattr(sim, name).numpy() for name in ("u", "v", "p")}
        bad = [name for name, a in arrays.items() if not np.isfinite(a).all()]
        if not bad:
            self.good = (sim.t, sim.n_steps, {k: a.copy() for k, a in arrays.items()})
            return
        where = np.argwhere(~np.isfinite(arrays[bad[0]]))[0]
        msg = (f"non-finite {bad} at t={sim.t:.6g} (step {sim.n_steps}), first at storage index "
               f"{tuple(int(w) for w in where)}")
        if self.good is not None:
            t, n, saved = self.good
            for k, a in saved.items():
                getattr(sim, k).assign(a)
            sim.t, sim.n_steps = t, n
            msg += f"; state restored to the last good one at t={t:.6g} (step {n})"
        raise FlowDiverged(msg)


def run(sim: Simulation, t_end: float, monitors=(), max_steps: int | None = None,
        land_exactly: bool = False) -> Simulation:
    """Advance ``sim`` until t >= ``t_end``, calling the monitors after every step.

    With ``land_exactly`` the last step is shortened to end on t_end; off by default because a
    sudden change of dt shows up as a one-step blip in the direct-forcing force history.
    """
    n = 0
    while sim.t < t_end - 1e-12 * max(1.0, abs(t_end)):
        dt = sim.stable_dt()
        if land_exactly:
            dt = min(dt, t_end - sim.t)
        sim.step(dt)
        n += 1
        for m in monitors:
            m(sim)
        if max_steps is not None and n >= max_steps:
            break
    if not math.isfinite(sim.t):
        raise FlowDiverged("time became non-finite")
    return sim
