"""Mesh refinement study of the bridge FEM: elements per hanger panel n = 1, 2, 4, 8, 16.

For each n: DOFs, the first 30 frequencies, the largest relative change of those 30 against the next
refinement, and the Eq 4.34 integrals of (S-V1, S-T1).  The converged choice is the smallest n whose
first 30 frequencies change by less than 0.5 % on the next refinement (the default of
bridge.structure.analysis must be at least that).  Prints a Markdown table (docs/structure.md).

    .venv/bin/python tools/fem_convergence.py [scenario] [--max 16] [--modes 30] [--sensitivity]

``--sensitivity`` adds the support variants discussed in docs/structure.md (same mesh): pylon tops
(cable saddles) held longitudinally, girder free longitudinally at one end, girder free vertically
at the pylons, pylon legs turned by 90 degrees, pylon concrete twice as stiff.  These are diagnostics of which
assumption moves which frequency, not model options.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.cable import solve_cables  # noqa: E402
from bridge.config import load_scenario  # noqa: E402
from bridge.structure import analyse  # noqa: E402

TOLERANCE = 0.005


def study(name: str, n_max: int = 16, n_modes: int = 30) -> list[dict]:
    s = load_scenario(name)
    c = solve_cables(s)
    rows = []
    n = 1
    while n <= n_max:
        t = time.perf_counter()
        r = analyse(s, c, elements_per_panel=n, n_modes=n_modes + 10)
        nan = float("nan")
        pair = next((p for p in r.modes.pair_integrals() if p["symmetry"] == "S"),
                    {"a_jj": nan, "a_kk": nan, "a_jk": nan})
        rows.append({"n": n, "dof": r.n_dof, "f": r.frequencies_hz[:n_modes].copy(),
                     "S-V1": r.frequency("S-V1") if "S-V1" in r.labels else nan,
                     "S-T1": r.frequency("S-T1") if "S-T1" in r.labels else nan, "pair": pair,
                     "time": time.perf_counter() - t})
        n *= 2
    for a, b in zip(rows[:-1], rows[1:], strict=False):
        a["change"] = float(np.max(np.abs(b["f"] / a["f"] - 1.0)))
    return rows


def sensitivity(name: str, n_sub: int = 4) -> list[tuple[str, dict]]:
    """Frequencies of S-V1, SS-V1, S-V2, S-T1, SS-T1 for the support variants of the docstring."""
    import dataclasses

    from bridge.structure.assembly import assemble
    from bridge.structure.eigen import lowest_modes
    from bridge.structure.model import build_model
    from bridge.structure.modes import classify_modes

    s = load_scenario(name)
    c = solve_cables(s)
    m = build_model(s, c, n_sub)
    tops = [int(m.cable_nodes[k, i]) for k in range(2) for i in np.flatnonzero(np.isin(m.girder_z, m.pylon_z_m))]
    ends = (int(m.girder_nodes[0]), int(m.girder_nodes[-1]))
    at_pylons = [int(m.girder_nodes[i]) for i in np.flatnonzero(np.isin(m.girder_z, m.pylon_z_m))]
    variants = {
        "as built (docs/structure.md)": m,
        "cable saddles held longitudinally": dataclasses.replace(m, fixed=m.fixed + tuple((t, 2) for t in tops)),
        "girder held longitudinally at one end only": dataclasses.replace(
            m, fixed=tuple(f for f in m.fixed if not (f[0] == ends[1] and f[1] == 2))),
        "girder free vertically at the pylons": dataclasses.replace(
            m, fixed=tuple(f for f in m.fixed if not (f[0] in at_pylons and f[1] == 1))),
    }
    from bridge.config import BoxSection

    p = s.pylon
    rotated = dataclasses.replace(s, pylon=dataclasses.replace(
        p, lower_leg=BoxSection(p.lower_leg.b_m, p.lower_leg.a_m, p.lower_leg.t_m),
        upper_leg=BoxSection(p.upper_leg.b_m, p.upper_leg.a_m, p.upper_leg.t_m)))
    conc = s.materials[p.material]
    stiffer = dataclasses.replace(s, materials={**s.materials, p.material: dataclasses.replace(
        conc, youngs_modulus_Pa=2.0 * conc.youngs_modulus_Pa)})
    variants["pylon legs turned 90 degrees (side b along the bridge)"] = build_model(rotated, c, n_sub)
    variants["pylon concrete E x 2"] = build_model(stiffer, c, n_sub)
    out = []
    for label, mod in variants.items():
        a = assemble(mod)
        f, v = lowest_modes(a.stiffness_reduced, a.mass_reduced, 40)
        ms = classify_modes(s, f, a.T @ v, a.mass, mod.girder_nodes, mod.girder_z, mod.deck_length_m,
                            mod.mid_span_z_m)
        out.append((label, {lab: float(ms.frequencies_hz[ms.index(lab)]) for lab in
                            ("SS-V1", "S-V1", "S-V2", "S-T1", "SS-T1") if lab in ms.labels}))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario", nargs="?", default="great_belt")
    ap.add_argument("--max", type=int, default=16)
    ap.add_argument("--modes", type=int, default=30)
    ap.add_argument("--sensitivity", action="store_true")
    a = ap.parse_args()
    rows = study(a.scenario, a.max, a.modes)
    print(f"### Refinement study: {a.scenario}, first {a.modes} frequencies\n")
    print("| elements per panel | DOFs | S-V1 [Hz] | S-T1 [Hz] | max change of f_1..f_30 vs next | "
          "a_jj | a_kk | a_jk | time [s] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        ch = f"{100 * r['change']:.3f} %" if "change" in r else "-"
        p = r["pair"]
        print(f"| {r['n']} | {r['dof']} | {r['S-V1']:.5f} | {r['S-T1']:.5f} | {ch} | {p['a_jj']:.4f} | "
              f"{p['a_kk']:.4f} | {p['a_jk']:.4f} | {r['time']:.2f} |")
    ok = [r["n"] for r in rows if r.get("change", 1.0) < TOLERANCE]
    print(f"\nsmallest n with < {100 * TOLERANCE:.1f} % change on refinement: {ok[0] if ok else 'none'}")
    if a.sensitivity:
        labs = ("SS-V1", "S-V1", "S-V2", "S-T1", "SS-T1")
        print(f"\n### Support variants: {a.scenario} [Hz]\n")
        print("| variant | " + " | ".join(labs) + " |")
        print("|---|" + "---|" * len(labs))
        for label, f in sensitivity(a.scenario):
            print(f"| {label} | " + " | ".join(f"{f[k]:.4f}" if k in f else "-" for k in labs) + " |")


if __name__ == "__main__":
    main()
