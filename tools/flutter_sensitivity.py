"""How much the flutter speed moves when one flutter derivative is off by a given factor.

    python tools/flutter_sensitivity.py great_belt [--derivatives H1 H2 H3 A1 A2 A3] [--factors 0.5 0.8 1.25 1.5]
    python tools/flutter_sensitivity.py great_belt --quality standard --cache /path/to/out/.cache
    python tools/flutter_sensitivity.py great_belt --together H3=1.1 A1=1.15 A2=1.5

Why: the CFD's derivatives carry uncertainties that differ by derivative (docs/aero.md: with SST the thin
plate's A2* differs by tens of per cent between our code and OpenFOAM's, its H1* by a point or two).  What
a user needs to know is what such a difference does to the critical wind speed.  This tool runs the
scenario's stages as ``python -m bridge.scenario`` does (from the stage cache when their inputs are
unchanged: pass the ``.cache`` of an earlier run to reuse its aerodynamics), takes the flutter stage's modes,
air density and aerodynamic model, and solves the two-mode determinant problem of every mode pair again with
one derivative scaled at every reduced frequency, all others unchanged
(:func:`bridge.flutter.derivatives.scale_derivative`).  It prints V_c and f_c of the governing pair for
each derivative and factor, and the elasticity d ln V_c / d ln X from the factors nearest 1;
``--together`` scales several derivatives at once (a set of differences seen elsewhere, e.g. between two
codes; a factor may be negative, for a derivative whose sign differs) and gives that V_c too.  The lateral
modes and the multimode p-k are left out (the flutter stage's report gives them for the unscaled model).

Writes ``--out`` (default out/flutter_sensitivity/<scenario>.json).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.config import load_scenario  # noqa: E402
from bridge.errors import ConvergenceError, InputError  # noqa: E402
from bridge.files import atomic_write_text  # noqa: E402
from bridge.flutter.derivatives import DERIVATIVE_NAMES, scale_derivative  # noqa: E402
from bridge.flutter.determinant import governing, solve_pair  # noqa: E402
from bridge.flutter.options import FlutterOptions  # noqa: E402
from bridge.flutter.stage import options_and_aerodynamics  # noqa: E402
from bridge.pipeline import run_stages  # noqa: E402
from bridge.results import json_value  # noqa: E402
from bridge.stages import RunOptions  # noqa: E402

VERTICAL_TORSIONAL = ("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4")


@dataclass(frozen=True)
class Scaled:
    """An aerodynamic model with one of Scanlan's derivatives times ``factor`` (the rest as ``base``'s)."""

    base: object
    derivative: str
    factor: float

    @property
    def name(self) -> str:
        return f"{self.base.name} with {self.derivative}* x {self.factor:g}"

    @property
    def provides(self):
        return getattr(self.base, "provides", ("h_pu", "h_ptheta", "h_mu", "h_mtheta"))

    @property
    def omega_range(self):
        return self.base.omega_range

    @property
    def speed_range(self):
        return self.base.speed_range

    def frf(self, omega, speed):
        return scale_derivative(self.base.frf(omega, speed), self.derivative, self.factor)


def critical(modal, aero, rho: float, fopts: FlutterOptions) -> tuple[float, float, str]:
    """V_c [m/s], f_c [Hz] and the name of the governing pair of the two-mode determinant method."""
    results = [solve_pair(modal.subset(p), aero, rho, fopts.max_speed_m_s, min_speed_m_s=fopts.min_speed_m_s,
                          n_speed=fopts.speed_steps) for p in modal.pairs(fopts.pairs)]
    gov = governing(results)
    if gov is None:
        return math.nan, math.nan, "none"
    return gov.critical_speed_m_s, gov.frequency_hz, "+".join(gov.pair)


def elasticity(factors: list[float], speeds: list[float], base_speed: float) -> float:
    """d ln V_c / d ln X from the two factors nearest 1 on either side (a central difference in ln X), or
    from the one nearest 1 against the unscaled model."""
    logs = [(math.log(f), math.log(v / base_speed)) for f, v in zip(factors, speeds, strict=True)
            if f > 0 and v > 0 and math.isfinite(v)]
    below = max((p for p in logs if p[0] < 0), default=None)
    above = min((p for p in logs if p[0] > 0), default=None)
    if below and above:
        return (above[1] - below[1]) / (above[0] - below[0])
    one = below or above
    return one[1] / one[0] if one else math.nan


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario", help="a shipped scenario's name or a scenario file")
    ap.add_argument("--derivatives", nargs="+", default=["H1", "H2", "H3", "A1", "A2", "A3"],
                    help="Scanlan's derivatives to scale, without the star (default H1 H2 H3 A1 A2 A3)")
    ap.add_argument("--factors", nargs="+", type=float, default=[0.5, 0.8, 1.25, 1.5],
                    help="factors applied to each, one at a time (default 0.5 0.8 1.25 1.5)")
    ap.add_argument("--together", nargs="+", default=[], metavar="NAME=FACTOR",
                    help="also scale these derivatives all at once (e.g. H3=1.1 A2=1.5; a negative factor turns "
                         "a derivative's sign, as H2* of a deck may between grids or codes)")
    ap.add_argument("--quality", choices=("tiny", "quick", "standard", "fine"), default=None,
                    help="the aero stage's CFD preset, for scenarios with CFD aerodynamics (default the "
                         "scenario's)")
    ap.add_argument("--cache", type=Path, default=Path("out") / ".cache",
                    help="stage cache to read and fill (default out/.cache, as python -m bridge.scenario)")
    ap.add_argument("--out", type=Path, default=None, help="JSON written (default out/flutter_sensitivity/<name>.json)")
    args = ap.parse_args(argv)
    for name in args.derivatives:
        if name not in VERTICAL_TORSIONAL:
            ap.error(f"--derivatives: {name!r} is not one of {', '.join(VERTICAL_TORSIONAL)} (the lateral "
                     f"{', '.join(n for n in DERIVATIVE_NAMES if n not in VERTICAL_TORSIONAL)} act only with "
                     "lateral modes, which this tool leaves out)")
    for f in args.factors:
        if not (math.isfinite(f) and 0.0 <= f <= 10.0) or f == 1.0:
            ap.error(f"--factors: each must be in [0, 10] and not 1 (the unscaled model is always run), got {f:g}")
    together = {}
    for item in args.together:
        name, _, value = item.partition("=")
        try:
            factor = float(value)
        except ValueError:
            factor = math.nan
        if name not in VERTICAL_TORSIONAL or not (math.isfinite(factor) and -10.0 <= factor <= 10.0):
            ap.error(f"--together: {item!r} must be NAME=FACTOR with NAME one of {', '.join(VERTICAL_TORSIONAL)} "
                     "and FACTOR in [-10, 10]")
        together[name] = factor
    args.together = together
    try:
        return _run(args)
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except ConvergenceError as err:
        print(f"error: {err}", file=sys.stderr)
        return 3


def _run(args) -> int:
    scenario = load_scenario(args.scenario)
    options = RunOptions(progress=lambda m: print(m, flush=True), cache=args.cache, quality=args.quality)
    outputs = run_stages(scenario, ["flutter"], options)
    flutter = outputs["flutter"].data
    fopts, aero = options_and_aerodynamics(scenario, outputs)    # as the flutter stage built them
    modal, rho = flutter.modal_model, flutter.air_density_kg_m3

    v0, f0, pair0 = critical(modal, aero, rho, fopts)
    print(f"{scenario.name}: {aero.name} aerodynamics, V_c {v0:.2f} m/s, f_c {f0:.4f} Hz ({pair0}), "
          f"two-mode determinant without lateral modes")
    rows = []
    header = f"{'derivative':>10} " + " ".join(f"{'x' + format(f, 'g'):>16}" for f in args.factors)
    print(header + f" {'dlnVc/dlnX':>11}")
    for name in args.derivatives:
        speeds, cells = [], []
        for f in args.factors:
            v, fc, pair = critical(modal, Scaled(aero, name, f), rho, fopts)
            speeds.append(v)
            cells.append({"factor": f, "critical_speed_m_s": v, "frequency_hz": fc, "pair": pair,
                          "relative_change": v / v0 - 1.0})
        e = elasticity(args.factors, speeds, v0)
        rows.append({"derivative": name, "runs": cells, "elasticity": e})
        print(f"{name + '*':>10} " + " ".join(f"{v:7.2f} ({100 * (v / v0 - 1):+5.1f}%)" for v in speeds)
              + f" {e:11.3f}")

    combined = None
    if args.together:
        model = aero
        for name, f in args.together.items():
            model = Scaled(model, name, f)
        v, fc, pair = critical(modal, model, rho, fopts)
        combined = {"factors": args.together, "critical_speed_m_s": v, "frequency_hz": fc, "pair": pair,
                    "relative_change": v / v0 - 1.0}
        print(f"together ({', '.join(f'{n}* x {f:g}' for n, f in args.together.items())}): V_c {v:.2f} m/s "
              f"({100 * (v / v0 - 1):+.1f} %), f_c {fc:.4f} Hz ({pair})")

    out = args.out or Path("out") / "flutter_sensitivity" / f"{scenario.name}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, json.dumps(json_value({
        "scenario": scenario.name, "aerodynamics": aero.name, "air_density_kg_m3": rho,
        "method": "two-mode determinant, every pair of flutter.pairs, without lateral modes",
        "unscaled": {"critical_speed_m_s": v0, "frequency_hz": f0, "pair": pair0},
        "derivatives": rows, "together": combined}), indent=1, allow_nan=False))
    print(f"written {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
