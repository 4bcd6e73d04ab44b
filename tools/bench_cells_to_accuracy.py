"""Benchmark: the cells, steps and wall time each of the two body grids needs for a given accuracy in DFG 2D-1's
c_D - the Cartesian overset pair (the cylinder immersed in a uniform body grid) against the body-fitted pair
(an O-grid graded from the wall) - each on its own sequence of grids, coarse to fine, run one after the other.

    python tools/bench_cells_to_accuracy.py [--tolerance 0.01] [--only cartesian|body_fitted] [--json FILE]

DFG 2D-1 (Schaefer and Turek 1996): a cylinder of D = 0.1 in a 2.2 x 0.41 channel, Re 20; reference
c_D = 5.57953523384 (the benchmark's reference value).  Each sequence stops at its first grid whose c_D lies
within ``--tolerance`` of it; ``--confirm`` runs the next grid as well, to show that the error stays inside.

* Cartesian pair (tools/validate_cfd.py dfg): body grid D / ppd (+-1 D) over a background of D / (ppd / 2),
  ppd 24, 32, 48, 64 (at 16 the background's cells leave no room for the hole), marched to t = 8.
* Body-fitted pair (tools/validate_body_fitted.py dfg): background D / 8, 16, 32 with 64, 128, 256 nodes round
  the cylinder, first cell D / 25, 50, 100, growth 1.2, 1.095, 1.047 (both grids refined together), to t = 5.

What users feel is the time to the accuracy: the report gives the cells, steps and seconds of the first grid
inside the tolerance, and their ratios.  Times are comparable only within one run (a shared machine).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import validate_body_fitted  # noqa: E402
import validate_cfd  # noqa: E402

from bridge.files import atomic_write_text  # noqa: E402

REFERENCE_C_D = 5.57953523384   # Schaefer and Turek 1996, the reference value of DFG 2D-1

CARTESIAN = [{"ppd": p, "overset": p // 2} for p in (24, 32, 48, 64)]
BODY_FITTED = [{"background": 8, "around": 64, "first": 0.004, "growth": 1.2},
               {"background": 16, "around": 128, "first": 0.002, "growth": 1.095},
               {"background": 32, "around": 256, "first": 0.001, "growth": 1.0466}]


def run_cartesian(grid: dict) -> dict:
    r = validate_cfd.dfg(grid["ppd"], 8.0, 2, "vanleer", overset=grid["overset"])
    return {"grid": f"body grid D/{grid['ppd']}, background D/{grid['overset']}", **_numbers(r)}


def run_body_fitted(grid: dict) -> dict:
    r = validate_body_fitted.dfg(grid["background"], grid["around"], grid["first"], grid["growth"], t_end=5.0)
    return {"grid": f"O-grid {grid['around']} round, first D/{round(0.1 / grid['first'])}, growth {grid['growth']:g}, "
                    f"background D/{grid['background']}", **_numbers(r)}


def _numbers(r: dict) -> dict:
    return {"cells": int(r["cells"]), "steps": int(r["steps"]), "wall_s": float(r["wall_s"]), "c_D": float(r["c_D"]),
            "error": float(r["c_D"] / REFERENCE_C_D - 1)}


def sequence(name: str, grids: list[dict], run, tolerance: float, confirm: bool, say=print) -> dict:
    """Run ``grids`` coarse to fine until one is within ``tolerance`` (and, with ``confirm``, the next)."""
    rows, first_within = [], None
    for grid in grids:
        row = run(grid)
        rows.append(row)
        say(f"{name}: {row['grid']}: {row['cells']} cells, {row['steps']} steps, {row['wall_s']:.0f} s, "
            f"c_D {row['c_D']:.4f} ({100 * row['error']:+.2f} %)")
        if first_within is None and abs(row["error"]) <= tolerance:
            first_within = len(rows) - 1
            if not confirm:
                break
        elif first_within is not None:
            break
    return {"runs": rows, "first_within": first_within}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tolerance", type=float, default=0.01, help="relative error in c_D (default 0.01)")
    ap.add_argument("--only", choices=("cartesian", "body_fitted"), default=None)
    ap.add_argument("--confirm", action="store_true", help="also run the grid after the first within tolerance")
    ap.add_argument("--json", type=Path, default=Path("out/bench_cells_to_accuracy.json"))
    args = ap.parse_args(argv)
    if not 1e-4 <= args.tolerance <= 0.2:
        ap.error(f"--tolerance {args.tolerance}: allowed 0.0001 .. 0.2")
    families = {"cartesian": (CARTESIAN, run_cartesian), "body_fitted": (BODY_FITTED, run_body_fitted)}
    result = {"reference_c_D": REFERENCE_C_D, "tolerance": args.tolerance}
    for name, (grids, run) in families.items():
        if args.only in (None, name):
            result[name] = sequence(name, grids, run, args.tolerance, args.confirm)
    print(f"\n| body grid | first grid within {100 * args.tolerance:g} % | cells | steps | wall s | c_D error |")
    print("|---|---|---|---|---|---|")
    reached = {}
    for name in families:
        if name not in result:
            continue
        k = result[name]["first_within"]
        if k is None:
            print(f"| {name} | none of the grids run | - | - | - | - |")
            continue
        row = reached[name] = result[name]["runs"][k]
        print(f"| {name} | {row['grid']} | {row['cells']} | {row['steps']} | {row['wall_s']:.0f} | "
              f"{100 * row['error']:+.2f} % |")
    if len(reached) == 2:
        c, b = reached["cartesian"], reached["body_fitted"]
        result["ratios_cartesian_over_body_fitted"] = {k: c[k] / b[k] for k in ("cells", "steps", "wall_s")}
        print("\nCartesian / body-fitted: " + ", ".join(f"{k} {v:.2f}" for k, v in
                                                        result["ratios_cartesian_over_body_fitted"].items()))
    args.json.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(args.json, json.dumps(result, indent=2) + "\n")
    print(f"written: {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
