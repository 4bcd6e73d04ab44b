"""The CFD's own flutter speed: a section on springs released in the wind, against the derivative route's V_c.

    python tools/free_vibration.py great_belt_section_cfd --speeds 60,70,80
    python tools/free_vibration.py thin_plate_cfd --speeds 90,110,130 --quality standard

SCENARIO is a scenario of kind "section": its [section] table is the structure (mass, inertia, frequencies,
damping), its [deck_section] and [aero] tables the CFD (the same preset as the derivative route).  For each
wind speed the section is held at ``--twist-deg`` (nose up) for ``--hold`` B/V while the flow settles, then
released and the flow and the structure advance together (bridge/aero/free_vibration.py) for ``--periods``
periods of the pitch mode, or until the twist passes 6 degrees.  The growth rate and frequency of the least
damped mode come from a matrix-pencil fit of heave and pitch after the first pitch period; the onset speed
is where the growth rate changes sign, linear between the bracketing speeds.  The derivative route runs the
scenario's aero and flutter stages (cached in ``--cache``, shared with the main job; or ``--route`` reads
the summary.json of an earlier run), and both are printed side by side.  Each speed's record is cached too
(``--cache``/free-vibration): nobody pays twice.

Writes ``--out`` (default out/free_vibration/SCENARIO/): free_vibration.json (per speed: growth rate [1/s],
damping ratio, frequency [Hz], the record's length; the onset and the derivative route's V_c) and
free_vibration.png (pitch against time per speed; damping ratio against speed).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bridge.aero.free_vibration import (  # noqa: E402
    ReleaseCase,
    SpringSection,
    check_speeds,
    damped_modes,
    least_damped,
    onset,
)
from bridge.aero.presets import QUALITY, build_flow, section_polygons  # noqa: E402
from bridge.aero.stage import scenario_preset  # noqa: E402
from bridge.errors import InputError  # noqa: E402
from bridge.flutter.stage import air_density  # noqa: E402
from bridge.stages import code_digest  # noqa: E402


class Grown(Exception):
    """The motion outgrew what the grid makes room for: the growth is established."""


def derivative_route(sc, quality: str, cache: Path | None, summary: Path | None) -> dict:
    """The scenario's aero and flutter stages: V_c and f_c from the forced-motion derivatives, run (cached), or
    read from ``summary`` (a summary.json of ``python -m bridge.scenario SCENARIO``; its preset must be
    ``quality``)."""
    if summary is not None:
        s = json.loads(summary.read_text())
        if s.get("aero.quality") != quality:
            raise InputError("--route", str(summary), f"its aero preset is {s.get('aero.quality')!r}, not {quality!r}")
    else:
        from bridge.pipeline import run_stages
        from bridge.stages import RunOptions

        s = run_stages(sc, ["flutter"], RunOptions(progress=print, cache=cache, quality=quality))["flutter"].summary
        s = {**s, "aero.quality": quality}
    return {"critical_speed_m_s": s.get("flutter.critical_speed_m_s"),
            "critical_frequency_hz": s.get("flutter.frequency_hz"),
            "multimode_critical_speed_m_s": s.get("flutter.multimode_critical_speed_m_s")}


def release_run(q, polys, structure: SpringSection, speed: float, args, cache: Path | None) -> dict:
    """One speed: the record of heave and pitch after the release (cached by its inputs and the code)."""
    twist = -math.radians(args.twist_deg)   # nose up = clockwise
    if args.about_zero:   # held level, the mean loads preloaded into the springs, released with a pitch rate
        case = ReleaseCase(twist_rad=0.0, hold=args.hold, kick_rate=structure.pitch_omega * twist, preload=True)
    else:
        case = ReleaseCase(twist_rad=twist, hold=args.hold)
    t_end = args.hold + args.periods * 2 * math.pi / structure.pitch_omega
    key = hashlib.sha256(json.dumps({"verts": [np.round(p.vertices, 12).tolist() for p in polys],
                                     "quality": asdict(q), "structure": asdict(structure), "case": case.key(),
                                     "t_end": t_end, "code": code_digest(("bridge.cfd", "bridge.aero", "kernels"))},
                                    sort_keys=True).encode()).hexdigest()[:24]
    path = None if cache is None else cache / "free-vibration" / f"{key}.npz"
    if path is not None and path.exists():
        with np.load(path) as f:
            return {"history": f["history"], "wall_s": float(f["wall_s"]), "cells": int(f["cells"]),
                    "grown": bool(f["grown"]), "cached": True}
    from bridge.cfd import ProgressNote, run

    free = case.flow(build_flow(q, polys, case), structure)
    flow = free.flow
    limit = case.max_twist_rad

    def guard(f):
        if f.history and (abs(f.history[-1][2]) > limit or abs(f.history[-1][1]) > case.reach):
            raise Grown

    t0 = time.perf_counter()
    grown = False
    try:
        run(free, t_end, [guard, ProgressNote(f"V = {speed:g} m/s", t_end)])
    except Grown:
        grown = True
    history = np.array(free.history)
    wall = time.perf_counter() - t0
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(".tmp.npz")
        np.savez(tmp, history=history, wall_s=wall, cells=flow.n_cells, grown=grown)
        tmp.replace(path)
    return {"history": history, "wall_s": wall, "cells": int(flow.n_cells), "grown": grown, "cached": False}


def fit(run_record: dict, speed: float, chord: float, skip: float) -> dict:
    h = run_record["history"]
    t = h[:, 0]
    # the first pitch period holds the flow's start-up; a record cut short by growth keeps its last 3/4
    sel = t >= t[0] + min(skip, 0.25 * (t[-1] - t[0]))
    modes = damped_modes(t[sel], h[sel][:, 1:3].T)
    md = least_damped(modes)
    per_second = speed / chord
    return {"speed_m_s": speed, "growth_rate_per_s": md.sigma * per_second, "damping_ratio": md.damping_ratio,
            "frequency_hz": md.omega * per_second / (2 * math.pi), "record_B_over_V": float(t[-1] - t[0]),
            "grown_past_limit": run_record["grown"], "wall_s": run_record["wall_s"], "cells": run_record["cells"],
            "modes": [{"growth_rate_per_s": m.sigma * per_second, "frequency_hz": m.omega * per_second / (2 * math.pi),
                       "heave_amplitude_B": m.amplitudes[0], "pitch_amplitude_rad": m.amplitudes[1]} for m in modes]}


def figure(results, records, route, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    for r, rec in zip(results, records, strict=True):
        h = rec["history"]
        a.plot(h[:, 0] - h[0, 0], np.degrees(-h[:, 2]), label=f"{r['speed_m_s']:g} m/s")
    a.set_xlabel("time after release [B/V]")
    a.set_ylabel("pitch, nose up [deg]")
    a.legend()
    v = [r["speed_m_s"] for r in results]
    b.plot(v, [r["damping_ratio"] for r in results], "o-", label="free vibration (CFD)")
    b.axhline(0.0, color="k", lw=0.5)
    if route.get("critical_speed_m_s"):
        b.axvline(route["critical_speed_m_s"], color="C1", ls="--", label="derivative route V_c")
    b.set_xlabel("wind speed [m/s]")
    b.set_ylabel("damping ratio of the least damped mode")
    b.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario", help="a scenario of kind \"section\" with [deck_section] and [aero] tables")
    ap.add_argument("--speeds", required=True, help="comma-separated wind speeds [m/s]: two or more bracket the onset")
    ap.add_argument("--quality", default=None, choices=sorted(QUALITY), help="CFD preset (default: the scenario's)")
    ap.add_argument("--twist-deg", type=float, default=1.0, help="initial twist, nose up [deg] (0.1-3)")
    ap.add_argument("--hold", type=float, default=10.0, help="time held before the release [B/V] (2-50)")
    ap.add_argument("--periods", type=float, default=6.0, help="record length in pitch periods (3-30)")
    ap.add_argument("--about-zero", action="store_true",
                    help="hold the section level, preload the springs with the held mean loads and release it with "
                         "the pitch rate of --twist-deg: it oscillates about zero incidence, as the derivative route "
                         "linearises (default: released from the twist, it oscillates about its static equilibrium)")
    ap.add_argument("--cache", type=Path, default=Path("out/.cache"), help="stage and record cache ('none': off)")
    ap.add_argument("--route", type=Path, default=None,
                    help="summary.json of the scenario's own run to take the derivative route's V_c from "
                         "(default: run its aero and flutter stages, cached)")
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    try:
        from bridge.config import load_scenario

        speeds = check_speeds(args.speeds.split(","))
        for name, low, high in (("twist_deg", 0.1, 3.0), ("hold", 2.0, 50.0), ("periods", 3.0, 30.0)):
            value = getattr(args, name)
            if not low <= value <= high:
                raise InputError(f"--{name.replace('_', '-')}", value, f"allowed {low:g} .. {high:g}")
        sc = load_scenario(args.scenario)
        if sc.kind != "section" or sc.section is None:
            raise InputError("kind", sc.kind, "\"section\": the free-vibration check needs a [section] table")
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    cache = None if str(args.cache) == "none" else args.cache
    out = args.out or Path("out/free_vibration") / (sc.name + ("_about_zero" if args.about_zero else ""))
    import warp as wp

    wp.config.quiet = True
    deck, q = scenario_preset(sc, args.quality)
    try:
        route = derivative_route(sc, q.name, cache, args.route)
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    polys, rho = section_polygons(deck), air_density(sc)
    results, records = [], []
    for v in speeds:
        structure = SpringSection.at_speed(sc.section, v, rho)
        rec = release_run(q, polys, structure, v, args, cache)
        results.append(fit(rec, v, sc.section.deck_width_m, 2 * math.pi / structure.pitch_omega))
        records.append(rec)
        r = results[-1]
        cached = ", cached" if rec["cached"] else ""
        print(f"V = {v:7.2f} m/s: growth rate {r['growth_rate_per_s']:+.5f} 1/s, damping ratio "
              f"{r['damping_ratio']:+.4f}, f = {r['frequency_hz']:.4f} Hz ({rec['wall_s']:.0f} s{cached})")
    v_on = onset(speeds, [r["growth_rate_per_s"] for r in results])
    f_on = None
    if v_on is not None:
        f_on = float(np.interp(v_on, [r["speed_m_s"] for r in results], [r["frequency_hz"] for r in results]))
    vc = route["critical_speed_m_s"]
    summary = {"scenario": sc.name, "quality": q.name, "reynolds": q.physics.reynolds, "twist_deg": args.twist_deg,
               "about_zero": args.about_zero,
               "hold_B_over_V": args.hold, "periods": args.periods, "speeds": results,
               "onset_speed_m_s": v_on, "onset_frequency_hz": f_on, "derivative_route": route,
               "difference_percent": None if (v_on is None or not vc) else 100 * (v_on - vc) / vc}
    out.mkdir(parents=True, exist_ok=True)
    (out / "free_vibration.json").write_text(json.dumps(summary, indent=1))
    figure(results, records, route, out / "free_vibration.png")
    on = "none in the speeds run" if v_on is None else f"{v_on:.1f} m/s at {f_on:.4f} Hz"
    print(f"{sc.name} on {q.name!r}: free-vibration onset {on}; derivative route V_c = "
          f"{'none' if not vc else f'{vc:.1f} m/s'} at {route['critical_frequency_hz'] or float('nan'):.4f} Hz"
          + ("" if summary["difference_percent"] is None else f" ({summary['difference_percent']:+.1f} %)"))
    print(f"wrote {out}/free_vibration.json and free_vibration.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
