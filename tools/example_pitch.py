"""Example of the CFD on its own: a deck section pitched in a uniform wind, and its flutter derivatives.

    python tools/example_pitch.py                                   # the Great Belt box, 'quick', U/(fB) 4 8 12
    python tools/example_pitch.py scenarios/own_deck.toml --quality tiny --reduced-velocities 6
"""
import argparse
import tomllib
from pathlib import Path

import numpy as np

from bridge.aero.forced_motion import ForcedCase, fit_window
from bridge.aero.frequency_response import forced_motion_response
from bridge.aero.presets import QUALITY, build_flow, section_polygons
from bridge.cfd import run
from bridge.cfd.sections import great_belt_section, section_from_mapping
from bridge.flutter.derivatives import FRF, derivatives_from_frf

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("scenario", nargs="?", help="a scenario file whose [deck_section] to pitch (default: Great Belt)")
ap.add_argument("--quality", default="quick", choices=list(QUALITY))
ap.add_argument("--reduced-velocities", type=float, nargs="+", default=[4.0, 8.0, 12.0], metavar="U/(fB)")
args = ap.parse_args()
section = great_belt_section() if args.scenario is None else section_from_mapping(
    tomllib.loads(Path(args.scenario).read_text())["deck_section"], base_dir=Path(args.scenario).parent)
q = QUALITY[args.quality].with_(overset=True, turbulence="sst", reynolds=50 * section.chord_m / 1.48e-5)
print(f"{section.describe()}: pitched on {q.name!r}\nU/(fB)     A2*      A3*      H2*      H3*")
for rv in args.reduced_velocities:
    K = 2 * np.pi / rv   # reduced frequency w B / V: the CFD's units are B = V = rho = 1; wind 50 m/s
    case = ForcedCase.thesis("pitch", K)
    flow = build_flow(q, section_polygons(section), case)   # a bridge.cfd.Flow, owning its SST model
    rows = []   # a monitor records t and the loads F_x, F_y, M_z (inertial axes, M_z counter-clockwise) each step
    run(flow, case.end_time(q), [lambda f, add=rows.append: add((f.t, *f.total_force))])
    t, _, lift, moment = np.array(rows).T
    w = fit_window(t, case, q)   # the whole periods after the start-up; pitch and moment nose-up (-M_z)
    (r,) = forced_motion_response(t[w], np.array([case.displacement(x) for x in t[w]]), [K], dof="pitch", speed_m_s=1,
                                  deck_width_m=1, air_density_kg_m3=1, lift=lift[w], moment=-moment[w], fundamental=K)
    d = derivatives_from_frf(np.array([K]), FRF(np.nan, r.frf.h_ptheta, np.nan, r.frf.h_mtheta))
    print(f"{rv:6.3g} " + " ".join(f"{float(np.squeeze(getattr(d, n))):8.4f}" for n in ("A2", "A3", "H2", "H3")))
