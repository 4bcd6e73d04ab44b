"""Forced heave and pitch of a deck section in a uniform wind (thesis 5.2-5.3), resumable.

A case moves the section harmonically in one degree of freedom - heave u(t) = u_0 sin(w t) or pitch
theta(t) = theta_0 sin(w t), or a sum of such sines (multi-frequency excitation) - in a uniform stream
and records the lift, drag and moment per unit length.  The CFD runs in units of the chord and the wind
speed (B = 1, V = 1, rho = 1, nu = 1 / Re): the reduced frequency K = w B / V is then w itself, and
forces come out as coefficients per (rho V^2 B) (moments per rho V^2 B^2).

Frames: the CFD's x runs downwind and y up, rotations counter-clockwise.  The flutter convention
(bridge/flutter/derivatives.py) has lift up, drag downwind and theta, moment NOSE-UP: with the wind
along +x the leading edge is at -x, so nose-up is clockwise, theta = -theta_z and m = -M_z.

Amplitudes follow the thesis (5.3): velocity amplitudes, heave udot_0 = 0.4 m/s and rotation rate
thetadot_0 = 0.028 rad/s at V = 50 m/s, B = 31 m, i.e. udot_0 / V = 0.008 and thetadot_0 B / V =
0.01736 in the CFD's units; the displacement amplitude is that over K.

Checkpoints: every ``checkpoint_every`` steps the whole state (velocity and pressure arrays with their
ghost cells, time, step count) and the force record so far are written to an HDF5 file (atomically); a
case started again with the same file continues from there and ends with the same numbers as an
uninterrupted run (the step is a one-step scheme whose only state is those arrays).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import signal
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from bridge.aero.presets import Quality, build_flow
from bridge.errors import DivergedError, InputError, check_range
from bridge.stages import CFD_KERNELS, code_digest

__all__ = ["ForcedCase", "StaticCase", "ForceRecord", "run_case", "case_key", "checkpoint_path", "whole_periods",
           "fit_window",
           "run_cases", "default_workers", "THESIS_HEAVE_RATE", "THESIS_PITCH_RATE"]

THESIS_HEAVE_RATE = 0.4 / 50.0            # udot_0 / V (thesis 5.3)
THESIS_PITCH_RATE = 0.028 * 31.0 / 50.0   # thetadot_0 B / V (thesis 5.3)


@dataclass(frozen=True)
class ForcedCase:
    """One forced-motion run: ``dof`` "heave" or "pitch", the reduced frequencies K = w B / V of its
    sine(s), their amplitudes (chords for heave, radians nose-up for pitch) and phases (radians);
    ``mean_angle``: the incidence (radians nose-up) the section moves about, in either dof."""

    dof: str
    reduced_frequencies: tuple[float, ...]
    amplitudes: tuple[float, ...]
    phases: tuple[float, ...] = ()
    mean_angle: float = 0.0

    def __post_init__(self):
        if self.dof not in ("heave", "pitch"):
            raise InputError("aero.dof", self.dof, "one of heave, pitch")
        ks, amps = tuple(float(k) for k in self.reduced_frequencies), tuple(float(a) for a in self.amplitudes)
        if not ks or len(ks) != len(amps):
            raise InputError("aero.amplitudes", amps, f"one per reduced frequency ({len(ks)})")
        for k in ks:
            check_range("aero.reduced_frequency", k, 0.0, 20.0, low_open=True)
        phases = tuple(float(p) for p in self.phases) or (0.0,) * len(ks)
        if len(phases) != len(ks):
            raise InputError("aero.phases", phases, f"one per reduced frequency ({len(ks)})")
        object.__setattr__(self, "reduced_frequencies", ks)
        object.__setattr__(self, "amplitudes", amps)
        object.__setattr__(self, "phases", phases)

    @classmethod
    def thesis(cls, dof: str, K: float) -> ForcedCase:
        """A single sine with the thesis's velocity amplitude (module docstring)."""
        rate = THESIS_HEAVE_RATE if dof == "heave" else THESIS_PITCH_RATE
        return cls(dof, (K,), (rate / K,))

    @classmethod
    def multi_frequency(cls, dof: str, Ks: tuple[float, ...], rate: float, mean_angle: float = 0.0) -> ForcedCase:
        """A sum of sines at the reduced frequencies ``Ks`` (whole multiples of the lowest) in one run.

        Each sine gets the velocity amplitude ``rate`` of a single run: the moving immersed boundary's error
        depends on how many cells the body travels, so a sine of a smaller
        amplitude would not measure the same thing as its single run.  The displacement then peaks at no more
        than sum(1/m) times the lowest sine's (2.08 for four harmonics), still a small motion; Schroeder's
        phases (phi_m = -pi m (m - 1) / M for harmonic m of M, IEEE Trans. Inf. Theory 16, 1970) keep the
        sines from peaking together."""
        k0 = min(Ks)
        harmonic = [round(k / k0) for k in Ks]       # the sine's harmonic number m of the lowest frequency
        m_max = max(harmonic)
        phases = tuple(-math.pi * m * (m - 1) / m_max for m in harmonic)
        return cls(dof, Ks, tuple(rate / k for k in Ks), phases, mean_angle)

    @property
    def fundamental(self) -> float:
        """The angular frequency whose period contains whole periods of every sine (their common
        period) - for a single sine the sine's own; for several, the lowest, the others being chosen
        as integer multiples of it (checked)."""
        ks = self.reduced_frequencies
        k0 = min(ks)
        for k in ks:
            if abs(k / k0 - round(k / k0)) > 1e-9:
                raise InputError("aero.reduced_frequencies", ks, "multiples of the lowest, so that whole periods of "
                                 "the lowest hold whole periods of all")
        return k0

    def displacement(self, t: float) -> float:
        return sum(a * math.sin(k * t + p) for k, a, p in zip(self.reduced_frequencies, self.amplitudes,
                                                              self.phases, strict=True))

    def rate(self, t: float) -> float:
        return sum(a * k * math.cos(k * t + p) for k, a, p in zip(self.reduced_frequencies, self.amplitudes,
                                                                  self.phases, strict=True))

    def motion(self):
        """The rigid motion in the CFD frame (pitch nose-up = clockwise = -theta_z)."""
        from bridge.cfd import PrescribedMotion

        a0 = self.mean_angle
        if self.dof == "heave":
            return PrescribedMotion(lambda t: (0.0, self.displacement(t), -a0),
                                    lambda t: (0.0, self.rate(t), 0.0))
        return PrescribedMotion(lambda t: (0.0, 0.0, -a0 - self.displacement(t)),
                                lambda t: (0.0, 0.0, -self.rate(t)))

    def discarded_periods(self, q: Quality) -> int:
        """Periods of the fundamental dropped before the fit: ``q.run.discard_periods``, or more if they last less
        than ``q.run.settle_time``.  The start-up decays in convective time (the shed vorticity of the first
        periods has to travel away), not in periods, so at high K two periods are a short wait; it also
        gives single runs the wait of a multi-frequency run (two periods of its lowest frequency).  A margin,
        not a measured need: on a short grid the periods after 8 B/V already agreed to 0.1 %."""
        T = 2 * math.pi / self.fundamental
        return max(q.run.discard_periods, math.ceil(q.run.settle_time / T - 1e-9))

    def end_time(self, q: Quality) -> float:
        """The dropped periods and then ``q.run.periods - q.run.discard_periods`` periods to fit."""
        return (self.discarded_periods(q) + q.run.periods - q.run.discard_periods) * 2 * math.pi / self.fundamental

    def excursion(self, radius: float) -> float:
        """Largest vertical travel of a point of the body (``radius``: its farthest point from the axis)."""
        tilt = abs(math.sin(self.mean_angle)) * radius
        return sum(abs(a) for a in self.amplitudes) * (1.0 if self.dof == "heave" else radius) + tilt

    def progress(self, t: float, q: Quality) -> str:
        total = self.discarded_periods(q) + q.run.periods - q.run.discard_periods
        return f"{t * self.fundamental / (2 * math.pi):.1f} of {total} periods"


@dataclass(frozen=True)
class StaticCase:
    """The section held still at the angle of attack ``angle_deg`` (degrees, nose-up) in the uniform wind,
    for the preset's ``static_duration``: static coefficients and the wake's shedding frequency."""

    angle_deg: float
    grid_angle_deg: float = 0.0   # the grid is made for angles up to this (one grid for a sweep of angles)
    dof: str = field(default="static", init=False)

    def __post_init__(self):
        check_range("aero.static_angles_deg", self.angle_deg, -30.0, 30.0)
        object.__setattr__(self, "angle_deg", float(self.angle_deg))
        object.__setattr__(self, "grid_angle_deg", max(abs(float(self.grid_angle_deg)), abs(self.angle_deg)))

    def displacement(self, t: float) -> float:
        return math.radians(self.angle_deg)

    def motion(self):
        """Fixed, rotated nose-up (clockwise in the CFD frame) about the reference point."""
        from bridge.cfd import Stationary

        return Stationary(0.0, 0.0, -math.radians(self.angle_deg))

    def end_time(self, q: Quality) -> float:
        return q.run.static_duration

    def excursion(self, radius: float) -> float:
        return math.sin(math.radians(self.grid_angle_deg)) * radius

    def progress(self, t: float, q: Quality) -> str:
        return f"angle {self.angle_deg:g} deg held"


@dataclass
class ForceRecord:
    """Time series of a case in the flutter convention, per unit length, in the CFD's units:
    lift (up) and drag (downwind) per rho V^2 B, moment (nose-up, about the reference point) per
    rho V^2 B^2; ``motion`` the prescribed displacement (chords or radians nose-up)."""

    t: np.ndarray
    lift: np.ndarray
    drag: np.ndarray
    moment: np.ndarray
    motion: np.ndarray
    steps: int = 0
    wall_s: float = 0.0
    resumed_from_step: int = 0
    meta: dict = field(default_factory=dict)
    snapshot: dict | None = None    # the flow at the end of the run (bridge.aero.snapshots.flow_snapshot)


def _polygons(shape) -> list:
    """A Polygon or a list of them (a deck with railings) as a list."""
    return list(shape) if isinstance(shape, (list, tuple)) else [shape]


def case_key(shape, case: ForcedCase, q: Quality) -> str:
    """What a checkpoint must match to be resumed: the geometry, the case, the preset and the source of
    the solver (a changed CFD code never resumes an old run)."""
    blob = json.dumps({"verts": [np.round(p.vertices, 12).tolist() for p in _polygons(shape)], "case": asdict(case),
                       "quality": asdict(q), "code": code_digest(("bridge.cfd", *CFD_KERNELS, "bridge.aero.presets",
                                                                   "bridge.aero.forced_motion"))}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()


def checkpoint_path(runs: Path | None, shape, case, q: Quality) -> Path | None:
    """Where a case keeps its checkpoint in the folder ``runs`` (None: no checkpoint): named by its key."""
    return None if runs is None else Path(runs) / f"{case_key(shape, case, q)[:24]}.h5"


def run_case(shape, case: ForcedCase | StaticCase, quality: Quality, checkpoint: Path | None = None,
             checkpoint_every: int = 2000, threads: int | None = None,
             progress: Callable[[str], None] | None = None, label: str = "",
             observe: Callable[[object], None] | None = None) -> ForceRecord:
    """Run one case - forced motion for :meth:`ForcedCase.end_time` (the caller drops the first
    :meth:`ForcedCase.discarded_periods`, :func:`whole_periods`), or a section held still for
    ``quality.run.static_duration`` - and return the whole force record.  ``shape``: the section's polygon,
    or a list of polygons moving together (a box with railings); the loads are their sum.  Resumes from
    ``checkpoint`` if it holds this case (:func:`case_key`); progress lines about every 10 % of the run.
    ``threads``: CPU threads of the step (default 2, but 1 below 20 000 cells, where waiting for the second thread
    costs more than it saves; the numbers do not depend on it).  A run whose flow stops being finite
    raises DivergedError (exit status 3); a section the preset's grid cannot hold, InputError (2).
    ``observe``: called with the flow after every step (after a resume: every step run here) - for a diagnostic
    that needs the fields, such as the plate's surface pressure of tools/plate_loading.py; on the overset grid
    the flow is a ``bridge.cfd.OversetPair``, whose ``body`` simulation moves with the section."""
    from bridge.cfd import FlowDiverged

    polys = _polygons(shape)
    flow = build_flow(quality, polys, case, threads)
    try:
        return _march(flow, polys, case, quality, checkpoint, checkpoint_every, progress, label, observe)
    except FlowDiverged as err:
        raise DivergedError(f"the CFD of {label or case}", str(err)) from None


def default_workers() -> int:
    """Cases run side by side: two on a machine with two or more cores, one inside a process that is itself
    a worker (a sweep's case, or a case of :func:`run_cases`), so that nothing runs more processes than cores."""
    import multiprocessing

    return 2 if (os.cpu_count() or 1) >= 2 and multiprocessing.parent_process() is None else 1


_PROGRESS = None   # in a case worker: the queue its progress lines go to
_STOPPING = None   # in a case worker: set by the parent on Ctrl-C or a failed case


def _case_worker_start(queue, stopping) -> None:
    """Case workers leave Ctrl-C to the parent, which sets ``stopping`` and forwards it to the running cases
    (run_cases)."""
    global _PROGRESS, _STOPPING
    _PROGRESS, _STOPPING = queue, stopping
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _case_in_worker(shape, case, quality, checkpoint, checkpoint_every, label) -> ForceRecord:
    signal.signal(signal.SIGINT, signal.default_int_handler)   # a forwarded Ctrl-C stops the case cleanly
    try:
        if _STOPPING is not None and _STOPPING.is_set():
            raise KeyboardInterrupt   # handed to this worker before the stop, which cancel() cannot take back
        return run_case(shape, case, quality, checkpoint, checkpoint_every, threads=1,
                        progress=None if _PROGRESS is None else _PROGRESS.put, label=label)
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def _case_on_cluster(shape, case, quality, checkpoint, checkpoint_every, label, progress, stop) -> ForceRecord:
    """A case on a Dask worker (:func:`bridge.cluster.run_on_cluster`): one thread, ``stop`` checked after
    every step; without its checkpoint where the worker cannot write the caller's checkpoint folder."""
    if checkpoint is not None:
        import tempfile

        folder = Path(checkpoint).parent
        try:
            folder.mkdir(parents=True, exist_ok=True)
            fd, probe = tempfile.mkstemp(dir=folder)   # writable, not merely there
            os.close(fd)
            os.unlink(probe)
        except OSError as err:
            progress(f"{label}: no checkpoint on this worker ({err.strerror or err}: {folder})")
            checkpoint = None
    return run_case(shape, case, quality, checkpoint, checkpoint_every, threads=1, progress=progress, label=label,
                    observe=stop)


class RunProgress:
    """The progress lines of several cases, each passed on with the whole run's time left appended.

    Every case's lines start with its label and say how far its simulated time has come (``t = 12.3 of 48``,
    ``resuming at t = 12.3``; :class:`bridge.cfd.ProgressNote`).  The run's time left is the simulated time
    the cases still have to cover, at the rate the running cases show (simulated time per wall second,
    each from its own lines, so a resumed case's head start does not count), times the cases that run at
    once (the workers, or the unfinished cases when fewer are left).  No estimate until a case has shown a
    rate."""

    _T = re.compile(r"^(?P<label>.*?): (?:t = |resuming at t = )(?P<t>[-+0-9.eE]+)")

    def __init__(self, jobs, quality: Quality, workers: int, sink: Callable[[str], None] | None):
        self.t_end = {label: case.end_time(quality) for case, _, label in jobs}
        self.workers, self.sink = max(1, min(workers, len(self.t_end))), sink
        self.t = dict.fromkeys(self.t_end, 0.0)
        self.first: dict[str, tuple[float, float]] = {}   # label -> (wall, t) of its first line here
        self.rate: dict[str, float] = {}
        self.done_rates: list[float] = []

    def finished(self, label: str) -> None:
        self.t[label] = self.t_end[label]
        if label in self.rate:       # running cases set the pace; finished ones until one has shown its own
            self.done_rates.append(self.rate.pop(label))

    def __call__(self, line: str) -> None:
        m = self._T.match(line)
        if m and m["label"] in self.t:
            label, t, now = m["label"], float(m["t"]), time.perf_counter()
            self.t[label] = t
            wall0, t0 = self.first.setdefault(label, (now, t))
            if t > t0 and now > wall0:
                self.rate[label] = (t - t0) / (now - wall0)
            rates = list(self.rate.values()) or self.done_rates
            unfinished = sum(self.t[k] < self.t_end[k] for k in self.t)
            if rates and len(self.t) > 1 and unfinished:
                rate = sum(rates) / len(rates) * min(self.workers, unfinished)   # the cases that can still run at once
                left = sum(max(self.t_end[k] - self.t[k], 0.0) for k in self.t) / rate
                line = f"{line} (all {len(self.t)} cases: about {left:.0f} s left)"
        if self.sink is not None:
            self.sink(line)


def run_cases(shape, jobs, quality: Quality, checkpoint_every: int = 2000,
              progress: Callable[[str], None] | None = None, workers: int | None = None,
              scheduler: str | None = None) -> list[ForceRecord]:
    """:func:`run_case` for every ``(case, checkpoint, label)`` of ``jobs``; the records in the jobs' order.

    With ``workers`` > 1 (default :func:`default_workers`) the cases run side by side in that many
    processes, each on one core: on this project's 2-core machine two cases at once finish sooner than the
    same cases one after the other on two threads each (docs/performance.md, "The whole chain").  Their
    progress lines reach ``progress`` from here.  A case that fails stops the others (each keeps its last
    checkpoint) and its error is raised here; so is Ctrl-C, which the running cases receive too.
    ``scheduler``: the address of a Dask scheduler whose workers run the cases instead, each on one thread
    (:mod:`bridge.cluster`; ``workers`` is then not used)."""
    import multiprocessing
    import queue as queues
    from concurrent.futures import FIRST_EXCEPTION, wait

    from bridge.workers import worker_pool

    if scheduler:
        from bridge.cluster import connect, run_on_cluster, worker_threads

        with connect(scheduler) as client:
            run = RunProgress(jobs, quality, worker_threads(client), progress)
            calls = [(shape, case, quality, ckpt, checkpoint_every, label) for case, ckpt, label in jobs]
            return run_on_cluster(client, _case_on_cluster, calls, progress=run,
                                  finished=lambda i, _: run.finished(jobs[i][2]))
    workers = default_workers() if workers is None else workers
    run = RunProgress(jobs, quality, workers, progress)
    if workers <= 1 or len(jobs) < 2:
        records = []
        for case, ckpt, label in jobs:
            records.append(run_case(shape, case, quality, ckpt, checkpoint_every,
                                    progress=None if progress is None else run, label=label))
            run.finished(label)
        return records

    context = multiprocessing.get_context("spawn")   # fresh processes: no copy of this one's Warp threads
    lines, stopping = context.Queue(), context.Event()

    def drain() -> None:
        while True:
            try:
                line = lines.get_nowait()
            except queues.Empty:
                return
            run(line)

    with worker_pool(min(workers, len(jobs)), context, _case_worker_start, (lines, stopping), stopping) as pool:
        try:
            futures = [pool.submit(_case_in_worker, shape, case, quality, ckpt, checkpoint_every, label)
                       for case, ckpt, label in jobs]
            labels = {f: label for f, (_, _, label) in zip(futures, jobs, strict=True)}
            pending = set(futures)
            while pending:
                done, pending = wait(pending, timeout=0.5, return_when=FIRST_EXCEPTION)
                drain()
                for f in done:
                    f.result()   # a failed case: raise its error now (worker_pool stops the others)
                    run.finished(labels[f])
            drain()
        except BaseException:
            drain()
            raise
    return [f.result() for f in futures]


class _CaseRecord:
    """Monitor: the loads of every step in the flutter convention (lift up, drag downwind, moment nose-up =
    -M_z) and the prescribed displacement; stops the run on non-finite loads."""

    NAMES = ("t", "lift", "drag", "moment", "motion")

    def __init__(self, case, columns: dict | None = None):
        self.case = case
        self.columns = {n: list((columns or {}).get(n, [])) for n in self.NAMES}

    def __call__(self, flow) -> None:
        from bridge.cfd import FlowDiverged

        fx, fy, mz = flow.total_force   # all parts about the same reference point
        if not np.all(np.isfinite((fx, fy, mz))):
            raise FlowDiverged(f"non-finite loads at t = {flow.t:.6g} (step {flow.n_steps})")
        c = self.columns
        c["t"].append(flow.t)
        c["lift"].append(fy)
        c["drag"].append(fx)
        c["moment"].append(-mz)
        c["motion"].append(self.case.displacement(flow.t))


def _march(flow, polys, case, q: Quality, checkpoint, checkpoint_every, progress, label, observe=None) -> ForceRecord:
    """Run ``flow`` to the case's end time with the loop of bridge.cfd (bridge.cfd.flow.run): the record of
    its loads, checkpoints, a check for non-finite fields and progress lines as monitors (run_case)."""
    from bridge.cfd import Checkpoint, NaNMonitor, ProgressNote, run

    record = _CaseRecord(case)
    saver = None
    resumed = 0
    if checkpoint is not None:
        saver = Checkpoint(checkpoint, case_key(polys, case, q), checkpoint_every, lambda: record.columns)
        got = saver.resume(flow)
        if got is not None:
            record = _CaseRecord(case, got)
            resumed = flow.n_steps
            if progress:
                progress(f"{label}: resuming at t = {flow.t:.2f} (step {resumed}) from {checkpoint}")
    t_end = case.end_time(q)
    monitors = [record, NaNMonitor(every=200)]
    if observe is not None:
        monitors.append(observe)
    if saver is not None:
        monitors.append(saver)
    if progress:
        monitors.append(ProgressNote(label, t_end, sink=progress,
                                     detail=lambda f: f"{case.progress(f.t, q)}, {f.describe()}"))
    t0 = time.perf_counter()
    run(flow, t_end, monitors)
    if saver is not None:
        saver.save(flow)
    arrays = {n: np.asarray(v, dtype=np.float64) for n, v in record.columns.items()}
    from bridge.aero.snapshots import body_grid_snapshot, flow_snapshot

    sim = flow.simulations[0]   # the fixed grid (overset: the background, which holds the body grid's flow
    grid = sim.grid             # at its own resolution in the hole)
    pose = case.motion().pose(sim.t)
    snap = flow_snapshot(grid, sim.u.numpy(), sim.v.numpy(), sim.p.numpy(), polys, pose, sim.t)
    body = getattr(flow, "body", None)   # the overset pair's body grid: the section's own detail
    if body is not None and hasattr(body.grid, "dx"):   # a Cartesian body grid (the O-grid has no picture yet)
        snap["body_grid"] = body_grid_snapshot(snap, body.grid, body.u.numpy(), body.v.numpy(), body.p.numpy(),
                                               polys, pose)
    return ForceRecord(**arrays, steps=flow.n_steps, wall_s=time.perf_counter() - t0, resumed_from_step=resumed,
                       meta={"nx": grid.nx, "ny": grid.ny, "cells": flow.n_cells, "grids": flow.describe(),
                             "reynolds": q.physics.reynolds, "quality": q.name, **asdict(case)}, snapshot=snap)


def whole_periods(record: ForceRecord, case: ForcedCase, q: Quality) -> np.ndarray:
    """Boolean mask of the record's samples that the fit uses (:func:`fit_window`)."""
    return fit_window(record.t, case, q)


def fit_window(t: np.ndarray, case: ForcedCase, q: Quality) -> np.ndarray:
    """Boolean mask of the times ``t`` (ascending) after the periods of the fundamental that
    ``case.discarded_periods(q)`` drops, ending on the last whole period."""
    T = 2 * math.pi / case.fundamental
    t = np.asarray(t, dtype=np.float64)
    n_whole = int(math.floor(t[-1] / T + 1e-9))
    # from the last sample at or before the start to the first at or after the end of the last whole period:
    # a window that starts after the first period's start or ends before its last one's end is shorter than
    # its periods, and the fit (periods ending at its last sample) would lose one of them
    first = max(int(np.searchsorted(t, case.discarded_periods(q) * T * (1 + 1e-12), side="right")) - 1, 0)
    last = min(int(np.searchsorted(t, n_whole * T * (1 - 1e-12), side="left")), t.size - 1)
    mask = np.zeros(t.size, dtype=bool)
    mask[first:last + 1] = True
    return mask
