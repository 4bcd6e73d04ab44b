"""Command line: ``python -m bridge.scenario NAME_OR_PATH [NAME_OR_PATH ...] [options]``.

Runs each scenario through its stages and writes ``OUT/<name>/`` (results.h5, summary.json, report.md,
PNG plots).  With several scenarios it also writes ``OUT/comparison.md``: the bridges side by side.

Exit status: 0 done; 2 bad input (one line naming the key, the value and the allowed range); 3 an
iteration that did not converge (with its last residual).  Nothing half-written is left in OUT.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from .config import load_scenario
from .errors import ConvergenceError, InputError
from .pipeline import run_scenario
from .stages import STAGES, RunOptions

__all__ = ["main", "comparison_table"]

# Rows of the side-by-side table: (summary key, label, format).
COMPARISON_ROWS = [
    ("scenario.main_span_m", "main span L [m]", "{:.0f}"),
    ("cable.area_m2", "cable area A_c [m^2] (Table 1.1)", "{:.3f}"),
    ("scenario.sag_m", "sag h [m] (Table 1.2)", "{:.2f}"),
    ("scenario.side_span_m", "side span L_s [m] (Table 1.2)", "{:.0f}"),
    ("scenario.pylon_height_m", "pylon height [m]", "{:.1f}"),
    ("scenario.pylon_leg_inertia_ratio", "pylon leg I/I_0 (Eq 1.3)", "{:.3f}"),
    ("scenario.extra_cross_beams", "extra pylon cross beams", "{}"),
    ("scenario.deck_mass_per_length_kg_m", "mu [kg/m] (Eq 4.7, Table 3.6)", "{:.4g}"),
    ("scenario.deck_inertia_per_length_kg_m2_m", "J [kg m^2/m] (Eq 4.7, Table 3.6)", "{:.4g}"),
    ("cable.horizontal_force_per_cable_N", "H per cable [N]", "{:.4g}"),
    ("cable.horizontal_force_total_N", "H both cables [N]", "{:.4g}"),
    ("cable.stress_at_pylon_Pa", "cable stress at pylon [Pa]", "{:.4g}"),
    ("cable.main_span_length_m", "cable length, main span [m]", "{:.1f}"),
    ("cable.hanger_count_per_cable", "hangers per cable", "{}"),
    ("cable.equilibrium_residual", "equilibrium residual (Eq 2.13)", "{:.1e}"),
    ("cable.first_vertical_frequency_eq_3_2_hz", "f_1 estimate Eq 3.2 [Hz]", "{:.4f}"),
    ("fem.frequency_S_V1_hz", "FEM first symmetric vertical [Hz]", "{:.4f}"),
    ("fem.frequency_S_T1_hz", "FEM first symmetric torsional [Hz]", "{:.4f}"),
    ("fem.a_jj", "a_jj (Table 3.6)", "{:.3f}"),
    ("fem.a_kk", "a_kk (Table 3.6)", "{:.3f}"),
    ("fem.a_jk", "a_jk (Table 3.6)", "{:.3f}"),
    ("flutter.critical_speed_m_s", "flutter speed V_c [m/s]", "{:.1f}"),
    ("flutter.frequency_hz", "flutter frequency [Hz]", "{:.4f}"),
]


def comparison_table(summaries: dict[str, dict]) -> str:
    """Markdown table, one column per scenario, rows for the keys any scenario has."""
    names = list(summaries)
    lines = ["| quantity | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for key, label, fmt in COMPARISON_ROWS:
        if not any(key in s for s in summaries.values()):
            continue
        cells = []
        for n in names:
            v = summaries[n].get(key)
            cells.append("-" if v is None else (fmt.format(v) if not isinstance(v, str) else v))
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m bridge.scenario", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenarios", nargs="+", metavar="NAME_OR_PATH",
                   help="scenario name in scenarios/ (great_belt, model_a, model_b, model_c) or a path to a .toml")
    p.add_argument("--out", default="out", type=Path, help="output folder (default: out/)")
    p.add_argument("--stages", default=None,
                   help=f"comma-separated stages to run (known: {', '.join(STAGES)}; default: all for the kind)")
    p.add_argument("--main-span", type=float, default=None, metavar="METRES",
                   help="up-scale the bridge to this main span (thesis 1.5 rules)")
    p.add_argument("--quick", action="store_true", help="coarse meshes/grids: a fast smoke run")
    p.add_argument("--quiet", action="store_true", help="no progress messages")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    say = (lambda m: None) if args.quiet else (lambda m: print(m, file=sys.stderr, flush=True))
    options = RunOptions(quick=args.quick, progress=say)
    stages = None if args.stages is None else [s.strip() for s in args.stages.split(",") if s.strip()]
    try:
        # read and check every scenario before running any, so bad input costs nothing
        scenarios = [load_scenario(n, main_span_m=args.main_span) for n in args.scenarios]
        summaries = {}
        for sc in scenarios:
            t0 = time.perf_counter()
            folder, outputs = run_scenario(sc, args.out, stages, options)
            summary = {k: v for out in outputs.values() for k, v in out.summary.items()}
            summaries[sc.name] = summary
            say(f"[{sc.name}] done in {time.perf_counter() - t0:.1f} s -> {folder}")
        if len(summaries) > 1:
            table = comparison_table(summaries)
            fd, tmp = tempfile.mkstemp(dir=args.out, prefix=".comparison.", suffix=".md")
            with os.fdopen(fd, "w") as fh:
                fh.write("# Bridges side by side\n\n" + table + "\n")
            os.replace(tmp, Path(args.out) / "comparison.md")
            print(table)
        else:
            print(f"results in {Path(args.out) / scenarios[0].name}")
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except ConvergenceError as err:
        print(f"error: {err}", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
