"""Benchmark: the cost per cell-step of the body-fitted O-grid's step (bridge/cfd/curvilinear.py) against the
Cartesian grid's (bridge/cfd/time_stepping.py), both a cylinder in a uniform stream at Re 100, measured one
after the other in one run.

    python tools/bench_body_fitted.py [--around 256] [--steps 200] [--repeats 3] [--json out/bench_body_fitted.json]

The O-grid: ``--around`` nodes round a cylinder of diameter 1, first cell 0.005, growth 1.05, outer boundary at
10 diameters.  The Cartesian grid: the same number of cells, uniform, a 2:1 box with the cylinder immersed,
two threads.  Each is stepped ``--steps`` times per repeat after 20 warm-up steps; the median per step is
reported as microseconds per cell-step, with the ratio.
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

from bridge.cfd import BoundaryConditions, CartesianGrid, FlowConfig, Simulation, Stationary, circle  # noqa: E402
from bridge.cfd.curvilinear import CurvilinearFlow, CurvilinearGrid, Farfield, polar_grid  # noqa: E402


def _time(step, steps: int, repeats: int) -> float:
    for _ in range(20):
        step()
    per = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(steps):
            step()
        per.append((time.perf_counter() - t0) / steps)
    return float(np.median(per))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--around", type=int, default=256)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args(argv)
    x, y = polar_grid(0.5, 10.0, args.around, 0.005, 1.05)
    o = CurvilinearFlow(CurvilinearGrid(x, y), 0.01, Stationary(), Farfield(1.0, 0.0))
    o.set_uniform_flow(1.0)
    n_o = o.n_cells
    t_o = _time(lambda: o.step(), args.steps, args.repeats)
    ny = int(round(math.sqrt(n_o / 2)))
    grid = CartesianGrid.uniform(2 * ny, ny, (-5.0, 15.0), (-5.0, 5.0))
    sim = Simulation(grid, FlowConfig(nu=0.01, bc=BoundaryConditions(left="inflow", right="outflow", bottom="slip",
                                                                      top="slip")))
    sim.add_body(circle(1.0), Stationary())
    sim.set_state(u=1.0)
    n_c = grid.nx * grid.ny
    t_c = _time(lambda: sim.step(), args.steps, args.repeats)
    row = {"ogrid_cells": n_o, "ogrid_us_per_cell_step": 1e6 * t_o / n_o, "ogrid_ms_per_step": 1e3 * t_o,
           "cartesian_cells": n_c, "cartesian_us_per_cell_step": 1e6 * t_c / n_c, "cartesian_ms_per_step": 1e3 * t_c,
           "ratio": (t_o / n_o) / (t_c / n_c)}
    for name, n, t in (("O-grid", n_o, t_o), ("Cartesian", n_c, t_c)):
        print(f"{name:<9} {n:7d} cells  {1e3 * t:7.2f} ms/step  {1e6 * t / n:.3f} us per cell-step")
    print(f"ratio (O-grid / Cartesian, per cell-step): {row['ratio']:.1f}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(row))
    return 0


if __name__ == "__main__":
    sys.exit(main())
