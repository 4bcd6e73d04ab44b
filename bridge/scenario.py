"""Command line: ``python -m bridge.scenario NAME_OR_PATH [NAME_OR_PATH ...] [options]``.

Runs each scenario through its stages and writes ``OUT/<name>/`` (results.h5, summary.json, report.md,
PNG plots), then prints the headline (flutter speed, frequency, governing modes, multimode speed,
divergence speed).  With several scenarios it also writes ``OUT/comparison.md``: the bridges side by side.
Finished stages are kept in ``OUT/.cache/`` and reused while their inputs are unchanged.
"""

from __future__ import annotations

import sys

if __name__ == "__main__":
    from bridge.interrupts import stop_quietly_while_loading

    stop_quietly_while_loading()

import argparse
import time
import tomllib
from collections.abc import Sequence
from pathlib import Path

from . import __version__
from .cluster import connect
from .config import AERODYNAMIC_CHOICES, SCENARIO_DIR, load_scenario, with_aerodynamics
from .errors import ConvergenceError, InputError
from .files import atomic_write_text, check_output_root
from .interrupts import Interrupts, exit_command
from .pipeline import plan_stages, run_scenario
from .results import check_target, headline
from .stages import STAGES, RunOptions

__all__ = ["main", "comparison_table", "parse_stages", "EXIT_CODES"]

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
    ("flutter.mode_pair", "governing mode pair", "{}"),
    ("flutter.multimode_critical_speed_m_s", "multimode p-k V_c [m/s]", "{:.1f}"),
    ("flutter.divergence_speed_m_s", "static divergence speed [m/s]", "{:.1f}"),
]

EXIT_CODES = {0: "done",
              2: "bad input: one line naming the key, the value and the allowed range; nothing written",
              3: "an iteration did not converge (its last residual is printed)",
              130: "interrupted (Ctrl-C); finished results and cached stages are kept",
              143: "terminated (SIGTERM); as 130"}


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


def _shipped_scenarios() -> str:
    lines = []
    for f in sorted(SCENARIO_DIR.glob("*.toml")):
        try:
            with open(f, "rb") as fh:
                desc = tomllib.load(fh).get("description", "")
        except (OSError, tomllib.TOMLDecodeError):
            desc = ""
        lines.append(f"  {f.stem:<26} {desc}")
    return "\n".join(lines)


def _epilog() -> str:
    codes = "\n".join(f"  {k:<4} {v}" for k, v in EXIT_CODES.items())
    return (f"shipped scenarios (scenarios/*.toml):\n{_shipped_scenarios()}\n\n"
            f"exit status:\n{codes}\n\nresult schema: docs/results.md")


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m bridge.scenario", description=__doc__.split("\n\n")[1],
                                epilog=_epilog(), formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenarios", nargs="+", metavar="NAME_OR_PATH",
                   help="a shipped scenario (listed below) or a path to a .toml file")
    p.add_argument("--out", default="out", type=Path, help="output folder (default: out/)")
    p.add_argument("--stages", default=None,
                   help=f"comma-separated stages to run (known: {', '.join(STAGES)}; default: all for the kind); "
                        "the stages they need run too, or come from the cache")
    p.add_argument("--main-span", type=float, default=None, metavar="METRES",
                   help="up-scale the bridge to this main span (thesis 1.5 rules)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace the results of an earlier run in OUT/<name>/ (other files there are kept)")
    p.add_argument("--no-cache", action="store_true",
                   help="compute every stage afresh (and do not store them in OUT/.cache/)")
    p.add_argument("--quick", action="store_true",
                   help="coarse meshes and grids everywhere (the FEM, and the CFD's 'tiny' preset): a smoke run "
                        "whose numbers are not to be used")
    p.add_argument("--quality", choices=("tiny", "quick", "standard", "fine"), default=None,
                   help="CFD preset of the aero stage (grid, time step, run length; docs/aero.md); default: the "
                        "scenario's [aero] quality (not with --quick, which selects 'tiny')")
    p.add_argument("--aerodynamics", choices=AERODYNAMIC_CHOICES, default=None,
                   help="the flutter stage's aerodynamics instead of the scenario's [flutter] aerodynamics: 'cfd' "
                        "(the deck's own, from the aero stage), 'theodorsen' (thin plate, seconds) or "
                        "'quasi_steady' (the scenario's [flutter.quasi_steady] static coefficients)")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="processes running the aero stage's CFD cases side by side (default: 2 on a machine "
                        "with 2 or more cores; 1: one after the other)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run the aero stage's CFD cases on the workers of this Dask scheduler (e.g. "
                        "tcp://host:8786; needs pip install -e \".[dask]\"; docs/guide.md)")
    p.add_argument("--quiet", action="store_true", help="no progress messages")
    p.add_argument("--version", action="version", version=f"bridge-flutter {__version__}")
    return p


def parse_stages(text: str | None) -> list[str] | None:
    """``--stages`` as a list (None: the default for each kind); an empty list is an InputError."""
    if text is None:
        return None
    stages = [s.strip() for s in text.split(",") if s.strip()]
    if not stages:
        raise InputError("--stages", text, f"names no stage; known: {', '.join(STAGES)}")
    return stages


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    say = (lambda m: None) if args.quiet else (lambda m: print(m, file=sys.stderr, flush=True))
    written: list[Path] = []
    with Interrupts() as interrupts:
        try:
            return _run(args, say, written)
        except InputError as err:
            print(f"error: {err}", file=sys.stderr)
            return 2
        except ConvergenceError as err:
            print(f"error: {err}", file=sys.stderr)
            return 3
        except BaseException:
            def kept() -> str:
                folders = f"kept: {', '.join(map(str, written))}" if written else "no result folder written"
                stored = not args.no_cache and any((args.out / ".cache").glob("*/*/entry.h5"))
                cached = f"; finished stages stay in {args.out / '.cache'}" if stored else ""
                return f"interrupted; {folders}{cached}"
            return interrupts.reported(kept)


def _run(args: argparse.Namespace, say, written: list[Path]) -> int:
    stages = parse_stages(args.stages)
    if args.workers is not None and not 1 <= args.workers <= 64:
        raise InputError("--workers", args.workers, "allowed: 1 .. 64 processes")
    if args.scheduler is not None and args.workers is not None:
        raise InputError("--workers", args.workers, "not with --scheduler, whose workers run the CFD cases")
    if args.quick and args.quality not in (None, "tiny"):
        raise InputError("--quality", args.quality, "not with --quick, which runs every stage coarse (the CFD on "
                         "'tiny'): drop --quick to run this preset with the full FEM")
    # read and check everything before running anything, so bad input costs nothing
    scenarios = [with_aerodynamics(load_scenario(n, main_span_m=args.main_span), args.aerodynamics)
                 for n in args.scenarios]
    seen: dict[str, str] = {}
    runs_cfd = False
    for arg, sc in zip(args.scenarios, scenarios, strict=True):
        if sc.name in seen:
            raise InputError("name", sc.name, f"given to both {seen[sc.name]} and {arg}: each scenario of one "
                             "command needs its own name (its result folder)")
        seen[sc.name] = arg
        runs_cfd |= "aero" in plan_stages(sc, stages)
    if args.scheduler is not None and runs_cfd:
        connect(args.scheduler).close()   # a scheduler that does not answer is refused before any work
    check_output_root(args.out)
    for sc in scenarios:
        check_target(args.out, sc.name, args.overwrite)
    comparison = args.out / "comparison.md"
    if len(scenarios) > 1 and comparison.exists() and not args.overwrite:
        raise InputError("--out", str(comparison), "already holds a comparison of an earlier run; pass "
                         "--overwrite to replace it or choose another --out")
    options = RunOptions(quick=args.quick, progress=say, cache=None if args.no_cache else args.out / ".cache",
                         quality=args.quality, workers=args.workers,
                         scheduler=args.scheduler)
    summaries = {}
    for sc in scenarios:
        t0 = time.perf_counter()
        folder, outputs = run_scenario(sc, args.out, stages, options, overwrite=args.overwrite)
        written.append(folder)
        summaries[sc.name] = {k: v for out in outputs.values() for k, v in out.summary.items()}
        say(f"[{sc.name}] done in {time.perf_counter() - t0:.1f} s -> {folder}")
    for name, summary in summaries.items():
        print(f"{name}: results in {args.out / name}")
        for line in headline(summary):
            print(f"  {line}")
    if len(summaries) > 1:
        table = comparison_table(summaries)
        atomic_write_text(comparison, "# Bridges side by side\n\n" + table + "\n")
        print(table)
    return 0


if __name__ == "__main__":
    exit_command(main())
