"""Checks of the body-fitted grid (bridge/cfd/curvilinear.py, bridge/cfd/body_fitted.py) against closed forms
and published benchmarks.

    python tools/validate_body_fitted.py couette            # order of accuracy: velocity and torque, 3 grids
    python tools/validate_body_fitted.py cylinder --re 40   # O-grid alone in a uniform stream: C_D
    python tools/validate_body_fitted.py dfg --background 32 --around 128 --first 0.002 --t-end 5
                                                            # DFG 2D-1: O-grid over the Cartesian channel
    python tools/validate_body_fitted.py dfg2 --background 32 --t-end 8 --window 2
                                                            # DFG 2D-2: periodic shedding at Re 100

* couette: circular Couette flow between a rotating inner cylinder (radius 1, in its own rotating frame) and a
  fixed outer one (radius 2), nu = 1: u_theta = A r + B / r, torque -4 pi nu Omega R1^2 R2^2 / (R2^2 - R1^2)
  (Batchelor 1967, 4.5).  The observed order of the velocity (max norm) and of the torque.
* cylinder: the O-grid alone, its outer boundary at ``--outer`` diameters in a uniform stream; Re 40 C_D
  1.50-1.58 (Tritton 1959; Dennis and Chang 1970; Fornberg 1980).
* dfg: the DFG benchmark 2D-1 (Schaefer and Turek 1996: channel 2.2 x 0.41, D = 0.1 at (0.2, 0.2), parabolic
  inflow U_max 0.3, nu 1e-3, Re 20): c_D 5.57-5.59, c_L 0.0104-0.0110; the cylinder's O-grid over a uniform
  background of D / ``--background``.
* dfg2: DFG 2D-2 (U_max 1.5, Re 100, periodic shedding): c_D,max 3.22-3.24, c_L,max 0.99-1.01 and the
  Strouhal number f D / U_mean 0.295-0.305 over the last ``--window`` time units.
Each prints its rows and writes them to ``--out`` (JSON).  Progress goes to stderr.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.cfd import (  # noqa: E402
    BoundaryConditions,
    CartesianGrid,
    FlowConfig,
    PrescribedMotion,
    ProgressNote,
    Stationary,
    run,
)
from bridge.cfd.advection import SCHEMES  # noqa: E402
from bridge.cfd.body_fitted import BodyFittedPair  # noqa: E402
from bridge.cfd.curvilinear import CurvilinearFlow, CurvilinearGrid, Farfield, polar_grid  # noqa: E402

BANDS = {"cylinder40": (1.50, 1.58), "dfg_cd": (5.57, 5.59), "dfg_dp": (0.1172, 0.1176), "dfg_cl": (0.0104, 0.0110),
         "dfg2_cd": (3.22, 3.24),
         "dfg2_cl": (0.99, 1.01), "dfg2_st": (0.295, 0.305)}


class _CouetteOuter:
    """The outer cylinder held at the exact solution (no flux through it)."""

    def __init__(self, exact):
        self.exact = exact

    def attach(self, flow):
        self.flow = flow

    def ghost_velocity(self, t):
        return self.exact(self.flow.grid.xg, self.flow.grid.yg)

    def outer_fluxes(self, t):
        return np.zeros(self.flow.grid.ni)


def couette(sizes=(32, 64, 128), t_end=3.0) -> dict:
    r1, r2, om, nu = 1.0, 2.0, 1.0, 1.0
    a, b = -om * r1 ** 2 / (r2 ** 2 - r1 ** 2), om * r1 ** 2 * r2 ** 2 / (r2 ** 2 - r1 ** 2)
    torque = -4 * math.pi * nu * om * r1 ** 2 * r2 ** 2 / (r2 ** 2 - r1 ** 2)

    def exact(x, y):
        r = np.hypot(x, y)
        ut = a * r + b / r
        return -ut * y / r, ut * x / r

    rows = []
    for ni in sizes:
        x, y = polar_grid(r1, r2, ni, (r2 - r1) / (ni // 4), 1.0)
        motion = PrescribedMotion(lambda t: (0.0, 0.0, om * t), lambda t: (0.0, 0.0, om))
        flow = CurvilinearFlow(CurvilinearGrid(x, y), nu, motion, _CouetteOuter(exact))
        flow.set_uniform_flow(0.0)
        t0 = time.perf_counter()
        run(flow, t_end)
        ue, ve = exact(flow.grid.xc, flow.grid.yc)
        err = float(max(np.abs(flow.u - ue).max(), np.abs(flow.v - ve).max()))
        rows.append({"around": ni, "rings": flow.grid.nj, "steps": flow.n_steps, "wall_s": time.perf_counter() - t0,
                     "velocity_error": err, "torque": float(flow.total_force[2]), "torque_exact": torque,
                     "torque_error": float(flow.total_force[2] / torque - 1)})
    for fine, coarse in zip(rows[1:], rows[:-1], strict=True):
        fine["velocity_order"] = math.log2(coarse["velocity_error"] / fine["velocity_error"])
        fine["torque_order"] = math.log2(abs(coarse["torque_error"] / fine["torque_error"]))
    return {"case": "couette", "rows": rows}


def cylinder(re=40.0, around=128, first=0.01, growth=1.08, outer=20.0, t_end=60.0, cfl=0.5) -> dict:
    x, y = polar_grid(0.5, outer, around, first, growth)
    flow = CurvilinearFlow(CurvilinearGrid(x, y), 1.0 / re, Stationary(), Farfield(1.0, 0.0), cfl=cfl)
    flow.set_uniform_flow(1.0)
    t0 = time.perf_counter()
    run(flow, t_end, [ProgressNote(f"cylinder Re {re:g}", t_end)])
    cd = 2 * float(flow.total_force[0])
    return {"case": "cylinder", "re": re, "around": around, "rings": flow.grid.nj, "first": first, "growth": growth,
            "outer_radius_D": outer, "t_end": t_end, "steps": flow.n_steps, "wall_s": time.perf_counter() - t0,
            "c_D": cd, "band": BANDS["cylinder40"] if re == 40 else None}


def dfg(background=32, around=128, first=0.002, growth=1.1, outer=0.12, t_end=5.0, unsteady=False,
        window=2.0, cfl=0.5, lockstep=False, advection="vanleer") -> dict:
    d, h_ch, length, nu, umax = 0.1, 0.41, 2.2, 1e-3, (1.5 if unsteady else 0.3)

    def profile(y, t):
        return 4 * umax * y * (h_ch - y) / h_ch ** 2

    bc = BoundaryConditions(left="inflow", right="outflow", bottom="noslip", top="noslip", inflow_profile=profile)
    cfg = FlowConfig(nu=nu, advection=advection, cfl=cfl, fourier=0.2, threads=2, bc=bc)
    h = d / background
    grid = CartesianGrid.uniform(int(round(length / h)), int(round(h_ch / h)), (0.0, length), (0.0, h_ch))
    x, y = polar_grid(d / 2, outer, around, first, growth)
    pair = BodyFittedPair(grid, CurvilinearGrid(x, y), cfg, Stationary(0.2, 0.2), subcycle=not lockstep)
    pair.background.set_state(u=np.broadcast_to(profile(grid.y_centres, 0.0)[:, None], (grid.ny, grid.nx + 1)))
    pair.set_initial_body_state()
    t0 = time.perf_counter()
    history = []
    name = "DFG 2D-2" if unsteady else "DFG 2D-1"
    run(pair, t_end, [lambda f: history.append((f.t, *f.total_force[:2])),
                      ProgressNote(f"{name}, background D/{background}, O-grid {around}", t_end)])
    scale = 2 / ((2 * umax / 3) ** 2 * d)
    t, fx, fy = np.array(history).T
    if unsteady:
        sel = t > t[-1] - window
        cl = scale * fy[sel]
        ts = t[sel]
        up = np.nonzero((cl[:-1] < cl.mean()) & (cl[1:] >= cl.mean()))[0]   # upward mean crossings
        crossings = ts[up] + (cl.mean() - cl[up]) / (cl[up + 1] - cl[up]) * (ts[up + 1] - ts[up])
        period = float(np.mean(np.diff(crossings))) if crossings.size > 1 else float("nan")
        return {"case": "DFG 2D-2", "background_per_D": background, "advection": advection, "around": around,
                "rings": pair.body.grid.nj,
                "first": first, "growth": growth, "outer_radius": outer, "cells": pair.n_cells, "t_end": t_end,
                "window": window, "steps": pair.n_steps, "subcycle": pair.subcycle, "wall_s": time.perf_counter() - t0,
                "c_D_max": float(scale * fx[sel].max()), "c_L_max": float(cl.max()), "c_L_min": float(cl.min()),
                "St": d / (period * 2 * umax / 3), "periods_in_window": int(max(crossings.size - 1, 0)),
                "band_c_D_max": BANDS["dfg2_cd"], "band_c_L_max": BANDS["dfg2_cl"], "band_St": BANDS["dfg2_st"]}
    last = t > t[-1] - 0.5
    # the pressure difference between the cylinder's front and back points (x = 0.15 and 0.25 on y = 0.2): the
    # wall pressure, linear in the angle between the wall faces' midpoints
    xm = pair.body.grid.xmj[0]
    ang = np.arctan2(xm[:, 1], xm[:, 0])
    p_back, p_front = np.interp([0.0, math.pi], ang, pair.body.wall_pressure(), period=2 * math.pi)
    dp = float(p_front - p_back)
    return {"case": "DFG 2D-1", "background_per_D": background, "advection": advection, "around": around,
            "rings": pair.body.grid.nj,
            "first": first, "growth": growth, "outer_radius": outer, "cells": pair.n_cells, "t_end": t_end,
            "steps": pair.n_steps, "subcycle": pair.subcycle, "wall_s": time.perf_counter() - t0,
            "c_D": float(scale * fx[-1]),
            "c_L": float(scale * fy[-1]), "delta_p": dp, "c_D_change_last_0.5": float(scale * np.ptp(fx[last])),
            "band_c_D": BANDS["dfg_cd"], "band_c_L": BANDS["dfg_cl"], "band_delta_p": BANDS["dfg_dp"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", choices=("couette", "cylinder", "dfg", "dfg2"))
    ap.add_argument("--window", type=float, default=2.0, help="dfg2: the time over which the maxima and St are taken")
    ap.add_argument("--re", type=float, default=40.0)
    ap.add_argument("--around", type=int, default=128, help="O-grid nodes around the body")
    ap.add_argument("--first", type=float, default=None, help="first cell height (cylinder: 0.01 D; dfg: 0.002)")
    ap.add_argument("--growth", type=float, default=None, help="layer growth ratio (cylinder 1.08, dfg 1.1)")
    ap.add_argument("--outer", type=float, default=None, help="outer radius (cylinder: 20 D; dfg: 0.12)")
    ap.add_argument("--background", type=int, default=32, help="dfg: background cells per diameter")
    ap.add_argument("--t-end", type=float, default=None)
    ap.add_argument("--cfl", type=float, default=0.5, help="cylinder, dfg, dfg2: Courant number of the step (0.05-0.5)")
    ap.add_argument("--advection", choices=sorted(SCHEMES), default="vanleer",
                    help="dfg, dfg2: the background's advection scheme (the O-grid's is always van Leer's)")
    ap.add_argument("--lockstep", action="store_true",
                    help="dfg, dfg2: both grids at the smaller step (default: the O-grid sub-cycles)")
    ap.add_argument("--out", type=Path, default=Path("out/validate_body_fitted.json"))
    args = ap.parse_args(argv)
    if not 0.05 <= args.cfl <= 0.5:
        ap.error(f"--cfl: {args.cfl} not allowed; allowed: 0.05 .. 0.5")
    if args.case == "couette":
        row = couette(t_end=args.t_end or 3.0)
    elif args.case == "cylinder":
        row = cylinder(args.re, args.around, args.first or 0.01, args.growth or 1.08, args.outer or 20.0,
                       args.t_end or 60.0, cfl=args.cfl)
    else:
        row = dfg(args.background, args.around, args.first or 0.002, args.growth or 1.1, args.outer or 0.12,
                  args.t_end or (8.0 if args.case == "dfg2" else 5.0), unsteady=args.case == "dfg2", window=args.window,
                  cfl=args.cfl, lockstep=args.lockstep, advection=args.advection)
    print(json.dumps(row, indent=1))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(row, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
