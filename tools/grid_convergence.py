"""How the flutter derivatives and the flutter speed converge over the grids of three runs of one scenario.

    python -m bridge.scenario great_belt_body_fitted                  # 16 cells per chord (the preset's)
    python -m bridge.scenario my_copy_24.toml my_copy_32.toml         # the same with cells_per_chord = 24, 32
    python tools/grid_convergence.py out/great_belt_body_fitted out/my_copy_24 out/my_copy_32 [--out F.json]

Each argument is a run's output folder (``results.h5`` and ``summary.json``, docs/results.md).  The runs must
differ only in the aero stage's grid (``aero.cells_per_chord``): the same deck, preset, flow model, Reynolds
number, reduced velocities and bridge.  Printed, and written to ``--out`` (default
``out/grid_convergence/<first run's name>.json``):

* each flutter derivative at each reduced velocity on every grid, its change between the two finest grids
  and, with three grids, its observed order; whether H2* and H4* keep their signs across the grids;
* the flutter speed of every grid (the governing pair's, and each pair's that flutters on every grid) and,
  with three grids, Roache's grid convergence index with Celik et al.'s observed order for unequal refinement
  ratios (:func:`bridge.aero.accuracy.three_grids`): the order, the extrapolated V_c, the finest grid's
  index and how far the coarsest grid's V_c lies from the extrapolation; for a sequence that oscillates or
  does not converge, no order, only how far apart the three lie.

What it cannot tell: an order from three grids is a measurement of those grids only.  The governing pair may
change between grids; the per-pair speeds show whether it does.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.aero.accuracy import three_grids  # noqa: E402
from bridge.files import atomic_write_text  # noqa: E402
from bridge.results import json_value  # noqa: E402

DERIVATIVES = ("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4")
SIGN_WATCHED = ("H2", "H4")   # small derivatives whose sign the grid may turn (docs/aero.md)
# the summary keys that must agree between the runs (and every fem.frequency_* key: the same bridge's modes):
# only the grid may differ
SAME = ("aero.section", "aero.quality", "aero.reynolds", "aero.turbulence", "aero.sst_walls", "aero.grid",
        "aero.reduced_velocity_min", "aero.reduced_velocity_max", "flutter.aerodynamics_option",
        "scenario.main_span_m")


class BadInput(Exception):
    pass


def read_run(folder: Path) -> dict:
    """The derivatives, reduced velocities, grid and flutter speeds of one run's output folder."""
    h5, js = folder / "results.h5", folder / "summary.json"
    for f in (h5, js):
        if not f.is_file():
            raise BadInput(f"{folder}: no {f.name} (a run's output folder is needed: python -m bridge.scenario "
                           "writes OUT/<name>/)")
    try:
        summary = json.loads(js.read_text())
    except (OSError, ValueError) as err:
        raise BadInput(f"{js}: not a summary this program wrote ({err})") from None
    if not isinstance(summary, dict) or not isinstance(summary.get("aero.cells_per_chord"), (int, float)):
        raise BadInput(f"{folder}: the run has no CFD aero stage (no aero.cells_per_chord in summary.json)")
    try:
        with h5py.File(h5, "r") as f:
            U = f["aero/reduced_velocity"][:]
            deriv = {n: f[f"aero/derivatives/{n}"][:] for n in DERIVATIVES}
    except (OSError, KeyError) as err:
        raise BadInput(f"{h5}: no aero/reduced_velocity or aero/derivatives/H1 ... A4 ({err})") from None
    order = np.argsort(U)
    pairs = {k[len("flutter.pair_"):-len(".critical_speed_m_s")]: v for k, v in summary.items()
             if k.startswith("flutter.pair_") and k.endswith(".critical_speed_m_s") and "lateral" not in k}
    return {"folder": str(folder), "name": summary.get("scenario.name", folder.name),
            "cells": float(summary["aero.cells_per_chord"]), "U": U[order],
            "derivatives": {n: v[order] for n, v in deriv.items()},
            "vc": summary.get("flutter.critical_speed_m_s"), "fc": summary.get("flutter.frequency_hz"),
            "pair": summary.get("flutter.mode_pair"), "pairs": pairs,
            "same": {k: v for k, v in summary.items() if k in SAME or k.startswith("fem.frequency_")}}


def check_runs(runs: list[dict]) -> None:
    cells = [r["cells"] for r in runs]
    if len(set(cells)) != len(cells):
        raise BadInput(f"the runs' grids must differ: cells per chord {cells}")
    first = runs[0]
    for r in runs[1:]:
        for k in sorted(set(first["same"]) | set(r["same"])):
            a, b = first["same"].get(k), r["same"].get(k)
            same = (math.isclose(a, b, rel_tol=1e-9) if isinstance(a, float) and isinstance(b, float) else a == b)
            if not same:
                raise BadInput(f"{r['folder']}: {k} = {b!r}, but {first['folder']} has {a!r}; only the grid "
                               "(aero.cells_per_chord) may differ")
        if r["U"].shape != first["U"].shape or not np.allclose(r["U"], first["U"], rtol=1e-9):
            raise BadInput(f"{r['folder']}: reduced velocities {r['U'].tolist()}, {first['folder']}: "
                           f"{first['U'].tolist()}; the runs must share them")


def _pct(x: float) -> str:
    return f"{100 * x:+.1f} %" if math.isfinite(x) else "-"


def _three(values, cells) -> dict | None:
    """three_grids on finest-first values as a dict (None for fewer than three grids or a value missing)."""
    if len(values) != 3 or any(v is None or not math.isfinite(v) for v in values):
        return None
    g = three_grids(values, cells)
    return {"order": g.order, "extrapolated": g.extrapolated, "gci_fine": g.gci_fine, "monotone": g.monotone,
            "converging": g.converging, "spread": g.spread, "coarsest_off_extrapolated": g.off_extrapolated(2)}


def analyse(runs: list[dict]) -> dict:
    runs = sorted(runs, key=lambda r: -r["cells"])   # finest first
    cells = [r["cells"] for r in runs]
    U = runs[0]["U"]
    table = []
    for n in DERIVATIVES:
        for k, u in enumerate(U):
            vals = [float(r["derivatives"][n][k]) for r in runs]
            change = vals[0] / vals[1] - 1.0 if vals[1] else math.nan   # as docs/aero.md: ratio of the values
            row = {"derivative": n, "reduced_velocity": float(u), "values": vals, "change_finest": change,
                   "signs_kept": bool(all(np.sign(v) == np.sign(vals[0]) for v in vals))}
            three = _three(vals, cells)
            if three is not None:
                row["order"] = three["order"]
            table.append(row)
    vc = {"governing": {"values": [r["vc"] for r in runs], "pairs": [r["pair"] for r in runs],
                        "frequency_hz": [r["fc"] for r in runs]}}
    vc["governing"]["three_grids"] = _three(vc["governing"]["values"], cells)
    per_pair = {}
    for p in runs[0]["pairs"]:
        vals = [r["pairs"].get(p) for r in runs]
        if all(v is not None for v in vals):
            per_pair[p] = {"values": vals, "three_grids": _three(vals, cells)}
    vc["pairs"] = per_pair
    return {"runs": [r["folder"] for r in runs], "cells_per_chord": cells, "reduced_velocities": U.tolist(),
            "derivatives": table, "critical_speed_m_s": vc}


def report(result: dict) -> str:
    cells = result["cells_per_chord"]
    head = " | ".join(f"{c:g}" for c in cells)
    lines = [f"grids (cells per chord, finest first): {head}", "",
             f"| derivative | U/(fB) | {head} | change {cells[1]:g} -> {cells[0]:g} | order |",
             "|---|---|" + "---|" * len(cells) + "---|---|"]
    for row in result["derivatives"]:
        vals = " | ".join(f"{v:.4g}" for v in row["values"])
        order = f"{row['order']:.2f}" if math.isfinite(row.get("order", math.nan)) else "-"
        sign = "" if row["signs_kept"] else " (sign turns)"
        lines.append(f"| {row['derivative']}* | {row['reduced_velocity']:.4g} | {vals} | "
                     f"{_pct(row['change_finest'])}{sign} | {order} |")
    main = ("H1", "H3", "A1", "A2", "A3")
    worst = max((abs(r["change_finest"]), r["derivative"], r["reduced_velocity"]) for r in result["derivatives"]
                if r["derivative"] in main)
    lines += ["", f"H1*, H3*, A1*, A2*, A3*: largest change between the two finest grids {100 * worst[0]:.1f} % "
              f"({worst[1]}* at U/(fB) {worst[2]:.4g})"]
    for n in SIGN_WATCHED:
        turns = [r["reduced_velocity"] for r in result["derivatives"] if r["derivative"] == n and not r["signs_kept"]]
        lines.append(f"{n}*: " + ("keeps its sign on every grid" if not turns else
                                   "turns sign at U/(fB) " + ", ".join(f"{u:.4g}" for u in turns)))
    vc = result["critical_speed_m_s"]
    gov = vc["governing"]
    lines += ["", "V_c [m/s]: " + ", ".join(
        f"{v:.2f} ({p}, {f:.4f} Hz)" if v is not None else "none" for v, p, f in
        zip(gov["values"], gov["pairs"], gov["frequency_hz"], strict=True))]
    for name, entry in [("governing", gov)] + list(vc["pairs"].items()):
        t = entry["three_grids"]
        label = "governing V_c" if name == "governing" else f"pair {name}"
        vals = ", ".join(f"{v:.2f}" for v in entry["values"])
        if t is None:
            lines.append(f"{label}: {vals}")
        elif not math.isfinite(t["order"]):
            why = ("not monotone" if not t["monotone"] else "the changes do not shrink" if not t["converging"]
                   else "a change is zero")
            lines.append(f"{label}: {vals}; no observed order ({why}); the three lie within "
                         f"{100 * t['spread']:.1f} % of the finest")
        else:
            low = " (an order below 0.5: the extrapolation means little)" if t["order"] < 0.5 else ""
            lines.append(f"{label}: {vals}; observed order {t['order']:.2f}{low}, extrapolated "
                         f"{t['extrapolated']:.2f}, GCI of the finest {100 * t['gci_fine']:.1f} %, the coarsest "
                         f"{_pct(t['coarsest_off_extrapolated'])} from the extrapolation")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", type=Path, help="output folders of runs on different grids (2 or 3)")
    ap.add_argument("--out", type=Path, default=None, help="JSON written (default out/grid_convergence/<name>.json)")
    args = ap.parse_args(argv)
    if not 2 <= len(args.runs) <= 3:
        ap.error(f"runs: 2 or 3 output folders, got {len(args.runs)}")
    try:
        runs = [read_run(f) for f in args.runs]
        check_runs(runs)
    except BadInput as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    result = analyse(runs)
    print(report(result))
    out = args.out or Path("out") / "grid_convergence" / f"{runs[0]['name']}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, json.dumps(json_value(result), indent=1, allow_nan=False))
    print(f"written {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
