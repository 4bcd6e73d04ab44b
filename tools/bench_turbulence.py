"""Benchmark: what the k-omega SST model (bridge/cfd/turbulence.py) adds to the cost of a time step.

    python tools/bench_turbulence.py                  # 512 x 256 cells
    python tools/bench_turbulence.py --size 1024x512 --steps 20 --repeats 5
    python tools/bench_turbulence.py --body          # with a pitching and heaving immersed deck
    python tools/bench_turbulence.py --overset       # the aero stage's Great Belt pair (quick), heaving

Method: a channel (inflow, outflow, no-slip walls) in a developing state, a fixed dt; blocks of
``--steps`` steps timed alternately: (a) the laminar step (``Simulation.step``), (b) the same step
followed by ``KOmegaSST.advance`` (the coefficient kernel twice, k and omega over the two stages, their
ghosts). The ratio (b)/(a) is the median over blocks in one run (the machine is shared: ratios, not
absolute times, are comparable across runs). Issue 17's target: at most 2x. ``--body``: a box section
(1 x 0.1, the Great Belt's proportions) heaving and pitching in the middle of the channel, an immersed
body in both (a) and (b); (b) then also pays the model's wall cells and wall function, with the body's
box of exact distances refreshed every step (it moves). ``--overset``: the aero stage's overset pair at 40 cells
per chord on a 2 / 10 / 2 chord domain (docs/performance.md) with the Great Belt deck heaving
(``bridge.aero.forced_motion``; ``--size`` does not apply); (a) the pair's step, (b) the same with
``OversetSST`` (both grids' models and the exchange of k and omega).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import warp as wp  # noqa: E402
from bench_overset import grid_shape  # noqa: E402  (tools/ is on the path: the script's own folder)

from bridge.cfd import LAMINAR, BoundaryConditions, CartesianGrid, FlowConfig, Simulation  # noqa: E402
from bridge.cfd.turbulence import KOmegaSST, freestream_turbulence  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=grid_shape, default=(512, 256))
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--body", action="store_true", help="an immersed section moving in the channel")
    ap.add_argument("--overset", action="store_true", help="the Great Belt deck heaving on the 40-cell overset pair")
    args = ap.parse_args(argv)
    wp.config.quiet = True
    if args.overset:
        return _overset(args)
    nx, ny = args.size
    nu = 1e-4
    grid = CartesianGrid.uniform(nx, ny, (0.0, 4.0), (0.0, 2.0))
    sim = Simulation(grid, FlowConfig(nu=nu, bc=BoundaryConditions(left="inflow", right="outflow", bottom="noslip",
                                                                   top="noslip")))
    if args.body:
        from bridge.cfd import HarmonicMotion, box_deck

        sim.add_body(box_deck(1.0, 0.1), HarmonicMotion(2.0, 1.0, (0.0, 0.02, 0.02), 0.8))
    sim.set_state(u=1.0)
    model = KOmegaSST(sim, *freestream_turbulence(1.0, nu, 0.05, 10.0))   # the simulation owns and advances it
    dt = 0.5 * sim.stable_dt()
    for _ in range(20):
        sim.step(dt)
    flow, both = [], []
    for _ in range(args.repeats):
        sim.use_turbulence(LAMINAR)   # the same flow with its model set aside
        t0 = time.perf_counter()
        for _ in range(args.steps):
            sim.step(dt)
        flow.append((time.perf_counter() - t0) / args.steps)
        sim.use_turbulence(model)
        t0 = time.perf_counter()
        for _ in range(args.steps):
            sim.step(dt)
        both.append((time.perf_counter() - t0) / args.steps)
    cells = nx * ny
    ratio = float(np.median(np.array(both) / np.array(flow)))
    tf, tb = float(np.median(flow)), float(np.median(both))
    row = {"size": [nx, ny], "cells": cells, "body": args.body, "laminar_ms_per_step": 1e3 * tf,
           "sst_ms_per_step": 1e3 * tb,
           "laminar_M_cell_steps_s": cells / tf / 1e6, "sst_M_cell_steps_s": cells / tb / 1e6, "ratio": ratio,
           "finite": bool(np.isfinite(model.nu_t()).all())}
    print(f"{nx} x {ny} = {cells} cells" + (", a moving immersed section" if args.body else ""))
    for label, sec in (("laminar step", tf), ("step + SST", tb)):
        print(f"  {label:<13} {1e3 * sec:.2f} ms/step  {cells / sec / 1e6:.2f} M cell-steps/s")
    print(f"  SST cost factor {ratio:.2f} (median of {args.repeats} block ratios; target <= 2)")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(row))
    return 0


def _overset(args) -> int:
    """Blocks of the pair's step without and with its SST model (module doc)."""
    from bridge.aero.forced_motion import ForcedCase
    from bridge.aero.presets import SHORT_DOMAIN_40, build_flow, section_polygons
    from bridge.cfd.sections import great_belt_section

    # the pair of docs/performance.md: 40 cells per chord on the short 2 / 10 / 2 chord domain
    q = SHORT_DOMAIN_40.with_(overset=True, turbulence="sst", reynolds=1.05e8)
    pair = build_flow(q, section_polygons(great_belt_section()), ForcedCase.thesis("heave", 0.5))
    model = pair.turbulence
    dt = pair.stable_dt()
    for _ in range(20):
        pair.step(dt)
    flow, both = [], []
    for _ in range(args.repeats):
        pair.use_turbulence(LAMINAR)
        t0 = time.perf_counter()
        for _ in range(args.steps):
            pair.step(dt)
        flow.append((time.perf_counter() - t0) / args.steps)
        pair.use_turbulence(model)
        t0 = time.perf_counter()
        for _ in range(args.steps):
            pair.step(dt)
        both.append((time.perf_counter() - t0) / args.steps)
    cells = pair.n_cells
    ratio = float(np.median(np.array(both) / np.array(flow)))
    tf, tb = float(np.median(flow)), float(np.median(both))
    print(f"{pair.describe()} = {cells} cells, the Great Belt deck heaving (40-cell overset pair)")
    for label, sec in (("pair step", tf), ("step + SST", tb)):
        print(f"  {label:<13} {1e3 * sec:.2f} ms/step  {cells / sec / 1e6:.2f} M cell-steps/s")
    print(f"  SST cost factor {ratio:.2f} (median of {args.repeats} block ratios; target <= 2)")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"overset": True, "cells": cells, "laminar_ms_per_step": 1e3 * tf,
                                         "sst_ms_per_step": 1e3 * tb, "ratio": ratio}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
