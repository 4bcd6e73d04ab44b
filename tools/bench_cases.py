"""Benchmark of the aero stage's two ways to use the cores: its CFD cases one after the other, each on
two threads, or side by side in two processes, one core each (bridge.aero.forced_motion.run_cases).

    python tools/bench_cases.py                       # quick preset, overset pair, SST, 4 static cases
    python tools/bench_cases.py --quality tiny --grid single --turbulence laminar --duration 6

Method: ``--cases`` cases of the Great Belt deck held still at angles spread over -2 ... 2 degrees, each
``--duration`` B/V long, without checkpoints, run (a) with ``workers=1`` (one after the other; each case
on two threads where its grid has 20 000 cells or more, on one below, as the stage chooses) and (b) with
``workers=2``; the two alternate ``--repeats`` times and the median wall-clock ratio (a)/(b) is printed,
measured in one run (the machine is shared: ratios, not absolute times, are comparable across runs).
Worker start-up (a fresh Python process importing Warp and the project, a few seconds) is inside (b).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bridge.aero.forced_motion import StaticCase, run_cases  # noqa: E402
from bridge.aero.presets import QUALITY, preset, section_polygons  # noqa: E402
from bridge.cfd.sections import great_belt_section  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quality", default="quick", choices=sorted(QUALITY))
    ap.add_argument("--grid", default="overset", choices=["overset", "single"])
    ap.add_argument("--turbulence", default="sst", choices=["sst", "laminar"])
    ap.add_argument("--cases", type=int, default=4)
    ap.add_argument("--duration", type=float, default=3.0, help="length of each case in B/V")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None, help="JSON of the timings")
    args = ap.parse_args(argv)
    if not 2 <= args.cases <= 16:
        ap.error(f"--cases: {args.cases} not allowed; allowed: 2 .. 16")
    if not 0.1 <= args.duration <= 100:
        ap.error(f"--duration: {args.duration} not allowed; allowed: 0.1 .. 100 B/V")
    if not 1 <= args.repeats <= 10:
        ap.error(f"--repeats: {args.repeats} not allowed; allowed: 1 .. 10")
    import warp as wp

    wp.config.quiet = True
    section = great_belt_section()
    q = preset(args.quality, args.grid).with_(static_duration=args.duration)
    if args.turbulence == "sst":
        q = q.with_(turbulence="sst", reynolds=50.0 * section.chord_m / 1.48e-5)
    polys = section_polygons(section)
    angles = np.linspace(-2.0, 2.0, args.cases)
    jobs = [(StaticCase(float(a), 2.0), None, f"{a:+.2f} deg") for a in angles]
    run_cases(polys, jobs[:1], q, workers=1)   # compile and warm the kernels here first
    times = {"one after the other": [], "side by side": []}
    for r in range(args.repeats):
        for name, workers in (("one after the other", 1), ("side by side", 2)):
            t0 = time.perf_counter()
            recs = run_cases(polys, jobs, q, workers=workers)
            times[name].append(time.perf_counter() - t0)
            print(f"repeat {r + 1}: {name}: {times[name][-1]:.1f} s ({sum(x.steps for x in recs)} steps, "
                  f"{recs[0].meta['grids']})", flush=True)
    ratios = [a / b for a, b in zip(times["one after the other"], times["side by side"], strict=True)]
    print(f"speed-up of side by side: median {np.median(ratios):.2f} (each repeat: "
          + ", ".join(f"{x:.2f}" for x in ratios) + ")")
    if args.out is not None:
        args.out.write_text(json.dumps({"args": {k: str(v) for k, v in vars(args).items()}, "times_s": times,
                                        "speedup": ratios}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
