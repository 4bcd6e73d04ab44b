"""Flutter derivatives of a thin flat plate from forced-motion CFD against Theodorsen's (docs/aero.md).

    python tools/validate_aero.py --quality standard --reduced-velocities 4 8 12 [--thickness 0.02]

Runs one heave and one pitch case per reduced velocity with the aero stage's runner (bridge.aero:
thesis velocity amplitudes, transient periods dropped, harmonic fit over whole periods) and prints the
eight derivatives H1*-H4*, A1*-A4* (B form, h and L down) beside Theodorsen's (Theodorsen 1935, NACA
Report 496; check values in docs/reference_cases.md) with the relative differences; writes the numbers
to ``--out`` (JSON).  Cases run one after another on both cores; each takes minutes on the standard grid.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.aero.forced_motion import QUALITY, ForcedCase, run_case, whole_periods  # noqa: E402
from bridge.aero.frequency_response import forced_motion_response  # noqa: E402
from bridge.aero.stage import _unit_polygon  # noqa: E402
from bridge.cfd.sections import FlatPlate  # noqa: E402
from bridge.flutter.aerodynamics import Theodorsen  # noqa: E402
from bridge.flutter.derivatives import FRF, derivatives_from_frf  # noqa: E402

NAMES = ("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4")


def plate_derivatives(reduced_velocity: float, quality: str, thickness: float, say=print) -> dict:
    poly = _unit_polygon(FlatPlate(1.0, thickness))
    q = QUALITY[quality]
    K = 2 * np.pi / reduced_velocity
    h, wall = {}, 0.0
    for dof in ("heave", "pitch"):
        case = ForcedCase.thesis(dof, K)
        rec = run_case(poly, case, q, progress=say, label=f"U/(fB) = {reduced_velocity:g} {dof}")
        wall += rec.wall_s
        sel = whole_periods(rec, case, q.discard_periods)
        (resp,) = forced_motion_response(rec.t[sel], rec.motion[sel], [K], dof=dof, speed_m_s=1.0, deck_width_m=1.0,
                                         air_density_kg_m3=1.0, lift=rec.lift[sel], moment=rec.moment[sel],
                                         fundamental=K)
        h.update({n: complex(getattr(resp.frf, n)) for n in resp.provides})
        cells = (rec.meta["nx"], rec.meta["ny"])
    frf = FRF(h_pu=h["h_pu"], h_ptheta=h["h_ptheta"], h_mu=h["h_mu"], h_mtheta=h["h_mtheta"])
    cfd = derivatives_from_frf(np.array([K]), FRF(*(np.array([v]) for v in frf[:4])))
    ref = derivatives_from_frf(np.array([K]), Theodorsen().frf(np.array([K]), 1.0))
    row = {"reduced_velocity": reduced_velocity, "K": K, "quality": quality, "thickness": thickness,
           "cells": cells, "wall_s": wall, "frf": {k: [v.real, v.imag] for k, v in h.items()}}
    for n in NAMES:
        c, r = float(np.asarray(getattr(cfd, n))[0]), float(np.asarray(getattr(ref, n))[0])
        row[n] = {"cfd": c, "theodorsen": r, "relative_difference": (c - r) / abs(r)}
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quality", default="standard", choices=sorted(QUALITY))
    ap.add_argument("--reduced-velocities", type=float, nargs="+", default=[4.0, 8.0, 12.0])
    ap.add_argument("--thickness", type=float, default=0.02, help="plate thickness / chord (default 0.02)")
    ap.add_argument("--out", type=Path, default=Path("out/validate_aero.json"))
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = [plate_derivatives(uv, args.quality, args.thickness, say=lambda m: print(m, file=sys.stderr, flush=True))
            for uv in args.reduced_velocities]
    print(f"thin plate t/B = {args.thickness:g}, preset {args.quality!r}, {time.perf_counter() - t0:.0f} s")
    print("| U/(fB) | " + " | ".join(f"{n}* CFD / Theodorsen (diff)" for n in NAMES) + " |")
    print("|---|" + "---|" * len(NAMES))
    for r in rows:
        cells = [f"{r[n]['cfd']:.3f} / {r[n]['theodorsen']:.3f} ({100 * r[n]['relative_difference']:+.0f} %)"
                 for n in NAMES]
        print(f"| {r['reduced_velocity']:g} | " + " | ".join(cells) + " |")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
