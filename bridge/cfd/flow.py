"""The contract every flow of the CFD keeps, and the one loop that advances a flow.

A *flow* is a solver state that can take a time step: one Cartesian grid (``Simulation``), the overset
pair (``OversetPair``: a body grid moving with the section over a fixed background), and the next grid
type the same way.  It keeps the :class:`Flow` protocol below, so that the time loop (:func:`run`), the
monitors (bridge.cfd.monitors: force records, progress, checkpoints, non-finite checks) and the aero stage
(bridge.aero.presets builds the presets' flows) work on any of them unchanged.

A flow *owns* its turbulence model (:class:`TurbulenceModel`): the model is handed the flow when it is made
(``KOmegaSST(sim, ...)``, ``OversetSST(pair, ...)``), registers itself with it, and the flow advances it
at the end of its own step (:meth:`FlowBase.step`, the only place a model is advanced).  No caller ever
advances a model: a user who builds a flow with SST and runs it gets k and omega that move with the flow.

To add a flow: subclass :class:`FlowBase` (it gives ``step`` and ``stable_dt`` with the model folded in),
implement ``_advance_flow(dt)`` and ``_flow_dt()`` and the rest of :class:`Flow`, and give it a builder in
bridge/aero/presets.py.
"""

from __future__ import annotations

import math
from typing import Protocol, runtime_checkable

import numpy as np

__all__ = ["Flow", "FlowBase", "TurbulenceModel", "Laminar", "LAMINAR", "run"]


class FlowDiverged(RuntimeError):
    """The flow stopped being finite (NaN or inf in the state or the loads, or a non-positive time step)."""


@runtime_checkable
class TurbulenceModel(Protocol):
    """A turbulence model owned by a flow: advanced by the flow after its velocity step, with that step's dt.

    ``name``: "laminar", "sst", ...; ``advance(dt)``: the model's own fields over the step the flow has just
    taken (it hands the flow its nu + nu_t for the next); ``stable_dt()``: the model's own time-step limit
    (infinite if none)."""

    name: str

    def advance(self, dt: float) -> None: ...

    def stable_dt(self) -> float: ...


class Laminar:
    """No turbulence model: the molecular viscosity only."""

    name = "laminar"

    def advance(self, dt: float) -> None:
        return None

    def stable_dt(self) -> float:
        return math.inf


LAMINAR = Laminar()


@runtime_checkable
class Flow(Protocol):
    """What the loop, the monitors and the aero stage use of a flow.

    ``t``, ``n_steps``: the state's time and steps taken; ``turbulence``: the model it owns (``LAMINAR`` if
    none); ``simulations``: its Cartesian solvers (the fixed one first: its fields are what a picture of
    the whole flow shows); ``n_cells``; ``total_force``: (F_x, F_y, M_z) on all its bodies over the last
    step, inertial axes, M_z about the bodies' reference point; ``stable_dt()``; ``step(dt)`` (returns the
    dt taken); ``describe()``: its grids in a few words; ``checkpoint_arrays()`` / ``restore_arrays(arrays,
    t, n_steps)``: everything a resumed run needs to continue bit for bit."""

    t: float
    n_steps: int
    turbulence: TurbulenceModel

    @property
    def simulations(self) -> list: ...

    @property
    def n_cells(self) -> int: ...

    @property
    def total_force(self) -> np.ndarray: ...

    def stable_dt(self) -> float: ...

    def step(self, dt: float | None = None) -> float: ...

    def describe(self) -> str: ...

    def checkpoint_arrays(self) -> dict[str, np.ndarray]: ...

    def restore_arrays(self, arrays: dict[str, np.ndarray], t: float, n_steps: int) -> None: ...


class FlowBase:
    """The step every flow shares: the flow's own step, then its turbulence model's (module doc)."""

    turbulence: TurbulenceModel = LAMINAR

    def use_turbulence(self, model: TurbulenceModel) -> None:
        """Make ``model`` this flow's turbulence model (the model's constructor calls this)."""
        if not isinstance(model, TurbulenceModel):
            raise TypeError(f"turbulence model: needs name, advance(dt) and stable_dt(), got {type(model).__name__}")
        if self.turbulence is not LAMINAR and model is not LAMINAR and model is not self.turbulence:
            raise ValueError(f"this flow already has a turbulence model ({self.turbulence.name}); a flow owns one")
        self.turbulence = model

    def _flow_dt(self) -> float:
        raise NotImplementedError

    def _advance_flow(self, dt: float) -> None:
        raise NotImplementedError

    def stable_dt(self) -> float:
        """The flow's own limit and its turbulence model's, the smaller."""
        dt = self._flow_dt()
        return dt if self.turbulence is LAMINAR else min(dt, self.turbulence.stable_dt())

    def step(self, dt: float | None = None) -> float:
        """Advance the flow by one step of ``dt`` (default :meth:`stable_dt`), then its turbulence model with
        the new velocity; returns the dt taken."""
        dt = self.stable_dt() if dt is None else float(dt)
        self._advance_flow(dt)
        self.turbulence.advance(dt)
        return dt


def run(flow: Flow, t_end: float, monitors=(), max_steps: int | None = None, land_exactly: bool = False) -> Flow:
    """Advance ``flow`` until t >= ``t_end`` at its stable step, calling each monitor (``monitor(flow)``) after
    every step, in order; returns the flow.  Raises :class:`FlowDiverged` when the step stops being finite.

    ``max_steps``: stop after that many steps here even before t_end.  With ``land_exactly`` the last step is
    shortened to end on t_end; off by default because a sudden change of dt shows up as a one-step blip in
    the direct-forcing force history."""
    n = 0
    while flow.t < t_end - 1e-12 * max(1.0, abs(t_end)):
        dt = flow.stable_dt()
        if not (np.isfinite(dt) and dt > 0.0):   # a non-finite velocity makes the limit infinite or NaN
            raise FlowDiverged(f"the time step became {dt!r} at t = {flow.t:.6g} (step {flow.n_steps}): the flow "
                               "is no longer finite")
        if land_exactly:
            dt = min(dt, t_end - flow.t)
        flow.step(dt)
        n += 1
        for m in monitors:
            m(flow)
        if max_steps is not None and n >= max_steps:
            break
    if not math.isfinite(flow.t):
        raise FlowDiverged("time became non-finite")
    return flow
