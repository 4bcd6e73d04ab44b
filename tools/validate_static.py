"""Static coefficients and Strouhal number from the aero stage's static runner against published data.

    python tools/validate_static.py cylinder [--cells 16 24] [--duration 150]
    python tools/validate_static.py plate [--cells 24 40] [--thickness 0.02] [--plate-domain preset --quality standard]
                                  [--upstream 8 --half-height 16] [--reynolds 2000]
    python tools/validate_static.py section --section rectangle [--quality quick]

``cylinder``: circular cylinder at Re = 100, held still, through the same code as a deck section
(:class:`bridge.aero.forced_motion.StaticCase`, :func:`bridge.aero.static.static_coefficients`):
Strouhal number against Williamson (1989, J. Fluid Mech. 206: St = -3.3265/Re + 0.1816 + 1.6e-4 Re =
0.1643 at Re 100) and mean C_D against the 1.33-1.40 of immersed-boundary studies (docs/reference_cases.md).
The polygon is turned by a fraction of its facet angle and moved 0.3 cells off the grid's mirror line, so
that the start is not symmetric and shedding sets in.  ``plate``: thin plate at -2, 0, 2 degrees against
thin-aerofoil theory (dC_L/dalpha = 2 pi, aerodynamic centre at the quarter chord).  ``section``: a deck
section of bridge/cfd/sections.py on a preset, for the report.  Prints a table; ``--out`` JSON.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.aero.forced_motion import StaticCase, run_case  # noqa: E402
from bridge.aero.presets import QUALITY, SHORT_DOMAIN_40, section_polygons  # noqa: E402
from bridge.aero.static import static_coefficients  # noqa: E402
from bridge.cfd import Polygon, circle  # noqa: E402
from bridge.cfd.sections import FlatPlate, Rectangle, great_belt_section  # noqa: E402

WILLIAMSON_ST_RE100 = -3.3265 / 100 + 0.1816 + 1.6e-4 * 100


def _say(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def cylinder(cells: int, duration: float) -> dict:
    n = 256
    poly = circle(1.0, n)
    turn = 0.37 * 2 * np.pi / n
    c, s = math.cos(turn), math.sin(turn)
    # turned by a fraction of a facet and moved off the grid's mirror line by 0.3 cells: a start that is not
    # mirror-symmetric, so that shedding sets in within a few tens of D/U instead of growing from round-off
    poly = Polygon(poly.vertices @ np.array([[c, s], [-s, c]]) + np.array([0.0, 0.3 / cells]))
    q = QUALITY["standard"].with_(name=f"cylinder D/{cells}", cells_per_chord=cells, dy_over_dx=1.0,
                            upstream=8.0, downstream=20.0, half_height=10.0, core_half_height=1.0, reynolds=100.0,
                            static_duration=duration)
    rec = run_case(poly, StaticCase(0.0), q, progress=_say, label=f"cylinder D/{cells}")
    st = static_coefficients([rec], [0.0], depth_over_chord=1.0)
    return {"case": "cylinder", "cells_per_diameter": cells, "cells": [rec.meta["nx"], rec.meta["ny"]],
            "duration": duration, "window": st.window, "drag": float(st.drag[0]), "lift_rms": float(st.lift_rms[0]),
            "strouhal": float(st.strouhal[0]), "strouhal_williamson": WILLIAMSON_ST_RE100, "wall_s": rec.wall_s,
            "blockage": 1.0 / 20.0}


def sweep(polys, depth_over_chord: float, q, angles=(-2.0, 0.0, 2.0)) -> dict:
    recs = [run_case(polys, StaticCase(a, grid_angle_deg=max(map(abs, angles))), q, progress=_say,
                     label=f"{q.name} {a:g} deg") for a in angles]
    st = static_coefficients(recs, angles, depth_over_chord)
    fits = {name: st.fit(getattr(st, name)) for name in ("drag", "lift", "moment")}
    return {"angles_deg": list(angles), "drag": st.drag.tolist(), "lift": st.lift.tolist(),
            "moment": st.moment.tolist(), "strouhal_on_depth": st.strouhal.tolist(), "lift_rms": st.lift_rms.tolist(),
            "settling": st.settling.tolist(), "fits": fits, "cells": [recs[0].meta["nx"], recs[0].meta["ny"]],
            "wall_s": sum(r.wall_s for r in recs)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("case", choices=("cylinder", "plate", "section"))
    ap.add_argument("--cells", type=int, nargs="+", default=None, help="cells per diameter / chord")
    ap.add_argument("--duration", type=float, default=150.0, help="cylinder: run length in D / U")
    ap.add_argument("--thickness", type=float, default=0.02)
    ap.add_argument("--section", default="rectangle", choices=("rectangle", "great_belt"),
                    help="rectangle: B/D = 5 (BARC's); great_belt: the streamlined box of bridge/cfd/sections.py")
    ap.add_argument("--quality", default="quick", choices=sorted(QUALITY))
    ap.add_argument("--plate-domain", default="old-quick", choices=("old-quick", "preset"),
                    help="plate: the short 2 / 10 / 2 chord domain (presets.SHORT_DOMAIN_40), or --quality's")
    ap.add_argument("--upstream", type=float, default=None, help="plate: chords upstream (default: the domain's)")
    ap.add_argument("--half-height", type=float, default=None, help="plate: chords to each side (default: domain's)")
    ap.add_argument("--reynolds", type=float, default=None, help="plate: Reynolds number (default: the preset's)")
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = []
    if args.case == "cylinder":
        for n in args.cells or [16, 24]:
            r = cylinder(n, args.duration)
            rows.append(r)
            print(f"cylinder Re 100, D/{n} ({r['cells'][0]} x {r['cells'][1]} cells, blockage D/H = 5 %): "
                  f"C_D = {r['drag']:.3f} (IB studies 1.33-1.40), St = {r['strouhal']:.4f} (Williamson "
                  f"{WILLIAMSON_ST_RE100:.4f}), C_L rms = {r['lift_rms']:.3f}, averaged over t = "
                  f"{r['window'][0]:.0f}-{r['window'][1]:.0f}, {r['wall_s']:.0f} s", flush=True)
    elif args.case == "plate":
        poly = section_polygons(FlatPlate(1.0, args.thickness))
        for n in args.cells or [24, 40]:
            # the short domain and its run length (SHORT_DOMAIN_40), or the preset's (its grid, n cells)
            base = SHORT_DOMAIN_40 if args.plate_domain == "old-quick" else QUALITY[args.quality]
            given = {"upstream": args.upstream, "half_height": args.half_height, "reynolds": args.reynolds}
            q = base.with_(name=f"plate {n}/chord", cells_per_chord=n,
                                    **{k: v for k, v in given.items() if v is not None})
            r = sweep(poly, args.thickness, q)
            rows.append({"case": "plate", "cells_per_chord": n, **r})
            (_, dcl), (_, dcm) = r["fits"]["lift"], r["fits"]["moment"]
            print(f"plate t/B = {args.thickness:g}, {n} cells per chord ({r['cells'][0]} x {r['cells'][1]}), "
                  f"Re {q.physics.reynolds:g}: dC_L/dalpha = {dcl:.3f} (2 pi = 6.283, ratio {dcl / (2 * np.pi):.3f}), "
                  f"dC_M/dalpha / dC_L/dalpha = {dcm / dcl:.3f} (0.25), C_D(0) = {r['drag'][1]:.4f}, "
                  f"{r['wall_s']:.0f} s", flush=True)
    else:
        section = Rectangle(5.0, 1.0) if args.section == "rectangle" else great_belt_section()
        q = QUALITY[args.quality]
        r = sweep(section_polygons(section), section.depth_m / section.chord_m, q)
        rows.append({"case": args.section, "quality": args.quality, **r})
        print(json.dumps(r["fits"]), "St", r["strouhal_on_depth"], f"{r['wall_s']:.0f} s", flush=True)
    print(f"total {time.perf_counter() - t0:.0f} s")
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
