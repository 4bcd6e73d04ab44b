"""How much the flutter speed moves with each ASSUMED dimension of the deck's outline.

    python tools/outline_sensitivity.py great_belt_body_fitted
    python tools/outline_sensitivity.py great_belt_body_fitted --change nose_height_fraction=0.7 cross_fall=0.0

Why: the Great Belt box's chord and depth are published, its other dimensions are not (bridge/cfd/sections.py,
``StreamlinedBox``: cross-fall, flat bottom, nose height, flat roof are ASSUMED).  A user needs to know which
drawing dimension the critical wind speed depends on before trusting, or correcting, the outline.  For each
``--change FIELD=VALUE`` (default: one plausible alternative for every ASSUMED field, :data:`DEFAULT_CHANGES`)
this tool runs the scenario's stages again with that one field of the deck's outline changed (the aero stage's
CFD and the flutter stage, as ``python -m bridge.scenario`` does, through the stage cache: the unchanged
outline's aerodynamics, and the structure's stages, are computed once) and prints a table: V_c, f_c and the
governing pair, the multimode V_c, the change of V_c against the unchanged outline, and the static
coefficients at zero incidence.  Each changed outline costs one aero stage (about 10 minutes for
``great_belt_body_fitted`` on two cores).

The grid error of each V_c is the preset's, shared in large part by outlines this close to each other; the
changed outlines are not the Great Belt deck that the preset's grid study covers, so their headlines say none
covers them.  Railings (also ASSUMED) are not in the default set: the body-fitted pair does not resolve them
yet, and on the overset pair's ``quick`` grid a 0.2 m strip covers a few faces and feels no drag.

Writes ``--out`` (default out/outline_sensitivity/<scenario>.json) and prints the table (Markdown).  Exit status:
0 done; 1 an outline could not be computed (its row says why; the others are kept); 2 bad input, nothing run.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.config import load_scenario  # noqa: E402
from bridge.errors import ConvergenceError, InputError  # noqa: E402
from bridge.files import atomic_write_text  # noqa: E402
from bridge.pipeline import run_stages, wants_cfd  # noqa: E402
from bridge.stages import RunOptions  # noqa: E402

# one plausible alternative for each ASSUMED dimension of the Great Belt box (defaults in brackets): a flat roof
# instead of a 2 % cross-fall [0.02]; a narrower flat bottom, so longer inclined panels [0.6]; the nose lower on
# the edge line [0.8]; a narrower flat roof, so longer upper fairing panels [0.9]
DEFAULT_CHANGES = {"cross_fall": 0.0, "bottom_flat_fraction": 0.5, "nose_height_fraction": 0.7,
                   "top_flat_fraction": 0.8}

KEYS = ("flutter.critical_speed_m_s", "flutter.frequency_hz", "flutter.mode_pair",
        "flutter.multimode_critical_speed_m_s", "aero.static.drag_coefficient", "aero.static.lift_coefficient",
        "aero.static.moment_coefficient", "aero.cfd_wall_s")


def _parse_changes(items: list[str]) -> dict[str, float]:
    out = {}
    for item in items:
        name, _, value = item.partition("=")
        if name not in DEFAULT_CHANGES or not value:
            raise InputError("--change", item, "FIELD=VALUE with FIELD one of the outline's ASSUMED dimensions: "
                             + ", ".join(DEFAULT_CHANGES))
        if name in out:
            raise InputError("--change", item, f"{name} is given twice: one value each")
        try:
            out[name] = float(value)
        except ValueError:
            raise InputError("--change", item, "VALUE must be a number") from None
    return out


def _outline(scenario):
    if not wants_cfd(scenario):
        raise InputError("scenario", scenario.name, "its flutter stage must take the deck's aerodynamics from the "
                         "CFD ([flutter] aerodynamics = \"cfd\"): else the outline changes nothing")
    section = scenario.deck_section
    if section is None:
        from bridge.cfd.sections import great_belt_section

        section = great_belt_section()
    if not hasattr(section, "nose_height_fraction"):
        raise InputError("scenario", scenario.name, "its deck section must be the streamlined box "
                         "(bridge/cfd/sections.py, StreamlinedBox) whose dimensions this tool changes")
    return section


def _row(label: str, outputs) -> dict:
    summary = {}
    for out in outputs.values():
        summary.update(out.summary)
    return {"change": label, **{k: summary.get(k) for k in KEYS}}


def _num(row: dict, key: str, fmt: str) -> str:
    v = row[key]
    return "none" if v is None else format(v, fmt)


def _table(rows: list[dict]) -> str:
    base = rows[0]["flutter.critical_speed_m_s"]
    lines = ["| outline | V_c [m/s] | change | f_c [Hz] | pair | multimode V_c [m/s] | C_D | C_L | C_M |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("error"):
            lines.append(f"| {r['change']} | not computed: {r['error']} | | | | | | | |")
            continue
        vc = r["flutter.critical_speed_m_s"]
        change = "" if r is rows[0] or vc is None or base is None else f"{100 * (vc / base - 1):+.1f} %"
        cells = [r["change"], _num(r, "flutter.critical_speed_m_s", ".1f"), change,
                 _num(r, "flutter.frequency_hz", ".4f"), str(r["flutter.mode_pair"]),
                 _num(r, "flutter.multimode_critical_speed_m_s", ".1f"),
                 *(_num(r, f"aero.static.{c}_coefficient", ".3f") for c in ("drag", "lift", "moment"))]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario", help="a shipped scenario's name or a scenario file whose deck is the streamlined box")
    ap.add_argument("--change", nargs="+", default=None, metavar="FIELD=VALUE",
                    help="outline fields to change, one at a time (default: "
                         + " ".join(f"{k}={v:g}" for k, v in DEFAULT_CHANGES.items()) + ")")
    ap.add_argument("--cache", type=Path, default=Path("out") / ".cache",
                    help="stage cache to read and fill (default out/.cache, as python -m bridge.scenario)")
    ap.add_argument("--out", type=Path, default=None,
                    help="JSON written (default out/outline_sensitivity/<scenario>.json)")
    args = ap.parse_args(argv)
    try:
        scenario = load_scenario(args.scenario)
        section = _outline(scenario)
        changes = _parse_changes(args.change) if args.change else dict(DEFAULT_CHANGES)
        variants = [(f"{k} {getattr(section, k):g} -> {v:g}", replace(section, **{k: v})) for k, v in changes.items()]
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    options = RunOptions(progress=lambda m: print(m, flush=True), cache=args.cache)
    try:
        rows = [_row("as assumed", run_stages(scenario, ["flutter"], options))]
    except (InputError, ConvergenceError) as err:
        print(f"error: the outline as assumed: {err}", file=sys.stderr)
        return 1
    for i, (label, outline) in enumerate(variants, 1):
        print(f"outline {i}/{len(variants)}: {label}", flush=True)
        try:
            rows.append(_row(label, run_stages(replace(scenario, deck_section=outline), ["flutter"], options)))
        except Exception as err:   # e.g. an outline the O-grid cannot mesh: said, and on to the next
            why = str(err) if isinstance(err, (InputError, ConvergenceError)) else f"{type(err).__name__}: {err}"
            print(f"outline {label}: not computed: {why}", flush=True)
            rows.append({"change": label, "error": why, **{k: None for k in KEYS}})
    table = _table(rows)
    print(table)
    out = args.out or Path("out") / "outline_sensitivity" / f"{scenario.name}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    clean = [{k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()} for r in rows]
    command = " ".join(sys.argv[1:] if argv is None else argv)
    atomic_write_text(out, json.dumps({"command": "python tools/outline_sensitivity.py " + command,
                                       "rows": clean, "table": table}, indent=1))
    print(f"written {out}")
    return 1 if any(r.get("error") for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
