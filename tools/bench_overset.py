"""Benchmark of the overset coupling: what it adds to the cost of a cell-step.

    python tools/bench_overset.py                     # background 480 x 160, body grid 160 x 120
    python tools/bench_overset.py --background 960x320 --body 320x240 --repeats 5

Method: a pitching and heaving body grid (a 4 % thick plate as immersed body) over a uniform
background in a stream, 20 warm-up steps, then blocks of ``--steps`` steps, timed alternately:
(a) the coupled pair (``OversetPair.step``: both grids' steps plus the fringe, the hole and the
stream functions), (b) the same two ``Simulation`` objects stepped one after the other with the
coupling hooks taken out (the hole and fringe faces then keep whatever they hold; the flow is not
meant to be right, only the work, and the state is restored after each such block). The overhead
is the median over blocks of (a)/(b) - 1, measured in one run (the machine is shared: ratios, not
absolute times, are comparable across runs).
Issue target: at most 30 %.
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

from bridge.cfd import BoundaryConditions, CartesianGrid, FlowConfig, HarmonicMotion, OversetPair  # noqa: E402
from bridge.cfd.sections import FlatPlate  # noqa: E402


def grid_shape(text: str) -> tuple[int, int]:
    """argparse type of a grid size "NXxNY" (at least 16 x 16)."""
    nx, ny = (int(v) for v in text.lower().split("x"))
    if nx < 16 or ny < 16:
        raise argparse.ArgumentTypeError(f"{text}: need at least 16 x 16 cells")
    return nx, ny


def build(background: tuple[int, int], body: tuple[int, int]) -> OversetPair:
    nx, ny = background
    bg = CartesianGrid.uniform(nx, ny, (-4.0, 8.0), (-2.0, 2.0))
    bx, by = body
    h = 1.6 / bx   # the body grid spans 1.6 x (1.6 by / bx) chords around a unit chord
    grid = CartesianGrid.uniform(bx, by, (-0.8, 0.8), (-0.5 * by * h, 0.5 * by * h))
    plate = FlatPlate(1.0, 0.04).polygon()
    motion = HarmonicMotion(0.0, 0.0, (0.0, 0.02, 0.02), omega=2 * np.pi / 8)
    pair = OversetPair(bg, grid, FlowConfig(nu=1e-3, bc=BoundaryConditions(u_inf=1.0)), motion, polygon=plate,
                       overlap=4)
    pair.set_uniform_flow(1.0)
    return pair


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--background", type=grid_shape, default=(480, 160))
    ap.add_argument("--body", type=grid_shape, default=(160, 120))
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args(argv)
    wp.config.quiet = True
    pair = build(args.background, args.body)
    dt = 0.5 * pair.stable_dt()
    for _ in range(20):
        pair.step(dt)
    hooks = (pair.background.hooks, pair.body.hooks)
    coupled, plain = [], []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        for _ in range(args.steps):
            pair.step(dt)
        coupled.append((time.perf_counter() - t0) / args.steps)
        saved = [list(h) for h in hooks]
        state, t, n = pair.checkpoint_arrays(), pair.t, pair.n_steps
        for h in hooks:
            h.clear()
        t0 = time.perf_counter()
        for _ in range(args.steps):
            pair.background.step(dt)
            pair.body.step(dt)
        plain.append((time.perf_counter() - t0) / args.steps)
        for h, s in zip(hooks, saved, strict=True):
            h.extend(s)
        pair.restore_arrays(state, t, n)   # the uncoupled steps' flow is not meant to be right: undo them
    cells = pair.n_cells
    ratio = float(np.median(np.array(coupled) / np.array(plain)))
    tc, tp = float(np.median(coupled)), float(np.median(plain))
    row = {"background": args.background, "body": args.body, "cells": cells, "coupled_ms_per_step": 1e3 * tc,
           "uncoupled_ms_per_step": 1e3 * tp, "coupled_M_cell_steps_s": cells / tc / 1e6,
           "uncoupled_M_cell_steps_s": cells / tp / 1e6, "overhead": ratio - 1}
    print(f"background {args.background[0]} x {args.background[1]} + body {args.body[0]} x {args.body[1]} "
          f"= {cells} cells")
    for label, sec in (("coupled pair", tc), ("grids uncoupled", tp)):
        print(f"  {label:<17} {1e3 * sec:.2f} ms/step  {cells / sec / 1e6:.2f} M cell-steps/s")
    print(f"  coupling overhead {100 * row['overhead']:.0f} % (median of {args.repeats} block ratios; target <= 30 %)")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(row))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
