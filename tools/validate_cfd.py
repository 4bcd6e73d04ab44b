"""Validation of the laminar CFD core against published numbers (docs/reference_cases.md); not in the test run.

    python tools/validate_cfd.py cylinder --re 20 --ppd 20 30 --t-end 40
    python tools/validate_cfd.py cylinder --re 100 --ppd 20 --t-end 150
    python tools/validate_cfd.py dfg --ppd 16 32 64 --t-end 6
    python tools/validate_cfd.py heave --shape circle deck --ppd 16 --re 100 --t-end 60 --window 40

Cylinder (diameter D = 1, U = 1): box x in [-10, 20] D (uniform in x), y in [-15, 15] D stretched
outside |y| < 1.5 D (growth 5 %), uniform inflow, convective outflow, slip sides; blockage
D/H = 1/30 (``--domain UPSTREAM DOWNSTREAM HALF_HEIGHT`` changes the box).
Reported: C_D = 2 F_x/(rho U^2 D) (mean over whole shedding periods when unsteady),
recirculation length L_w/D (last zero of u on the wake centreline, from the rear of the cylinder),
Strouhal number from the zero up-crossings of C_L over the last ``--window`` time units.
DFG 2D-2 (``dfg2``): the same channel with U_max = 1.5 (Re 100, periodic shedding): c_D,max, c_L,max
and St = f D / U_mean over the last ``--window`` (at most half of ``--t-end``), the force series written next
to ``--out`` as dfg2_ppd<N>[_bg<M>].h5 and .png. ``--overset BG_PPD`` (dfg, dfg2, heave): the body in a
body grid of h = D/ppd spanning +-1 D (``bridge.cfd.OversetPair``) over a background of h = D/BG_PPD.
``--save-state FILE`` (dfg2 --overset, one --ppd) keeps the background's flow at the end of the run in HDF5;
``--start-from FILE`` starts a run at that time from that background (the same --overset) with a body
grid of any --ppd set from it as at the start (``OversetPair.set_initial_state``): a finer body grid need
not pay for the approach to the periodic state again, only for its own settling, which ``--window`` must
leave out.
DFG 2D-1 (Schaefer and Turek 1996): channel 2.2 x 0.41, D = 0.1 at (0.2, 0.2), nu = 1e-3, parabolic
inflow U_max = 0.3, no-slip walls; c_D, c_L on U_mean = 0.2; pressure difference between the front
and rear points of the cylinder, each extrapolated along the line y = 0.2 from the nearest cells
without forced faces: dp quadratically from three, dp_linear linearly from two. ``--ppd``: grid
cells per diameter. Heave (a method check of the moving-body force, no reference): a body heaving
with amplitude 0.1 and period 4 (the deck also pitching by 0.05 rad) in a uniform stream U = 1 at
x = y = 0 of a uniform box x in [-4, 12], y in [-4, 4] with slip sides, nu = 1/re; the circle has
D = 1, the deck (``box_deck``) width 2, depth 0.2, fairings 0.2, ``--ppd`` cells per unit length.
Over the last ``--window``: the first harmonic of F_x, F_y, M_z at the motion's frequency
(amplitude, phase against sin), the step-to-step noise (rms second difference, alone and over the std),
and the mean pressure inside the body at the end. Results are appended to ``--out`` as JSON lines.
"""

from __future__ import annotations

import argparse
import io
import json
import sys
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import warp as wp  # noqa: E402

from bridge.cfd import (  # noqa: E402
    BoundaryConditions,
    CartesianGrid,
    FlowConfig,
    ForceHistory,
    HarmonicMotion,
    ImmersedBody,
    NaNMonitor,
    OversetPair,
    ProgressNote,
    Simulation,
    Stationary,
    box_deck,
    circle,
    run,
    stretched_faces,
)
from bridge.cfd.advection import SCHEMES  # noqa: E402
from bridge.cfd.time_stepping import TIME_SCHEMES  # noqa: E402
from bridge.files import atomic_write_bytes  # noqa: E402

BANDS = {  # docs/reference_cases.md
    20: {"C_D": (2.00, 2.09), "L_w/D": (0.91, 0.94)},
    40: {"C_D": (1.50, 1.58), "L_w/D": (2.13, 2.35)},
    100: {"St": (0.160, 0.168), "C_D": (1.33, 1.40)},
    "dfg": {"c_D": (5.57, 5.59), "c_L": (0.0104, 0.0110), "dp": (0.1172, 0.1176)},
    "dfg2": {"c_D_max": (3.22, 3.24), "c_L_max": (0.99, 1.01), "St": (0.295, 0.305)},
}


def _wake_length(sim, x_rear, y_axis):
    """Distance from x_rear to the last point where the centreline u changes sign (0 if none)."""
    g = sim.grid
    u, _, _ = sim.interior()
    yc = g.y_centres
    j = int(np.searchsorted(yc, y_axis))
    w = (y_axis - yc[j - 1]) / (yc[j] - yc[j - 1])
    line = (1 - w) * u[j - 1] + w * u[j]
    x = g.x_faces
    m = x > x_rear
    xs, us = x[m], line[m]
    neg = np.nonzero(us < 0)[0]
    if neg.size == 0:
        return 0.0
    k = neg[-1]
    x0 = xs[k] + (xs[k + 1] - xs[k]) * us[k] / (us[k] - us[k + 1])
    return float(x0 - x_rear)


def _strouhal(t, cl, window):
    sel = t > t[-1] - window
    t, cl = t[sel], cl[sel] - cl[sel].mean()
    up = np.nonzero((cl[:-1] < 0) & (cl[1:] >= 0))[0]
    if up.size < 3:
        return float("nan"), None
    tc = t[up] - cl[up] * (t[up + 1] - t[up]) / (cl[up + 1] - cl[up])
    period = np.diff(tc).mean()
    return float(1.0 / period), (tc[0], tc[-1])


def _period_peaks(t, cl, window):
    """The largest c_L of each whole period of the series (between up-crossings of the last ``window``'s
    mean lift), as (start of the period, peak): how the envelope settles."""
    m = cl - cl[t > t[-1] - window].mean()
    up = np.nonzero((m[:-1] < 0) & (m[1:] >= 0))[0]
    return [(round(float(t[a]), 4), round(float(cl[a:b + 1].max()), 5)) for a, b in zip(up[:-1], up[1:], strict=True)]


def cylinder(re, ppd, t_end, window, threads, scheme, upstream=10.0, downstream=20.0, half_height=15.0,
             ib_order=1):
    h = 1.0 / ppd
    nx = int(round((upstream + downstream) / h))
    grid = CartesianGrid(np.linspace(-upstream, downstream, nx + 1),
                         stretched_faces(-half_height, half_height, (-1.5, 1.5), h, 1.05))
    cfg = FlowConfig(nu=1.0 / re, advection=scheme, cfl=0.5, fourier=0.2, threads=threads,
                     bc=BoundaryConditions(u_inf=1.0))
    sim = Simulation(grid, cfg)
    sim.bodies = [ImmersedBody(circle(1.0), Stationary(0.0, 0.0), grid, sim.L, order=ib_order)]
    sim.set_state(u=1.0)
    if re >= 60:  # trigger shedding: a short asymmetric rotation pulse is cleaner, a tilted start suffices
        sim.set_state(u=1.0, v=0.05 * np.exp(-((grid.x_centres[None, :] - 2) ** 2)) * np.ones((grid.ny + 1, 1)))
    hist, nan = ForceHistory(), NaNMonitor(every=200)
    t0 = time.perf_counter()
    run(sim, t_end, [hist, nan, ProgressNote(f"cylinder Re {re:g}, D/{ppd}", t_end)])
    wall = time.perf_counter() - t0
    t, f = hist.array()
    cd, cl = 2 * f[:, 0, 0], 2 * f[:, 0, 1]
    out = {"case": f"cylinder Re={re:g}", "ppd": ppd, "cells": grid.nx * grid.ny, "nx": grid.nx, "ny": grid.ny,
           "t_end": float(sim.t), "steps": sim.n_steps, "wall_s": wall, "blockage": 0.5 / half_height,
           "domain": [-upstream, downstream, -half_height, half_height],
           "advection": scheme}
    if re < 50:
        last = t > t[-1] - 5
        out["C_D"] = float(cd[-1])
        out["C_D_drift_per_time"] = float(np.polyfit(t[last] - t[-1], cd[last], 1)[0]) if last.sum() > 2 else np.nan
        out["L_w/D"] = _wake_length(sim, 0.5, 0.0)
        # surface pressure at the front and rear stagnation points against the inflow boundary's
        # pressure on the axis (potential-flow offset there ~ 2 (R/x)^2 < 0.01 for x >= 10 D)
        body = lambda x, y: np.hypot(x, y) - 0.5  # noqa: E731
        _, _, p = sim.interior()
        j = int(np.searchsorted(grid.y_centres, 0.0))
        p_inf = 0.5 * (p[j - 1, 0] + p[j, 0])
        out["Cp_front"] = 2 * (_line_pressure(sim, -0.5, -1, 0.0, body) - p_inf)
        out["Cp_rear"] = 2 * (_line_pressure(sim, 0.5, +1, 0.0, body) - p_inf)
    else:
        st, span = _strouhal(t, cl, window)
        out["St"] = st
        if span is not None:
            sel = (t >= span[0]) & (t <= span[1])
            out["C_D"] = float(cd[sel].mean())
            out["C_L_amplitude"] = float(np.abs(cl[sel]).max())
    out["band"] = BANDS.get(re)
    return out


def _line_pressure(sim, x_target, side, y_line, body_phi, points=3):
    """Pressure at (x_target, y_line) extrapolated from the ``points`` nearest cells on one side by
    the polynomial through them (3: quadratic, the default; 2: linear).

    The line lies between two cell rows; a column is used only where neither of its two cells has a
    forced face (``ImmersedBody.forced_cells``: their pressure is shaped by the forcing) and both
    centres lie outside the body. The usable cells then lie 1.5-3.5 h from the wall (DFG, ppd 16),
    over which the pressure near a stagnation point is curved: linear extrapolation leaves an error
    of order h there, quadratic one of order h^2 (docs/validation.md gives both)."""
    g = sim.grid
    _, _, p = sim.interior()
    yc, xc = g.y_centres, g.x_centres
    j = int(np.searchsorted(yc, y_line))
    w = (y_line - yc[j - 1]) / (yc[j] - yc[j - 1])
    line = (1 - w) * p[j - 1] + w * p[j]
    forced = np.zeros_like(p, dtype=bool)
    for body in sim.bodies:
        forced |= body.forced_cells()
    usable = ~(forced[j - 1] | forced[j]) & (body_phi(xc, yc[j - 1]) > 0) & (body_phi(xc, yc[j]) > 0)
    idx = np.nonzero(usable & ((xc < x_target) if side < 0 else (xc > x_target)))[0]
    k = idx[-points:] if side < 0 else idx[:points]
    return float(np.polyval(np.polyfit(xc[k] - x_target, line[k], points - 1), 0.0))


def _march_pair(pair, t_end, label):
    """Step an ``OversetPair`` to t_end like ``run()`` (no shortened last step: a step much shorter
    than the one before spoils that step's forcing impulse, hence its force); (t, force) series.
    A progress line on stderr at every tenth of t_end."""
    t, f = [], []
    note = ProgressNote(f"{label} (overset)", t_end)
    while pair.t < t_end - 1e-12:
        pair.step()
        t.append(pair.t)
        f.append(pair.last_force)
        note(pair)
        if pair.n_steps % 200 == 0 and not np.isfinite(f[-1]).all():
            raise FloatingPointError(f"{label} overset: non-finite force at t = {pair.t}")
    return np.array(t), np.array(f)


class ControlVolumeLift:
    """Lift on a body from the momentum balance of a box of cells around it (a check of the immersed
    boundary's force, which sums the forcing): F_y = -(dM_y/dt + sum over the box's sides of the
    outgoing flux of y-momentum, pressure and viscous stress), on a grid uniform near the box. The box
    is cut along cell faces, ``half`` (a length) around ``centre``; its sides must lie in fluid."""

    def __init__(self, sim, centre, half):
        g = sim.grid
        self.hx, self.hy, self.nu = g.dx, float(g.dy[0]), sim.config.nu
        self.ia, self.ib = (int(round((centre[0] + s * half - g.x_faces[0]) / g.dx)) for s in (-1, 1))
        self.ja, self.jb = (int(np.searchsorted(g.y_faces, centre[1] + s * half)) for s in (-1, 1))
        self.sim, self.m_old, self.f = sim, None, []

    def _momentum(self, v):
        ia, ib, ja, jb = self.ia, self.ib, self.ja, self.jb
        return self.hx * self.hy * (v[ja + 1:jb, ia:ib].sum() + 0.5 * (v[ja, ia:ib].sum() + v[jb, ia:ib].sum()))

    def _flux(self, u, v, p):
        ia, ib, ja, jb, hx, hy, nu = self.ia, self.ib, self.ja, self.jb, self.hx, self.hy, self.nu
        f = 0.0
        for i, sgn in ((ia, -1), (ib, 1)):   # x = const sides: u v - nu (du/dy + dv/dx), rows ja .. jb-1
            vf = 0.25 * (v[ja:jb, i - 1] + v[ja:jb, i] + v[ja + 1:jb + 1, i - 1] + v[ja + 1:jb + 1, i])
            dvdx = 0.5 * ((v[ja:jb, i] - v[ja:jb, i - 1]) + (v[ja + 1:jb + 1, i] - v[ja + 1:jb + 1, i - 1])) / hx
            dudy = (u[ja + 1:jb + 1, i] - u[ja - 1:jb - 1, i]) / (2 * hy)
            f += sgn * hy * np.sum(u[ja:jb, i] * vf - nu * (dudy + dvdx))
        for j, sgn in ((ja, -1), (jb, 1)):   # y = const sides: v v + p - 2 nu dv/dy, columns ia .. ib-1
            pf = 0.5 * (p[j - 1, ia:ib] + p[j, ia:ib])
            dvdy = (v[j + 1, ia:ib] - v[j - 1, ia:ib]) / (2 * hy)
            f += sgn * hx * np.sum(v[j, ia:ib] ** 2 + pf - 2 * nu * dvdy)
        return f

    def __call__(self, sim):
        u, v, p = sim.interior()
        m = self._momentum(v)
        if self.m_old is not None:
            self.f.append(-((m - self.m_old) / sim.last_dt + self._flux(u, v, p)))
        else:
            self.f.append(np.nan)
        self.m_old = m


DFG_D, DFG_H = 0.1, 0.41  # cylinder diameter, channel height


class DfgVariant(NamedTuple):
    """Changes to the DFG channel for a sensitivity study (the defaults are the benchmark's): the channel's
    length (the outflow's distance), its walls ("noslip" or "slip"), the viscosity's factor (Re = 100 /
    nu_scale in 2D-2), the time step's Courant number and scheme, and the walls' first cell as a fraction of
    h (``wall_cell`` < 1: y spacing growing by 10 % from it to h, uniform h in the middle)."""

    channel_length: float = 2.2
    walls: str = "noslip"
    nu_scale: float = 1.0
    cfl: float = 0.5
    time_scheme: str = "heun"
    wall_cell: float = 1.0


def _wall_refined_faces(height, h, first):
    """y faces on [0, height]: ``first`` h at each wall, growing by 10 % up to h, uniform h between."""
    side, step = [0.0], first * h
    while step < h or side[-1] < 3 * h:
        side.append(side[-1] + step)
        step = min(h, 1.1 * step)
    side = np.array(side)
    n_mid = max(1, int(round((height - 2 * side[-1]) / h)))
    mid = np.linspace(side[-1], height - side[-1], n_mid + 1)
    return np.concatenate([side, mid[1:-1], height - side[::-1]])


def dfg_cells_across(ppd):
    """Cells across the DFG channel at h = D/ppd (before any ``ny_shift``)."""
    return int(round(DFG_H / (DFG_D / ppd)))


def dfg(ppd, t_end, threads, scheme, ib_order=1, ny_shift=0, overset=None, body_shift=0.0, unsteady=False,
        window=3.0, series_out=None, body_extent=1.0, cv_lift=False, variant=None, save_state=None,
        start_from=None):
    """DFG 2D-1 on a uniform grid h = D/ppd; ``ny_shift`` adds cells across the channel (dy =
    0.41/(ny + ny_shift), nearly the same resolution, the cylinder cut differently by the grid).
    ``overset`` = background cells per diameter: the cylinder in a body grid of h = D/ppd spanning
    +-``body_extent`` D around it (``bridge.cfd.OversetPair``) over a uniform background of h =
    D/overset, the body grid shifted by ``body_shift`` of its cells in x and y (the cylinder cut
    differently).
    ``unsteady``: DFG 2D-2 (U_max = 1.5, Re 100, periodic shedding): c_D,max, c_L,max and St over the
    last ``window``, the force series written to ``series_out`` (.h5 and .png). ``cv_lift`` (single
    grid): also the lift from a control volume of +-1.5 D (``ControlVolumeLift``). ``variant`` (a
    ``DfgVariant``): the sensitivity changes of ``--channel-length`` and the options after it.
    ``save_state`` / ``start_from`` (overset): a path the background's flow is written to at the end / read
    from at the start (``save_background``, ``load_background``)."""
    v = variant or DfgVariant()
    d, h_ch, length, nu, umax = DFG_D, DFG_H, v.channel_length, 1e-3 * v.nu_scale, (1.5 if unsteady else 0.3)

    def profile(y, t):
        return 4 * umax * y * (h_ch - y) / h_ch ** 2

    bc = BoundaryConditions(left="inflow", right="outflow", bottom=v.walls, top=v.walls, inflow_profile=profile)
    cfg = FlowConfig(nu=nu, advection=scheme, cfl=v.cfl, fourier=0.2, threads=threads, bc=bc,
                     time_scheme=v.time_scheme)
    bg_ppd = overset if overset is not None else ppd
    h = d / bg_ppd
    nx = int(round(length / h))
    ny = dfg_cells_across(bg_ppd) + ny_shift
    grid = CartesianGrid.uniform(nx, ny, (0.0, length), (0.0, h_ch))
    if v.wall_cell < 1.0:
        grid = CartesianGrid(grid.x_faces, _wall_refined_faces(h_ch, h, v.wall_cell))
        ny = grid.ny
    yc = grid.y_centres
    u0 = np.broadcast_to(profile(yc, 0)[:, None], (ny, nx + 1))
    t0 = time.perf_counter()
    if overset is None:
        sim = Simulation(grid, cfg)
        sim.bodies = [ImmersedBody(circle(d), Stationary(0.2, 0.2), grid, sim.L, order=ib_order)]
        sim.set_state(u=u0)
        hist, nan = ForceHistory(), NaNMonitor(every=200)
        monitors = [hist, nan, ProgressNote(f"DFG D/{ppd}", t_end)] \
            + ([ControlVolumeLift(sim, (0.2, 0.2), 1.5 * d)] if cv_lift else [])
        run(sim, t_end, monitors)
        t, f = hist.array()
        f = f[:, 0, :]
        probe, centre, cells, steps, t_start = sim, (0.2, 0.2), nx * ny, sim.n_steps, 0.0
    else:
        sh = body_shift * d / ppd
        n, e = int(round(2 * body_extent * ppd)), body_extent * d
        body_grid = CartesianGrid.uniform(n, n, (-e + sh, e + sh), (-e + sh, e + sh))
        pair = OversetPair(grid, body_grid, cfg, Stationary(0.2, 0.2), polygon=circle(d))
        if start_from is None:
            pair.background.set_state(u=u0)
        else:
            load_background(pair, start_from)
        t_start = pair.background.t
        pair.set_initial_state()
        t, f = _march_pair(pair, t_end, "DFG")
        if save_state is not None:
            save_background(pair, save_state, {"overset_background_ppd": overset, "ppd": ppd,
                                               "variant": json.dumps(v._asdict())})
        probe, centre = pair.body, (0.0, 0.0)
        cells, steps = nx * ny + body_grid.nx * body_grid.ny, pair.n_steps
    wall = time.perf_counter() - t0
    um = 2 * umax / 3
    scale = 2 / (um ** 2 * d)
    last = t > t[-1] - 1.0

    def phi(x, y):
        return np.hypot(x - centre[0], y - centre[1]) - d / 2

    dp, dp_linear = (_line_pressure(probe, centre[0] - d / 2, -1, centre[1], phi, n)
                     - _line_pressure(probe, centre[0] + d / 2, +1, centre[1], phi, n) for n in (3, 2))
    if unsteady:
        cd, cl = scale * f[:, 0], scale * f[:, 1]
        sel = t > t[-1] - window
        st, _ = _strouhal(t, cl, window)
        row = {"case": "DFG 2D-2", "ppd": ppd, "overset_background_ppd": overset, "body_shift": body_shift,
               "body_extent": body_extent if overset else None,
               "cells": cells, "t_end": float(t[-1]), "steps": steps, "wall_s": wall, "window": window,
               "t_start": t_start, "start_from": None if start_from is None else str(start_from),
               "c_D_max": float(cd[sel].max()), "c_L_max": float(cl[sel].max()), "c_L_min": float(cl[sel].min()),
               "St": st * d / um, "variant": v._asdict(), "band": BANDS["dfg2"],
               "c_L_max_per_period": _period_peaks(t, cl, window)}
        if cv_lift and overset is None:
            cl_cv = scale * np.array(monitors[-1].f)
            row.update(c_L_max_cv=float(cl_cv[sel].max()), c_L_min_cv=float(cl_cv[sel].min()),
                       c_L_rms_difference_cv=float(np.sqrt(np.mean((cl_cv[sel] - cl[sel]) ** 2))))
        if series_out is not None:
            _write_series(series_out, t, cd, cl, row)
        return row
    return {"case": "DFG 2D-1", "ppd": ppd, "overset_background_ppd": overset, "body_shift": body_shift,
            "body_extent": body_extent if overset else None,
            "cells": cells, "nx": nx, "ny": ny,
            "t_end": float(t[-1]), "steps": steps, "wall_s": wall, "blockage": d / h_ch, "advection": scheme,
            "ib_order": ib_order, "ny_shift": ny_shift, "variant": v._asdict(), "c_D": float(scale * f[-1, 0]),
            "c_L": float(scale * f[-1, 1]), "dp": dp, "dp_linear": dp_linear,
            "c_D_drift_per_time": float(np.polyfit(t[last] - t[-1], scale * f[last, 0], 1)[0])
            if last.sum() > 2 else np.nan,
            "band": BANDS["dfg"]}


def save_background(pair, path, attrs) -> None:
    """The background's flow state (u, v, p: bridge.cfd.state), its time and ``attrs`` in the HDF5 file
    ``path``, written whole or not at all."""
    import h5py

    buf = io.BytesIO()
    with h5py.File(buf, "w") as fh:
        pair.background.state.save(fh.create_group("background"))   # the state holds the grid's t and n_steps
        for key, value in attrs.items():
            fh.attrs[key] = value
    atomic_write_bytes(Path(path), buf.getvalue())


def saved_background(path) -> dict:
    """The attributes of a file ``save_background`` wrote, with the background's time as ``t``."""
    import h5py

    with h5py.File(path, "r") as fh:
        return {**dict(fh.attrs), "t": float(fh["background"].attrs["t"])}


def load_background(pair, path) -> None:
    """The background's flow and time from ``path`` (``save_background``); ValueError if it does not fit."""
    import h5py

    with h5py.File(path, "r") as fh:
        pair.background.state.load(fh["background"])   # t with it (Simulation.t is the state's)
    pair.background.n_steps = 0   # the restarted run counts its own steps


def _write_series(stem: Path, t, cd, cl, row) -> None:
    """Force series as HDF5 (t, c_D, c_L; the row's numbers as attributes) and a PNG plot."""
    import h5py
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    stem.parent.mkdir(parents=True, exist_ok=True)
    with h5py.File(stem.with_suffix(".h5"), "w") as h5:
        for name, values in (("t", t), ("c_D", cd), ("c_L", cl)):
            h5.create_dataset(name, data=values)
        for k, v in row.items():
            if isinstance(v, (int, float, str)) and v is not None:
                h5.attrs[k] = v
    fig, ax = plt.subplots(2, 1, sharex=True, figsize=(8, 5), layout="constrained")
    ax[0].plot(t, cd)
    ax[0].set_ylabel("c_D")
    ax[1].plot(t, cl)
    ax[1].set_ylabel("c_L")
    ax[1].set_xlabel("t")
    lo, hi = row["band"]["c_L_max"]
    ax[1].axhspan(lo, hi, color="0.85", label="DFG 2D-2 band of c_L,max")
    ax[1].legend(loc="lower left")
    ax[0].set_title(f"DFG 2D-2, body grid D/{row['ppd']}" + (f" over D/{row['overset_background_ppd']}"
                                                            if row["overset_background_ppd"] else " (single grid)"))
    fig.savefig(stem.with_suffix(".png"), dpi=110)
    plt.close(fig)


def heave(shape, ppd, re, t_end, window, threads, scheme, overset=None):
    """Heaving (and, for the deck, pitching) body in a stream: force smoothness and first harmonic.
    ``overset`` = background cells per unit length: the body in a body grid of h = 1/ppd reaching
    ``margin`` beyond it (0.5 or 6 background cells, whichever is more) over the same box at
    h = 1/overset (``bridge.cfd.OversetPair``)."""
    bc = BoundaryConditions(left="inflow", right="outflow", bottom="slip", top="slip")
    cfg = FlowConfig(nu=1.0 / re, advection=scheme, cfl=0.5, threads=threads, bc=bc)
    polygon, pitch = (circle(1.0), 0.0) if shape == "circle" else (box_deck(2.0, 0.2, 0.2), 0.05)
    omega = 2 * np.pi / 4.0
    motion = HarmonicMotion(0.0, 0.0, (0.0, 0.1, pitch), omega)
    bg_ppd = ppd if overset is None else overset
    grid = CartesianGrid.uniform(16 * bg_ppd, 8 * bg_ppd, (-4.0, 12.0), (-4.0, 4.0))
    t0 = time.perf_counter()
    if overset is None:
        sim = Simulation(grid, cfg)
        body = sim.add_body(polygon, motion)
        sim.set_state(u=1.0)
        hist, nan = ForceHistory(), NaNMonitor(every=200)
        run(sim, t_end, [hist, nan, ProgressNote(f"heave {shape}, h = 1/{ppd}", t_end)])
        t, f = hist.array()
        f = f[:, 0, :]
        inside = body.solid_cells()
        p = sim.interior()[2]
        p_inside = float(p[inside].mean()) if inside.any() else None
        cells, steps = grid.nx * grid.ny, sim.n_steps
        t_last = sim.t
    else:
        v = polygon.vertices
        m = max(0.5, 6.0 / overset)
        nbx = int(np.ceil((np.ptp(v[:, 0]) + 2 * m) * ppd))
        nby = int(np.ceil((np.ptp(v[:, 1]) + 2 * m) * ppd))
        body_grid = CartesianGrid.uniform(nbx, nby, (-nbx / (2 * ppd), nbx / (2 * ppd)),
                                          (-nby / (2 * ppd), nby / (2 * ppd)))
        pair = OversetPair(grid, body_grid, cfg, motion, polygon=polygon)
        pair.set_uniform_flow(1.0)
        t, f = _march_pair(pair, t_end, "heave")
        p_inside = None
        cells, steps, t_last = pair.n_cells, pair.n_steps, pair.t
    wall = time.perf_counter() - t0
    sel = t > t[-1] - window
    ts, fs = t[sel], f[sel]
    basis = np.column_stack([np.sin(omega * ts), np.cos(omega * ts), np.ones_like(ts)])
    coef = np.linalg.lstsq(basis, fs, rcond=None)[0]  # F ~ a sin + b cos + c
    d2_rms = np.sqrt(np.mean(np.diff(fs, 2, axis=0) ** 2, axis=0))
    return {"case": "heave", "shape": shape, "ppd": ppd, "overset_background_ppd": overset, "re": re,
            "cells": cells, "t_end": float(t_last), "steps": steps, "cell_steps": cells * steps, "wall_s": wall,
            "first_harmonic_amplitude": np.hypot(coef[0], coef[1]).tolist(),
            "first_harmonic_phase_deg": np.degrees(np.arctan2(coef[1], coef[0])).tolist(),
            "noise_d2_rms": d2_rms.tolist(), "noise_d2_over_std": (d2_rms / fs.std(axis=0)).tolist(),
            "p_inside_mean": p_inside}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", choices=["cylinder", "dfg", "dfg2", "heave"])
    ap.add_argument("--shape", nargs="+", choices=["circle", "deck"], default=["circle"], help="heave: body")
    ap.add_argument("--re", type=float, default=20)
    ap.add_argument("--ppd", type=int, nargs="+", default=[20])
    ap.add_argument("--t-end", type=float, default=40.0)
    ap.add_argument("--window", type=float, default=40.0, help="time window for St and mean C_D")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--domain", type=float, nargs=3, default=[10.0, 20.0, 15.0],
                    metavar=("UPSTREAM", "DOWNSTREAM", "HALF_HEIGHT"), help="cylinder box in D")
    ap.add_argument("--advection", default="vanleer", choices=sorted(SCHEMES))
    ap.add_argument("--ib-order", type=int, choices=[1, 2], default=1,
                    help="interpolation of the forced faces: 1 linear (Fadlun et al.), 2 quadratic")
    ap.add_argument("--ny-shift", type=int, nargs="+", default=[0],
                    help="dfg: extra cells across the channel (same h within a few %%, the cylinder cut "
                         "differently): shows how much of c_L depends on where the grid cuts the body")
    ap.add_argument("--overset", type=int, default=None, metavar="BG_PPD",
                    help="dfg, dfg2, heave: the body in a body grid of h = 1/ppd over a background of h = 1/BG_PPD "
                         "(lengths in D; heave: in units of the circle's D or half the deck's width)")
    ap.add_argument("--body-shift", type=float, nargs="+", default=[0.0],
                    help="dfg --overset: shift of the body grid against the cylinder, in body-grid cells (the "
                         "overset counterpart of --ny-shift)")
    ap.add_argument("--body-extent", type=float, default=1.0, metavar="E",
                    help="dfg, dfg2 --overset: the body grid spans +-E D around the cylinder (default 1)")
    ap.add_argument("--cv-lift", action="store_true",
                    help="dfg2 on the single grid: also the lift from a control-volume momentum balance of +-1.5 D "
                         "(a check of the immersed boundary's force)")
    sens = ap.add_argument_group("dfg, dfg2 sensitivity (what moves the forces; defaults: the benchmark's)")
    sens.add_argument("--channel-length", type=float, default=2.2, help="channel length (the outflow's distance)")
    sens.add_argument("--walls", choices=["noslip", "slip"], default="noslip", help="the channel's walls")
    sens.add_argument("--nu-scale", type=float, default=1.0, help="viscosity factor (Re = 100 / NU_SCALE in dfg2)")
    sens.add_argument("--cfl", type=float, default=0.5, help="Courant number of the time step")
    sens.add_argument("--time-scheme", choices=sorted(TIME_SCHEMES), default="heun")
    sens.add_argument("--wall-cell", type=float, default=1.0,
                      help="the walls' first cell over h (< 1: refined towards the walls, single grid)")
    ap.add_argument("--save-state", type=Path, default=None, metavar="FILE",
                    help="dfg2 --overset, one --ppd: the background's flow at the end, for --start-from (HDF5)")
    ap.add_argument("--start-from", type=Path, default=None, metavar="FILE",
                    help="dfg2 --overset: start at the time and from the background of a --save-state file (the "
                         "same --overset and sensitivity options), the body grid set from it; --window must "
                         "leave out the body grid's settling")
    ap.add_argument("--out", default="out/validation_cfd.jsonl")
    args = ap.parse_args(argv)
    wp.config.quiet = True
    command = "python tools/validate_cfd.py " + " ".join(argv if argv is not None else sys.argv[1:])
    _check_args(ap, args)
    results = []
    for ppd in args.ppd:
        variants = (args.body_shift if args.overset else args.ny_shift) if args.case in ("dfg", "dfg2") \
            else args.shape if args.case == "heave" else [0]
        for variant in variants:
            if args.case == "heave":
                r = heave(variant, ppd, args.re, args.t_end, args.window, args.threads, args.advection,
                          args.overset)
            elif args.case == "cylinder":
                r = cylinder(args.re, ppd, args.t_end, args.window, args.threads, args.advection,
                             *args.domain, ib_order=args.ib_order)
            else:
                stem = Path(args.out).with_name(f"{args.case}_ppd{ppd}" + (f"_bg{args.overset}" if args.overset else "")
                                                + (f"_shift{variant:g}" if variant else "")
                                                + (f"_ext{args.body_extent:g}" if args.body_extent != 1.0 else "")
                                                + ("_restarted" if args.start_from else ""))
                r = dfg(ppd, args.t_end, args.threads, args.advection, args.ib_order,
                        0 if args.overset else variant, args.overset, variant if args.overset else 0.0,
                        unsteady=args.case == "dfg2", window=min(args.window, args.t_end / 2), series_out=stem,
                        body_extent=args.body_extent, cv_lift=args.cv_lift,
                        variant=DfgVariant(args.channel_length, args.walls, args.nu_scale, args.cfl,
                                           args.time_scheme, args.wall_cell),
                        save_state=args.save_state, start_from=args.start_from)
            r["command"] = command
            _emit(r, args.out)
            results.append(r)
    return results


def _check_args(ap, args):
    """Refuse bad input before any run (argparse error: one line naming the option, exit 2)."""
    checks = [("--ppd", args.ppd, min(args.ppd) >= 4, "cells per diameter >= 4 (the body must span cells)"),
              ("--re", args.re, args.re > 0, "> 0"),
              ("--t-end", args.t_end, args.t_end > 0, "> 0"),
              ("--window", args.window, args.window > 0, "> 0"),
              ("--threads", args.threads, args.threads >= 1, ">= 1"),
              ("--channel-length", args.channel_length, 1.0 <= args.channel_length <= 20.0,
               "1 .. 20 (the cylinder sits at x = 0.2)"),
              ("--nu-scale", args.nu_scale, 0.1 <= args.nu_scale <= 10.0, "0.1 .. 10"),
              ("--cfl", args.cfl, 0.0 < args.cfl <= 1.0, "(0, 1]"),
              ("--wall-cell", args.wall_cell,
               0.05 <= args.wall_cell <= 1.0 and (args.wall_cell == 1.0 or args.overset is None),
               "0.05 .. 1, below 1 only on the single grid"),
              ("--body-extent", args.body_extent, 0.75 <= args.body_extent <= 1.6,
               "0.75 .. 1.6 D (the body grid must hold the cylinder and the hole, and its fringe must stay clear "
               "of the channel's wall 2 D from the centre)"),
              ("--domain", args.domain, min(args.domain[:2]) >= 1 and args.domain[2] > 1.5,
               "UPSTREAM, DOWNSTREAM >= 1 D and HALF_HEIGHT > 1.5 D (the refined band is +-1.5 D)")]
    if args.overset is not None:
        checks.append(("--overset", args.overset, args.overset >= 4 and args.case in ("dfg", "dfg2", "heave"),
                       ">= 4 background cells per diameter, with the dfg, dfg2 or heave case"))
    for name, value, ok, allowed in checks:
        if not ok:
            ap.error(f"{name}: {value} not allowed; allowed: {allowed}")
    _check_state_args(ap, args)
    if args.case in ("dfg", "dfg2") and any(dfg_cells_across(ppd) + k < 1 for ppd in args.ppd for k in args.ny_shift):
        ap.error(f"--ny-shift: {args.ny_shift} leaves no cells across the channel")


def _check_state_args(ap, args):
    """--save-state and --start-from: dfg2 on the overset pair; a start file that fits the run."""
    for name, path in (("--save-state", args.save_state), ("--start-from", args.start_from)):
        if path is not None and (args.case != "dfg2" or args.overset is None):
            ap.error(f"{name}: {path} not allowed; only with the dfg2 case and --overset")
    if args.save_state is not None and (len(args.ppd) > 1 or len(args.body_shift) > 1):
        ap.error(f"--save-state: {args.save_state} not allowed with several --ppd or --body-shift (one run, one file)")
    if args.start_from is None:
        return
    try:
        saved = saved_background(args.start_from)
    except (OSError, KeyError) as err:
        ap.error(f"--start-from: {args.start_from} is not a file --save-state wrote ({err})")
    variant = DfgVariant(args.channel_length, args.walls, args.nu_scale, args.cfl, args.time_scheme,
                         args.wall_cell)
    if int(saved.get("overset_background_ppd", -1)) != args.overset:
        ap.error(f"--start-from: {args.start_from} holds a background of D/{saved.get('overset_background_ppd')}; "
                 f"--overset must be the same, not {args.overset}")
    if json.loads(saved.get("variant", "{}")) != json.loads(json.dumps(variant._asdict())):
        ap.error(f"--start-from: {args.start_from} was run with other sensitivity options ({saved.get('variant')})")
    if not args.t_end - saved["t"] > args.window:
        ap.error(f"--t-end: {args.t_end} not allowed; must exceed the start file's time {saved['t']:g} by more than "
                 f"--window {args.window:g} (the body grid's settling left out)")


def _emit(r, out):
    print(json.dumps(r), flush=True)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    with open(out, "a") as fh:
        fh.write(json.dumps(r) + "\n")


if __name__ == "__main__":
    main()
