"""The thesis's Reynolds-number question (its Table 5.3): the Great Belt deck's frequency response at one
reduced frequency, Omega = 0.5, for two wind speeds (25 and 50 m/s), with the k-omega SST model.

    python tools/reynolds_study.py --quality quick --grid overset --speeds 25 50 [--omega 0.5]
                                   [--sst-walls equilibrium|function|blended] [--out out/reynolds_study.json]

At one Omega the flow differs between the two speeds only through the Reynolds number Re = V B / nu (5.2e7
and 1.05e8 for B = 31 m, nu = 1.48e-5 m^2/s, thesis 5.2.4), so a Reynolds-number-independent section gives
the same non-dimensional h_xy at both; the thesis's Table 5.3 reports differences of 3-9 % in the amplitudes
and up to 31 % in the phases. Each speed runs one heave and one pitch case with the aero stage's runner
(bridge.aero.forced_motion.run_case: the deck as an immersed body with Spalding's wall function, on the
overset pair by default, whole periods fitted) at the thesis's velocity amplitudes relative to the wind
(udot_0 / V = 0.4 / 50, thetadot_0 B / V = 0.028 * 31 / 50: the same motion in units of B and B / V at both
speeds, so only Re differs). Reported per speed: h_pu, h_mu, h_ptheta, h_mtheta (Eq 4.37), and in the
thesis's form |H_xdot| (N s/m^2 ... N s) with the phase lag phi of H = |H| (cos phi - i sin phi), beside
Table 5.3. Cases keep checkpoints in ``<out>_runs/`` (an interrupted study resumes; a finished case is read
back). Laminar runs (``--turbulence laminar``) use the preset's Reynolds number at both speeds, which only
checks the set-up.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.aero.forced_motion import ForcedCase, checkpoint_path, run_case, whole_periods  # noqa: E402
from bridge.aero.frequency_response import forced_motion_response  # noqa: E402
from bridge.aero.presets import QUALITY, SST_WALLS, Physics, preset, section_polygons  # noqa: E402
from bridge.cfd.sections import great_belt_section  # noqa: E402

RHO, NU_AIR = 1.225, 1.48e-5   # thesis 5.2.4
# Table 5.3 of the thesis: (V = 25 m/s, omega = 0.4 rad/s) and (V = 50 m/s, omega = 0.8 rad/s)
THESIS_TABLE_5_3 = {25.0: {"H_pu": 1.95e3, "H_mu": 1.66e4, "H_ptheta": 3.95e4, "H_mtheta": 3.49e5,
                           "phi_pu": 1.645, "phi_mu": 1.717, "phi_ptheta": -0.073, "phi_mtheta": 0.253},
                    50.0: {"H_pu": 1.77e3, "H_mu": 1.52e4, "H_ptheta": 4.16e4, "H_mtheta": 3.39e5,
                           "phi_pu": 1.275, "phi_mu": 1.510, "phi_ptheta": -0.400, "phi_mtheta": 0.174}}


def run_speed(speed: float, omega: float, quality: str, turbulence: str, runs: Path | None, say=print,
              grid: str = "overset", threads: int | None = None, **changes) -> dict:
    """Heave and pitch at one speed; ``changes``: fields of the preset to replace (a grid study's
    cells_per_chord, cfl); ``threads``: of each case (None: run_case's choice)."""
    section = great_belt_section()
    polys = section_polygons(section)
    q = preset(quality, grid).with_(**changes)
    if turbulence != "laminar":
        q = q.with_(turbulence=turbulence, reynolds=speed * section.chord_m / NU_AIR)
    phys = q.physics
    row: dict = {"speed_m_s": speed, "reynolds": phys.reynolds, "turbulence": phys.turbulence, "quality": quality,
                 "grid": grid, **({"sst_walls": phys.sst_walls} if phys.turbulence == "sst" else {}),
                 "omega": omega, "angular_frequency_rad_s": omega * speed / section.chord_m, "cases": {}}
    for dof in ("heave", "pitch"):
        case = ForcedCase.thesis(dof, omega)
        t0 = time.perf_counter()
        rec = run_case(polys, case, q, checkpoint_path(runs, polys, case, q), progress=say,
                       label=f"V = {speed:g} m/s {dof}", threads=threads)
        sel = whole_periods(rec, case, q)
        # the CFD's units are B = V = rho = 1: the fit gives the non-dimensional h_xy (Eq 4.37), which the
        # same response at the real speed, width and density turns into the thesis's H_xdot
        (resp,) = forced_motion_response(rec.t[sel], rec.motion[sel], [omega], dof=dof, speed_m_s=1.0,
                                         deck_width_m=1.0, air_density_kg_m3=1.0, lift=rec.lift[sel],
                                         moment=rec.moment[sel], fundamental=omega)
        real = replace(resp, speed_m_s=speed, deck_width_m=section.chord_m, air_density_kg_m3=RHO)
        for name in resp.provides:
            h = complex(getattr(resp.frf, name))
            err = complex(getattr(resp.stderr, name))
            H = real.rate()[name]
            key = name.removeprefix("h_")
            row[name] = [h.real, h.imag]
            row[f"{name}_stderr"] = [err.real, err.imag]
            row[f"H_{key}"] = abs(H)
            row[f"phi_{key}"] = float(-np.angle(H))   # H = |H| (cos phi - i sin phi)
        row["cases"][dof] = {"steps": rec.steps, "wall_s": time.perf_counter() - t0, "periods": resp.periods,
                             "cells": rec.meta["cells"], "resumed_from_step": rec.resumed_from_step}
    return row


def start_study(ap: argparse.ArgumentParser, args) -> tuple[Path, Path]:
    """What a study tool does once its own arguments are checked: check ``--threads``, quiet Warp, make
    the folder of ``--out``; returns the output file and the folder of the cases' checkpoints beside it."""
    if args.threads is not None and not 1 <= args.threads <= 64:
        ap.error(f"--threads: {args.threads} not allowed; allowed: 1 .. 64")
    import warp as wp

    wp.config.quiet = True
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    return out, out.with_name(out.stem + "_runs")


def _table(rows: list[dict]) -> str:
    keys = [("H_pu", "|H_pudot| [N s/m^2]"), ("H_mu", "|H_mudot| [N s/m]"), ("H_ptheta", "|H_pthetadot| [N s/m]"),
            ("H_mtheta", "|H_mthetadot| [N s]"), ("phi_pu", "phi_pu [rad]"), ("phi_mu", "phi_mu [rad]"),
            ("phi_ptheta", "phi_ptheta [rad]"), ("phi_mtheta", "phi_mtheta [rad]")]
    a, b = rows[0], rows[-1]
    va, vb = a["speed_m_s"], b["speed_m_s"]
    head = (f"| | CFD V = {va:g} | CFD V = {vb:g} | CFD variation [%] | thesis V = 25 | thesis V = 50 | "
            "thesis variation as printed [%] | thesis variation at one Omega [%] |")
    lines = [head, "|---|---|---|---|---|---|---|---|"]
    for key, label in keys:
        ta, tb = THESIS_TABLE_5_3[25.0][key], THESIS_TABLE_5_3[50.0][key]
        # at one Omega, |H_xdot| = |h_xy| rho V B^n / (2 Omega) grows with V: the Reynolds number shows in
        # |H_xdot| / V (amplitudes), in the phases as they are
        per = (lambda h, v: h / v) if key.startswith("H_") else (lambda h, v: h)
        var = 100 * (per(a[key], va) - per(b[key], vb)) / abs(per(a[key], va))
        tvar = 100 * (per(ta, 25.0) - per(tb, 50.0)) / abs(per(ta, 25.0))
        # a phase near zero makes a relative change meaningless (the thesis's phi_ptheta, -0.073 rad)
        printed, tv = ((f"{100 * (ta - tb) / abs(ta):.1f}", f"{tvar:.1f}") if abs(ta) >= 0.1 or key.startswith("H_")
                       else ("-", "-"))
        lines.append(f"| {label} | {a[key]:.4g} | {b[key]:.4g} | {var:.1f} | {ta:.4g} | {tb:.4g} | {printed} | {tv} |")
    lines += ["", "Variations relative to the lower speed; amplitudes compared as |H_xdot| / V (at one Omega a "
              "Reynolds-number-independent section has |H_xdot| proportional to V), phases as they are."]
    lines += ["", "| | " + " | ".join(f"V = {r['speed_m_s']:g} (Re {r['reynolds']:.3g})" for r in rows) + " |",
              "|---|" + "---|" * len(rows)]
    for name in ("h_pu", "h_mu", "h_ptheta", "h_mtheta"):
        lines.append(f"| {name} | " + " | ".join(f"{r[name][0]:.4f} {r[name][1]:+.4f}i" for r in rows) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quality", default="quick", choices=sorted(QUALITY))
    ap.add_argument("--speeds", type=float, nargs="+", default=[25.0, 50.0])
    ap.add_argument("--omega", type=float, default=0.5, help="reduced frequency Omega = w B / V (thesis 0.5)")
    ap.add_argument("--turbulence", default="sst", choices=["sst", "laminar"])
    ap.add_argument("--grid", default="overset", choices=["overset", "single"],
                    help="overset (default): the deck fixed in a body grid; single: the deck moving through one grid, "
                         "whose SST forces jitter as the deck's faces change class (docs/aero.md)")
    ap.add_argument("--threads", type=int, default=None,
                    help="CPU threads of each case (default: 2 on grids of 20 000 cells or more, else 1)")
    walls = Physics(reynolds=1.0).sst_walls   # the presets' wall treatment
    ap.add_argument("--sst-walls", default=walls, choices=SST_WALLS,
                    help=f"with SST, the deck's walls (Physics.sst_walls; default {walls!r}, the presets')")
    ap.add_argument("--out", default="out/reynolds_study.json")
    args = ap.parse_args(argv)
    if len(args.speeds) < 2 or any(not 1.0 <= v <= 200.0 for v in args.speeds):
        ap.error(f"--speeds: {args.speeds} not allowed; allowed: two or more speeds in 1 .. 200 m/s")
    if not 0.05 <= args.omega <= 5.0:
        ap.error(f"--omega: {args.omega} not allowed; allowed: 0.05 .. 5")
    out, runs = start_study(ap, args)
    rows = [run_speed(v, args.omega, args.quality, args.turbulence, runs,
                      say=lambda s: print(s, file=sys.stderr, flush=True), grid=args.grid, threads=args.threads,
                      sst_walls=args.sst_walls)
            for v in sorted(args.speeds)]
    table = _table(rows)
    print(table)
    result = {"command": "python tools/reynolds_study.py " + " ".join(argv if argv is not None else sys.argv[1:]),
              "rows": rows, "table": table}
    tmp = out.with_suffix(".tmp")
    tmp.write_text(json.dumps(result, indent=1))
    tmp.replace(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
