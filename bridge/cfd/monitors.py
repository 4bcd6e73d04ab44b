"""Monitors: small objects the time loop (bridge.cfd.flow.run) calls after every step (PyFR-plugin style).

Each monitor has ``__call__(flow)``; ``every`` sets how often it works.  ``ForceHistory``, ``CFLMonitor`` and
``DivergenceMonitor`` read one ``Simulation``; ``NaNMonitor``, ``ProgressNote`` and ``Checkpoint`` work on any
flow (bridge.cfd.flow.Flow).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from kernels import cfd as _k

from .flow import FlowDiverged, run
from .grids import GHOST
from .launch import ROW0
from .time_stepping import Simulation

__all__ = ["ForceHistory", "CFLMonitor", "DivergenceMonitor", "NaNMonitor", "ProgressNote", "Checkpoint", "run",
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
    """Stops the run on a non-finite velocity or pressure in any grid of the flow: restores the last good
    state (checked every ``every`` steps, copies kept on the host) and raises ``FlowDiverged`` with where and
    when."""

    def __init__(self, every: int = 20):
        self.every = every
        self.good = None

    def __call__(self, flow):
        if flow.n_steps % self.every:
            return
        sims = getattr(flow, "simulations", [flow])
        arrays = [{name: getattr(sim, name).numpy() for name in ("u", "v", "p")} for sim in sims]
        bad = [(n, name) for n, a in enumerate(arrays) for name, x in a.items() if not np.isfinite(x).all()]
        if not bad:
            self.good = (flow.t, flow.n_steps, [{k: x.copy() for k, x in a.items()} for a in arrays])
            return
        n, name = bad[0]
        where = np.argwhere(~np.isfinite(arrays[n][name]))[0]
        grid = "" if len(sims) == 1 else f" in grid {n}"
        msg = (f"non-finite {name}{grid} at t={flow.t:.6g} (step {flow.n_steps}), first at storage index "
               f"{tuple(int(w) for w in where)}")
        if self.good is not None:
            t, steps, saved = self.good
            for sim, fields in zip(sims, saved, strict=True):
                for k, x in fields.items():
                    getattr(sim, k).assign(x)
                sim.t, sim.n_steps = t, steps
            flow.t, flow.n_steps = t, steps
            msg += f"; state restored to the last good one at t={t:.6g} (step {steps})"
        raise FlowDiverged(msg)


class Checkpoint:
    """Writes the flow's whole state (``Flow.checkpoint_arrays``, its time and steps) and the columns that
    ``record()`` returns (a force record so far) to the HDF5 file ``path`` every ``every`` steps, atomically
    (a temporary file renamed over the old one), tagged with ``key``: what a checkpoint must match to be
    resumed (the case, the grid, the code).  ``resume(flow)`` loads a matching file into the flow and returns
    its record (None: no file, another key, or unreadable: start afresh); ``save(flow)`` writes now."""

    def __init__(self, path: str | Path, key: str, every: int, record: Callable[[], dict]):
        if every < 1:
            raise ValueError(f"every: must be >= 1, got {every}")
        self.path, self.key, self.every, self.record = Path(path), str(key), int(every), record
        self.path.parent.mkdir(parents=True, exist_ok=True)

    def __call__(self, flow) -> None:
        if flow.n_steps % self.every == 0:
            self.save(flow)

    def save(self, flow) -> None:
        import h5py

        fd, tmp = tempfile.mkstemp(dir=self.path.parent, prefix=f".{self.path.name}.", suffix=".tmp")
        os.close(fd)
        try:
            with h5py.File(tmp, "w") as h5:
                h5.attrs["case_key"] = self.key
                h5.attrs["t"] = flow.t
                h5.attrs["n_steps"] = flow.n_steps
                for name, values in flow.checkpoint_arrays().items():
                    h5.create_dataset(f"state/{name}", data=values)
                for name, values in self.record().items():
                    h5.create_dataset(f"record/{name}", data=np.asarray(values))
            os.replace(tmp, self.path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise

    def resume(self, flow) -> dict | None:
        import h5py

        if not self.path.is_file():
            return None
        try:
            with h5py.File(self.path, "r") as h5:
                if h5.attrs.get("case_key") != self.key:
                    return None
                arrays = {}
                h5["state"].visititems(lambda name, obj: arrays.__setitem__(name, obj[()])
                                       if isinstance(obj, h5py.Dataset) else None)
                flow.restore_arrays(arrays, float(h5.attrs["t"]), int(h5.attrs["n_steps"]))
                return {name: list(h5[f"record/{name}"][()]) for name in h5["record"]}
        except (OSError, KeyError, ValueError):   # unreadable or of another grid: start afresh
            return None
