"""Benchmark of the bridge FEM: element-matrix throughput (Warp kernel vs vectorised NumPy), sparse
assembly, eigen solve, and the cold full run (build + assemble + solve, Warp compilation included).

Warp timings exclude compilation (one warm-up call first) and include the host<->device copies of
``bridge.structure.elements.element_matrices`` (the call the model uses); medians of ``--repeats``.
The cold run is a fresh Python process with an empty Warp kernel cache, timed from process start
to the classified modes of Great Belt with the default mesh (target < 30 s on the 2-core machine).

    .venv/bin/python tools/bench_fem.py [--repeats 5] [--tile 10] [--no-cold]

On the shared 2-core machine OpenBLAS's threads slow ARPACK's small dense steps down; compare the
eigen time with OPENBLAS_NUM_THREADS=1 in the environment (docs/performance.md).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def _median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def cold_run() -> None:
    """Body of the cold subprocess: empty kernel cache, full Great Belt analysis."""
    t0 = time.perf_counter()
    import warp as wp

    wp.config.kernel_cache_dir = tempfile.mkdtemp(prefix="warp_cold_")
    wp.config.quiet = True
    from bridge.cable import solve_cables
    from bridge.config import load_scenario
    from bridge.structure import analyse

    s = load_scenario("great_belt")
    r = analyse(s, solve_cables(s))
    total = time.perf_counter() - t0
    print(f"COLD {total:.3f} {r.n_dof} {r.frequency('S-V1'):.5f} " +
          " ".join(f"{k}={v:.3f}" for k, v in r.timings_s.items()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--tile", type=int, default=10, help="copies of the Great Belt element set for throughput")
    ap.add_argument("--cold", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--no-cold", action="store_true", help="skip the cold full run (smoke tests)")
    a = ap.parse_args()
    if a.cold:
        cold_run()
        return

    from bridge.cable import solve_cables
    from bridge.config import load_scenario
    from bridge.structure.analysis import DEFAULT_ELEMENTS_PER_PANEL
    from bridge.structure.assembly import assemble, global_matrices
    from bridge.structure.eigen import lowest_modes
    from bridge.structure.elements import ElementSet, element_matrices, element_matrices_numpy
    from bridge.structure.model import build_model

    s = load_scenario("great_belt")
    c = solve_cables(s)
    model = build_model(s, c, DEFAULT_ELEMENTS_PER_PANEL)
    es = model.elements
    big = ElementSet(*(np.tile(x, (a.tile, 1)) for x in (es.xa, es.xb, es.orient, es.props)))
    element_matrices(es)  # warm-up: compile or load the kernel module
    print("## FEM assembly and eigen solve\n")
    print(f"Great Belt, {DEFAULT_ELEMENTS_PER_PANEL} elements per hanger panel: {len(es)} elements, "
          f"{assemble(model).n_dof} DOFs.  Medians of {a.repeats} runs; Warp on the CPU device, float64.\n")
    print("| step | elements | time [ms] | elements/s |")
    print("|---|---|---|---|")
    for label, elements in (("GB model", es), (f"GB x{a.tile}", big)):
        tw = _median_time(lambda elements=elements: element_matrices(elements), a.repeats)
        tn = _median_time(lambda elements=elements: element_matrices_numpy(elements), a.repeats)
        print(f"| element matrices K, M, K_G, Warp kernel ({label}) | {len(elements)} | {1e3 * tw:.2f} | "
              f"{len(elements) / tw:.3g} |")
        print(f"| element matrices K, M, K_G, vectorised NumPy ({label}) | {len(elements)} | {1e3 * tn:.2f} | "
              f"{len(elements) / tn:.3g} |")
    tg = _median_time(lambda: global_matrices(model.conn, es, model.n_nodes), a.repeats)
    print(f"| Warp element matrices + COO -> CSR (3 matrices) | {len(es)} | {1e3 * tg:.2f} | {len(es) / tg:.3g} |")
    ta = _median_time(lambda: assemble(model), a.repeats)
    print(f"| full assembly incl. constraint reduction T^T K T | {len(es)} | {1e3 * ta:.2f} | {len(es) / ta:.3g} |")
    asm = assemble(model)
    te = _median_time(lambda: lowest_modes(asm.stiffness_reduced, asm.mass_reduced, 40), max(3, a.repeats // 2))
    print(f"| eigen solve, 40 modes (splu + eigsh shift-invert) | {asm.n_dof} DOFs | {1e3 * te:.1f} | - |")
    if a.no_cold:
        return
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    t = time.perf_counter()
    out = subprocess.run([sys.executable, __file__, "--cold"], capture_output=True, text=True, env=env, cwd=ROOT)
    wall = time.perf_counter() - t
    line = next((ln for ln in out.stdout.splitlines() if ln.startswith("COLD")), None)
    if line is None:
        print(out.stdout, out.stderr)
        raise SystemExit("cold run failed")
    parts = line.split()
    print(f"\nCold full run (fresh process, empty Warp kernel cache, imports + cable statics + model + "
          f"compile + assembly + 40 modes + classification): {float(parts[1]):.2f} s inside the process, "
          f"{wall:.2f} s including interpreter start; steps: {' '.join(parts[4:])} (target < 30 s).")


if __name__ == "__main__":
    main()
