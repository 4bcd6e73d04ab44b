"""Grid and time-step study of the Great Belt deck with k-omega SST on the overset pair (issue 17; the
thesis asks for the sensitivity of its CFD to the grid).

    python tools/sst_grid_study.py --cells 20 40 80 [--angles 0] [--omega 0.5] [--cfl 0.5]
                                   [--quality quick] [--speed 50] [--threads N] [--out out/sst_grid_study.json]
                                   [--grid body_fitted [--growth G] [--first-height H]]

For each body-grid resolution (cells per chord; the background keeps the preset's coarsening, so it is refined
with the body grid; on ``--grid body_fitted`` the O-grid's nodes around, 2 per cell of a chord, with it, and its
layers as ``--growth`` and ``--first-height`` say, by default the preset's) the deck is held still at
``--angles`` (degrees, nose-up) for the preset's static duration and gives C_D, C_L, C_M (bridge.aero.static,
second half of the record); with ``--omega`` it is also forced in heave and in pitch at that reduced frequency
with the thesis's velocity amplitudes (tools/reynolds_study.py's runner), giving h_pu, h_mu, h_ptheta, h_mtheta
(Eq 4.37). Everything else is the preset's, at the deck's Reynolds number V B / nu_air (1.05e8 at 50 m/s). With
three resolutions in a ratio of two, the observed order p = ln(|f1 - f2| / |f2 - f3|) / ln 2 of each quantity is
printed.
Cases keep checkpoints in ``<out>_runs/`` (an interrupted study resumes; a finished case is read back).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from reynolds_study import NU_AIR, run_speed, start_study  # noqa: E402

from bridge.aero.forced_motion import StaticCase, checkpoint_path, run_case  # noqa: E402
from bridge.aero.presets import QUALITY, preset, section_polygons  # noqa: E402
from bridge.aero.static import static_coefficients  # noqa: E402
from bridge.cfd.sections import great_belt_section  # noqa: E402

RESPONSES = ("h_pu", "h_mu", "h_ptheta", "h_mtheta")


def _say(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run_resolution(cells: int, args, runs: Path) -> dict:
    section = great_belt_section()
    polys = section_polygons(section)
    changes = _grid_changes(args)
    q = preset(args.quality, args.grid).with_(turbulence="sst", reynolds=args.speed * section.chord_m / NU_AIR,
                                              cells_per_chord=cells, cfl=args.cfl, **changes)
    row: dict = {"cells_per_chord": cells, "cfl": args.cfl, "reynolds": q.physics.reynolds, "grid": args.grid,
                 **changes, "static": {}}
    grid_angle = max(abs(a) for a in args.angles)
    for angle in args.angles:
        case = StaticCase(angle, grid_angle)
        t0 = time.perf_counter()
        rec = run_case(polys, case, q, checkpoint_path(runs, polys, case, q), progress=_say,
                       label=f"{cells} cells per chord, {angle:g} deg", threads=args.threads)
        c = static_coefficients([rec], [angle], section.depth_m / section.chord_m)
        row["static"][f"{angle:g}"] = {"C_D": float(c.drag[0]), "C_L": float(c.lift[0]), "C_M": float(c.moment[0]),
                                       "lift_rms": float(c.lift_rms[0]), "settling": c.settling[0].tolist(),
                                       "steps": rec.steps, "cells": rec.meta["cells"],
                                       "wall_s": time.perf_counter() - t0}
    if args.omega is not None:
        forced = run_speed(args.speed, args.omega, args.quality, "sst", runs, say=_say, grid=args.grid,
                           threads=args.threads, cells_per_chord=cells, cfl=args.cfl, **changes)
        row.update({name: forced[name] for name in RESPONSES if name in forced})
        row["forced_cases"] = forced["cases"]
    return row


def _grid_changes(args) -> dict:
    """The body-fitted O-grid's layer settings given on the command line (none on the overset pair)."""
    if args.grid != "body_fitted":
        return {}
    given = {"growth": args.growth, "first_height": args.first_height}
    return {k: v for k, v in given.items() if v is not None}


def _order(values: list[float]) -> str:
    """Observed order of three values on grids refined by two (``-`` where it is not defined)."""
    if len(values) != 3:
        return "-"
    d1, d2 = abs(values[0] - values[1]), abs(values[1] - values[2])
    if d1 == 0 or d2 == 0:
        return "-"
    return f"{math.log(d1 / d2) / math.log(2.0):.2f}"


def table(rows: list[dict], angles) -> str:
    cells = [r["cells_per_chord"] for r in rows]
    ratio2 = len(rows) == 3 and cells[1] == 2 * cells[0] and cells[2] == 2 * cells[1]
    head = "| quantity | " + " | ".join(f"{c} cells/chord" for c in cells) + " | observed order |"
    lines = [head, "|---|" + "---|" * (len(rows) + 1)]
    for angle in angles:
        for name in ("C_D", "C_L", "C_M"):
            vals = [r["static"][f"{angle:g}"][name] for r in rows]
            lines.append(f"| {name} at {angle:g} deg | " + " | ".join(f"{v:.4f}" for v in vals)
                         + f" | {_order(vals) if ratio2 else '-'} |")
    for name in RESPONSES:
        if all(name in r for r in rows):
            vals = [complex(*r[name]) for r in rows]
            lines.append(f"| {name} | " + " | ".join(f"{v.real:.4f} {v.imag:+.4f}i" for v in vals)
                         + f" | {_order([abs(v) for v in vals]) if ratio2 else '-'} (of the modulus) |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cells", type=int, nargs="+", default=[20, 40, 80], help="cells per chord of the body grid")
    ap.add_argument("--angles", type=float, nargs="+", default=[0.0], help="static angles of attack [deg]")
    ap.add_argument("--omega", type=float, default=None,
                    help="also force heave and pitch at this reduced frequency Omega = w B / V (thesis 0.5)")
    ap.add_argument("--cfl", type=float, default=0.5)
    ap.add_argument("--quality", default="quick", choices=sorted(QUALITY))
    ap.add_argument("--speed", type=float, default=50.0, help="wind speed [m/s]: the Reynolds number V B / nu")
    ap.add_argument("--threads", type=int, default=None,
                    help="CPU threads of each case (default: 2 on grids of 20 000 cells or more, else 1)")
    ap.add_argument("--grid", default="overset", choices=["overset", "body_fitted"],
                    help="the overset pair (default) or the body-fitted O-grid over the background")
    ap.add_argument("--growth", type=float, default=None,
                    help="body_fitted: the O-grid's layer growth ratio (1 .. 1.2; default the preset's)")
    ap.add_argument("--first-height", type=float, default=None,
                    help="body_fitted: the O-grid's first cell height, chords (default: y+ about 1, the wall "
                         "resolved; above twice that, Spalding's wall function: 3e-5 at 50 m/s puts the first "
                         "centre near y+ 50)")
    ap.add_argument("--out", default="out/sst_grid_study.json")
    args = ap.parse_args(argv)
    if args.grid != "body_fitted" and (args.growth is not None or args.first_height is not None):
        ap.error("--growth and --first-height: only with --grid body_fitted")
    if args.growth is not None and not 1.0 <= args.growth <= 1.2:
        ap.error(f"--growth: {args.growth} not allowed; allowed: 1 .. 1.2")
    if args.first_height is not None and not 0.0 < args.first_height <= 0.1:
        ap.error(f"--first-height: {args.first_height} not allowed; allowed: above 0, at most 0.1 chords")
    if any(not 8 <= c <= 400 for c in args.cells):
        ap.error(f"--cells: {args.cells} not allowed; allowed: 8 .. 400 cells per chord")
    if any(not -10.0 <= a <= 10.0 for a in args.angles):
        ap.error(f"--angles: {args.angles} not allowed; allowed: -10 .. 10 degrees")
    if args.omega is not None and not 0.05 <= args.omega <= 5.0:
        ap.error(f"--omega: {args.omega} not allowed; allowed: 0.05 .. 5")
    if not 0.05 <= args.cfl <= 1.0:
        ap.error(f"--cfl: {args.cfl} not allowed; allowed: 0.05 .. 1")
    if not 1.0 <= args.speed <= 200.0:
        ap.error(f"--speed: {args.speed} not allowed; allowed: 1 .. 200 m/s")
    out, runs = start_study(ap, args)
    command = "python tools/sst_grid_study.py " + " ".join(argv if argv is not None else sys.argv[1:])
    rows = []
    for c in sorted(args.cells):   # the file holds every finished resolution, so a long study shows as it goes
        rows.append(run_resolution(c, args, runs))
        text = table(rows, args.angles)
        tmp = out.with_suffix(".tmp")
        tmp.write_text(json.dumps({"command": command, "rows": rows, "table": text}, indent=1))
        tmp.replace(out)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
