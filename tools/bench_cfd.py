"""Benchmark of the laminar CFD step: cell-steps per second of the whole step and of each part,
beside the NumPy implementation of the same step and this machine's memory-bandwidth roofline.

    python tools/bench_cfd.py                       # 256x128, 512x256, 1024x512
    python tools/bench_cfd.py --sizes 1024x512 --repeats 7 --json out/bench_cfd.json

Method: compile and 3 warm-up steps excluded; each figure is the median over ``--repeats`` timed
blocks (``--steps`` steps each for the full step; per-part timings use the same state). Warp and
NumPy step blocks alternate, and the speed-up is the median of the per-block ratios. Launches
are synchronous on the CPU; on CUDA the tool synchronises before stopping the clock. The flow:
uniform inflow 1 + a smooth disturbance, convective outflow, slip sides, van Leer advection,
Heun (2 stages), no body (a body adds work only in its bounding box).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import threading
import time
from pathlib import Path

import numpy as np
import warp as wp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bridge.cfd import CartesianGrid, FlowConfig, Simulation  # noqa: E402
from bridge.cfd.grids import GHOST  # noqa: E402
from bridge.cfd.launch import ROW0  # noqa: E402
from bridge.cfd.reference_numpy import NumpyFlow  # noqa: E402
from kernels import cfd as kc  # noqa: E402

# Bytes moved per cell per STAGE, assuming each array is streamed once (stencil neighbours in cache):
BYTES_PER_CELL_STAGE = {
    "predict_u": 5 * 8,   # read u, v, nu, u0; write u* (the y-fluxes stay in cache; no p in the "full" form)
    "predict_v": 5 * 8,   # read u, v, nu, v0; write v*
    "boundaries": 0,      # O(ny) per call
    "divergence": 3 * 8,  # read u*, v*; write rhs
    "poisson": 10 * 8,    # DCT along x and its inverse (read + write each), Thomas sweeps (r, factor; write r)
    "project": 6 * 8,     # read u*, v*, phi; write u, v, p
}


def _sync(device):
    if not wp.get_device(device).is_cpu:
        wp.synchronize_device(device)


def make_case(nx: int, ny: int, threads: int, device=None, pressure="full"):
    grid = CartesianGrid.uniform(nx, ny, (0.0, 2.0 * nx / ny), (-1.0, 1.0))
    cfg = FlowConfig(nu=1e-3, advection="vanleer", threads=threads, pressure=pressure)
    sim = Simulation(grid, cfg, device=device)
    x, y = np.meshgrid(grid.x_faces, grid.y_centres)
    u = 1.0 + 0.1 * np.sin(3 * x) * np.cos(2 * y)
    xv, yv = np.meshgrid(grid.x_centres, grid.y_faces)
    v = 0.1 * np.cos(2 * xv) * np.sin(np.pi * (yv + 1) / 2)
    sim.set_state(u, v)
    return sim


def _block_time(fn, inner, device):
    _sync(device)
    t0 = time.perf_counter()
    for _ in range(inner):
        fn()
    _sync(device)
    return (time.perf_counter() - t0) / inner


def _median_time(fn, repeats, inner, device):
    return statistics.median(_block_time(fn, inner, device) for _ in range(repeats))


def bench_steps(nx, ny, threads, repeats, steps, numpy_steps, device=None):
    """Whole-step rates of Warp and NumPy, timed in alternating blocks so that both see the same
    machine load (the shared machine's speed drifts by +-15 % over minutes); the speed-up is the
    median of the per-block ratios."""
    sim = make_case(nx, ny, threads, device)
    dt = 0.2 * sim.grid.dx
    for _ in range(3):
        sim.step(dt)  # compile + warm-up
    grid = CartesianGrid.uniform(nx, ny, (0.0, 2.0 * nx / ny), (-1.0, 1.0))
    ref = NumpyFlow(grid, FlowConfig(nu=1e-3, advection="vanleer"))
    start = make_case(nx, ny, 1)
    for name in "uvp":
        getattr(ref, name)[...] = getattr(start, name).numpy()
    ref.step(dt)
    tw, tn = [], []
    for _ in range(repeats):
        tw.append(_block_time(lambda: sim.step(dt), steps, device))
        tn.append(_block_time(lambda: ref.step(dt), numpy_steps, None))
    ratios = [n / w for w, n in zip(tw, tn, strict=True)]
    cells = nx * ny
    return {"warp_step": cells / statistics.median(tw), "numpy_step": cells / statistics.median(tn),
            "speedup": statistics.median(ratios), "speedup_min": min(ratios), "speedup_max": max(ratios)}, sim


def bench_warp(sim, repeats, steps, device=None):
    """Per-part rates (cells per second per call, one stage) on the state of ``sim``."""
    nx, ny = sim.grid.nx, sim.grid.ny
    dt = 0.2 * sim.grid.dx
    cells = nx * ny
    out = {}
    g = GHOST
    L = sim.L
    rhs0 = np.random.default_rng(1).standard_normal((ny, nx))
    rhs0 -= rhs0.mean()
    rhs_buf = sim.rhs.numpy() if sim.L.device.is_cpu else None
    nb = sim.n_blocks
    pred = [sim.hy_c, sim.hy_f, sim.grid.dx, dt, 0.5, 0.5]
    frame = [sim.frame_x, sim.frame_xf, sim.frame_y, sim.frame_yu, sim.frame_omega]
    parts = {
        "predict_u": lambda: L.rows(kc.predict_u, nb, 0, [sim.u, sim.v, sim.p, sim.nu, sim.u, sim.u_star, *pred,
                                                          g + 1, g + nx, g, ny, nb, 0, sim.scheme, ROW0,
                                                          sim.yflux_scratch, *frame], min_split=2),
        "predict_v": lambda: L.rows(kc.predict_v, nb, 0, [sim.u, sim.v, sim.p, sim.nu, sim.v, sim.v_star, *pred,
                                                          g, g + nx, g + 1, ny - 1, nb, 0, sim.scheme, ROW0,
                                                          sim.yflux_scratch, *frame], min_split=2),
        "boundaries": lambda: sim.bc.set_normal_faces(sim.u, sim.u, sim.u_star, sim.t, dt, 0.5, 0.5),
        "divergence": lambda: L.rows(kc.divergence, ny, 0, [sim.u_star, sim.v_star, sim.hy_c, sim.grid.dx,
                                                            1.0, g, nx, ROW0, sim.rhs]),
        # a fresh right-hand side every call (the in-place solve would otherwise re-solve its own output);
        # the copy (~0.3 ns/cell) is included in the figure
        "poisson": lambda: sim.poisson.solve_inplace(np.copyto(rhs_buf, rhs0) or rhs_buf) if sim.L.device.is_cpu
        else sim.rhs.assign(sim.poisson.solve(rhs0)),
        "project": lambda: L.rows(kc.project, ny, 0, [sim.u_star, sim.v_star, sim.rhs, sim.hy_f, sim.grid.dx,
                                                      0.5 * dt, g, nx, ny, 0, ROW0, sim.u_sub, sim.v_sub,
                                                      sim.p]),
        "ghosts": lambda: sim.bc.fill_ghosts(sim.u_sub, sim.v_sub),
    }
    for name, fn in parts.items():
        fn()
        out[name] = cells / _median_time(fn, repeats, steps, device)  # per call (one stage)
    return out


def bandwidth(n_bytes=256 * 2**20, repeats=5):
    """memcpy (numpy copyto, one thread) and STREAM triad a = b + s c on two threads, GB/s.
    Bytes counted: copy 2 N, triad 3 N (write-allocate not counted, as STREAM does)."""
    n = n_bytes // 8
    a, b, c = np.zeros(n), np.ones(n), np.full(n, 2.0)
    copy = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        np.copyto(a, b)
        copy.append(2 * n_bytes / (time.perf_counter() - t0))

    def triad(lo, hi):
        np.multiply(c[lo:hi], 3.0, out=a[lo:hi])
        np.add(a[lo:hi], b[lo:hi], out=a[lo:hi])  # two passes over a: counted below

    tri = []
    for _ in range(repeats):
        ths = [threading.Thread(target=triad, args=(k * n // 2, (k + 1) * n // 2)) for k in range(2)]
        t0 = time.perf_counter()
        for th in ths:
            th.start()
        for th in ths:
            th.join()
        # NumPy triad in two calls moves 5 N (read c, write a; read a, b, write a)
        tri.append(5 * n_bytes / (time.perf_counter() - t0))
    return statistics.median(copy) / 1e9, statistics.median(tri) / 1e9


def _sizes(text: str) -> list[tuple[int, int]]:
    """'NXxNY,NXxNY,...' -> [(nx, ny), ...], each at least 16 x 16."""
    out = []
    for size in text.split(","):
        try:
            nx, ny = (int(s) for s in size.lower().split("x"))
        except ValueError:
            raise argparse.ArgumentTypeError(f"{size!r} not allowed; allowed: NXxNY, e.g. 1024x512") from None
        if nx < 16 or ny < 16:
            raise argparse.ArgumentTypeError(f"{size} not allowed; allowed: NX, NY >= 16")
        out.append((nx, ny))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=_sizes, default="256x128,512x256,1024x512")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=5, help="steps per timed block")
    ap.add_argument("--numpy-steps", type=int, default=2)
    ap.add_argument("--device", default=None)
    ap.add_argument("--json", default=None)
    ap.add_argument("--bandwidth-mb", type=int, default=256, help="array size of the bandwidth test")
    args = ap.parse_args(argv)
    for name in ("threads", "repeats", "steps", "numpy_steps", "bandwidth_mb"):
        if getattr(args, name) < 1:
            ap.error(f"--{name.replace('_', '-')}: {getattr(args, name)} not allowed; allowed: >= 1")
    wp.config.quiet = True
    wp.init()
    copy_bw, triad_bw = bandwidth(args.bandwidth_mb * 2**20)
    bytes_step = 2 * sum(BYTES_PER_CELL_STAGE.values())
    bw = triad_bw * 1e9
    print(f"memory bandwidth: memcpy {copy_bw:.1f} GB/s, 2-thread triad {triad_bw:.1f} GB/s; "
          f"~{bytes_step} B per cell-step -> roofline {bw / bytes_step / 1e6:.1f} M cell-steps/s (triad)")
    results = {"bandwidth_GBs": {"memcpy": copy_bw, "triad_2threads": triad_bw},
               "bytes_per_cell_step": bytes_step, "sizes": {}}
    for nx, ny in args.sizes:
        size = f"{nx}x{ny}"
        st, sim = bench_steps(nx, ny, args.threads, args.repeats, args.steps, args.numpy_steps, args.device)
        w = bench_warp(sim, args.repeats, args.steps, args.device)
        roof = bw / bytes_step
        results["sizes"][size] = {"steps": st, "warp_parts": w, "roofline_step": roof}
        print(f"\n{nx}x{ny} ({nx * ny / 1e6:.3f} M cells), threads={args.threads}")
        print(f"  full step (2 stages)   {st['warp_step'] / 1e6:8.2f} M cell-steps/s   "
              f"NumPy same step {st['numpy_step'] / 1e6:6.3f}  -> speed-up {st['speedup']:5.1f}x "
              f"(blocks {st['speedup_min']:.1f}-{st['speedup_max']:.1f})   "
              f"roofline {roof / 1e6:6.1f} -> {st['warp_step'] / roof:5.1%}")
        for name in ("predict_u", "predict_v", "boundaries", "divergence", "poisson",
                     "project", "ghosts"):
            print(f"  {name:<22} {w[name] / 1e6:8.1f} M cells/s per call  ({1e9 / w[name]:6.2f} ns/cell)")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(results, indent=2))
    return results


if __name__ == "__main__":
    main()
