"""Pipeline stage ``fem``: 3D FEM eigen analysis of the bridge (thesis chapter 3).

``run(scenario, upstream, options)`` needs ``upstream["cable"].data`` (the CableSolution).
``options.quick``: 2 elements per hanger panel and 30 modes (tests, smoke runs); otherwise
DEFAULT_ELEMENTS_PER_PANEL and DEFAULT_N_MODES of :mod:`.analysis`.
HDF5 datasets of the ``fem`` group: docs/results.md, section ``/fem``.
"""

from __future__ import annotations

import numpy as np

from ..config import Scenario
from ..errors import InputError
from ..results import write_dataset
from ..stages import RunOptions, StageOutput
from .analysis import DEFAULT_ELEMENTS_PER_PANEL, DEFAULT_N_MODES, FemResult, analyse
from .modes import ModeSet
from .plots import fem_figures

__all__ = ["run", "fem_summary", "fem_report", "match_reference", "write_h5", "THESIS_TABLE_3_5", "THESIS_TABLE_3_6"]

# Reference numbers for the report only (never used in a computation).
# Table 3.5: the thesis's ABAQUS eigenfrequencies (symmetry, Hz), modes 1-9.
THESIS_TABLE_3_5 = {
    "great_belt": [("S", 0.128), ("SS", 0.174), ("S", 0.216), ("SS", 0.269), ("S", 0.294), ("SS", 0.306),
                   ("S", 0.331), ("SS", 0.387), ("S", 0.438)],
    "model_a": [("S", 0.113), ("SS", 0.151), ("S", 0.187), ("S", 0.243), ("SS", 0.277), ("S", 0.318),
                ("SS", 0.323), ("SS", 0.361), ("S", 0.390)],
    "model_b": [("S", 0.090), ("SS", 0.119), ("S", 0.129), ("SS", 0.148), ("SS", 0.180), ("SS", 0.183),
                ("S", 0.215), ("S", 0.217), ("SS", 0.242)],
    "model_c": [("S", 0.078), ("S", 0.083), ("SS", 0.103), ("SS", 0.115), ("S", 0.128), ("SS", 0.156),
                ("S", 0.171), ("S", 0.185), ("SS", 0.211)],
}
# Table 3.6: a_jj, a_kk, a_jk for j1 (first symmetric bending) and k1 (first symmetric torsional).
THESIS_TABLE_3_6 = {"great_belt": (0.308, 0.239, 0.038), "model_c": (0.345, 0.161, 0.178)}


def fem_summary(r: FemResult) -> dict[str, float | int | str]:
    m = r.modes
    out: dict[str, float | int | str] = {
        "fem.n_modes": len(m.labels), "fem.n_dof": r.n_dof, "fem.n_elements": r.model.n_elements,
        "fem.elements_per_panel": r.model.n_sub,
        "fem.hanger_weight_residual": float(r.model.hanger_weight_residual),
        "fem.cable_node_residual_N": float(r.model.cable_node_residual_N),
    }
    for lab in ("S-V1", "SS-V1", "S-V2", "S-T1", "SS-T1", "S-L1", "SS-L1"):
        if lab in m.labels:
            out[f"fem.frequency_{lab.replace('-', '_')}_hz"] = r.frequency(lab)
    pairs = [p for p in m.pair_integrals() if p["symmetry"] == "S"]
    if pairs:
        p = pairs[0]
        out.update({"fem.a_jj": p["a_jj"], "fem.a_kk": p["a_kk"], "fem.a_jk": p["a_jk"]})
    return out


# Modes listed in the report's mode table beyond the vertical and torsional ones: lateral modes among
# the first FIRST_MODES (no reference row exists for them; they show where the references skip modes).
FIRST_MODES = 12


# Reference rows whose mode type the thesis states (1-based row -> kind).  Table 3.5, Great Belt: Figs
# 3.3-3.6 show rows 1, 3, 7 as the first three symmetric bending modes and row 5 as the first symmetric
# torsional mode.  Table 3.4 (measured) states no type; its rows 1-5 pair one to one with Table 3.5's
# rows 1-5 (the same symmetries, frequencies within 11 %), so rows 1, 3 are vertical and row 5 torsional
# (the thesis's two-mode case takes its damping for the first bending and torsional modes from rows 1, 5).
REFERENCE_KINDS = {
    "table_3_4": {1: "vertical", 3: "vertical", 5: "torsional"},
    "table_3_5_great_belt": {1: "vertical", 3: "vertical", 5: "torsional", 7: "vertical"},
}


def match_reference(modes: ModeSet, rows: list[tuple[str, float]], kinds: dict[int, str] | None = None,
                    tolerance: float = 0.15) -> dict[int, tuple[int, str, float]]:
    """Model mode index -> (1-based row, symmetry, f [Hz]) of a thesis table of (symmetry, f) rows.

    The tables list deck vertical and torsional modes with their symmetry and frequency; the type is
    known only for some rows (``kinds``: row -> "vertical" | "torsional", see REFERENCE_KINDS).  Rule:
    a row of known type takes the n-th model mode of that type and symmetry (n: its rank among the rows
    of that type and symmetry); every other row takes, in row order, the vertical or torsional model
    mode of its symmetry nearest in frequency among those not yet matched, if that lies within
    ``tolerance`` (relative) of the row's frequency - else the row stays unmatched.  Lateral,
    longitudinal and cable modes get no row.
    """
    kinds = kinds or {}
    out: dict[int, tuple[int, str, float]] = {}
    for sym in ("S", "SS"):
        refs = [(n + 1, f) for n, (s, f) in enumerate(rows) if s == sym]
        for kind in ("vertical", "torsional"):
            model = [i for i in range(len(modes.labels)) if modes.symmetries[i] == sym and modes.kinds[i] == kind]
            typed = [(n, f) for n, f in refs if kinds.get(n) == kind]
            out.update({i: (n, sym, f) for i, (n, f) in zip(model, typed, strict=False)})
        free = [i for i in range(len(modes.labels)) if modes.symmetries[i] == sym and i not in out
                and modes.kinds[i] in ("vertical", "torsional")]
        for n, f in refs:
            if n in kinds or not free:
                continue
            i = min(free, key=lambda j: abs(float(modes.frequencies_hz[j]) - f))
            if abs(float(modes.frequencies_hz[i]) - f) <= tolerance * f:
                out[i] = (n, sym, f)
                free.remove(i)
    return out


def _reference_cell(f_model: float, row: tuple[int, str, float] | None) -> str:
    if row is None:
        return "-"                                # no row of the table went to this mode
    n, sym, f = row
    return f"{n}: {sym} {f:.3f} ({100.0 * (f_model - f) / f:+.1f} %)"


def fem_report(r: FemResult) -> str:
    m, s = r.modes, r.scenario
    measured = [(d.symmetry, d.frequency_hz) for d in s.damping] if s.reference_name is None else []
    abaqus = THESIS_TABLE_3_5.get(s.name, [])
    to_measured = match_reference(m, measured, REFERENCE_KINDS["table_3_4"])
    to_abaqus = match_reference(m, abaqus, REFERENCE_KINDS.get(f"table_3_5_{s.name}"))
    shown = [i for i in range(len(m.labels))
             if m.kinds[i] in ("vertical", "torsional") or (m.kinds[i] == "lateral" and i < FIRST_MODES)]
    lines = [
        "## Structural dynamics: 3D FEM eigen analysis (thesis chapter 3)", "",
        f"{r.model.n_elements} elements, {r.n_dof} DOFs, {r.model.n_sub} elements per hanger panel; "
        f"hanger tensions balance the girder weight to {r.model.hanger_weight_residual:.1e} (relative), "
        f"largest cable-node imbalance {r.model.cable_node_residual_N:.1e} N.", "",
        "Mode table: every vertical and torsional mode of the model (the modes the flutter stage uses), and "
        f"the lateral modes among the first {FIRST_MODES}; mode = number in ascending frequency of all "
        f"{len(m.labels)} modes computed.  Thesis Table 3.4 (measured) and Table 3.5 (ABAQUS) list deck "
        "vertical and torsional modes by symmetry and frequency; where the thesis states a row's type "
        "(Table 3.5, Great Belt: rows 1, 3, 7 vertical and 5 torsional, Figs 3.3-3.6; Table 3.4: rows 1, 3 "
        "vertical and 5 torsional, paired one to one with Table 3.5's rows 1-5), the row takes the model "
        "mode of that type and symmetry of the same rank; every other row takes the unmatched vertical or "
        "torsional mode of its symmetry nearest in frequency, if within 15 % (cell: row number: symmetry, "
        "f [Hz], model minus reference in %; '-': no row of the table is matched to this mode; rows left "
        "unmatched are listed below the table).  Lateral, longitudinal and cable modes have no reference row"
        + ("" if measured else "; Table 3.4 was measured on the Great Belt only") + ".  zeta is the "
        "Table 3.4 ratio of the measured mode of the same symmetry nearest in frequency "
        "(bridge.structure.modes.assign_damping), not necessarily that of the matched row.", "",
        "| mode | label | f [Hz] | deck energy V/T/L/Z | zeta | Table 3.4 measured | Table 3.5 ABAQUS |",
        "|---|---|---|---|---|---|---|",
    ]
    for i in shown:
        e = "/".join(f"{x:.2f}" for x in m.energy_shares[i])
        f = float(m.frequencies_hz[i])
        if m.kinds[i] == "lateral":
            meas = aba = "none (lateral)"
        else:
            meas = _reference_cell(f, to_measured.get(i)) if measured else "n/a"
            aba = _reference_cell(f, to_abaqus.get(i)) if abaqus else "n/a"
        lines.append(f"| {i + 1} | {m.labels[i]} | {f:.4f} | {e} | {m.damping_ratios[i]:.4f} | {meas} | {aba} |")
    for title, rows, matched in (("Table 3.4", measured, to_measured), ("Table 3.5", abaqus, to_abaqus)):
        used = {row[0] for row in matched.values()}
        left = [f"{n}: {sym} {f:.3f}" for n, (sym, f) in enumerate(rows, start=1) if n not in used]
        if left:
            lines += ["", f"{title} rows with no model mode matched: {', '.join(left)}."]
    lines += ["", "Modal integrals (Eq 4.34, whole deck length L = main + side spans):", "",
              "| j | k | a_jj | a_kk | a_jk | Table 3.6 (j1, k1) |", "|---|---|---|---|---|---|"]
    ref = THESIS_TABLE_3_6.get(s.name)
    for n, p in enumerate(m.pair_integrals()):
        t = f"{ref[0]:.3f} / {ref[1]:.3f} / {ref[2]:.3f}" if (ref and n == 0) else ""
        lines.append(f"| {p['j']} | {p['k']} | {p['a_jj']:.3f} | {p['a_kk']:.3f} | {p['a_jk']:.3f} | {t} |")
    return "\n".join(lines)


def run(scenario: Scenario, upstream: dict, options: RunOptions) -> StageOutput:
    if scenario.kind != "suspension_bridge":
        raise InputError("stages", "fem", f"the fem stage needs a suspension bridge, not kind {scenario.kind!r}")
    if "cable" not in upstream:
        raise InputError("stages", "fem", "needs the cable stage first")
    cables = upstream["cable"].data
    n_sub = 2 if options.quick else DEFAULT_ELEMENTS_PER_PANEL
    n_modes = 30 if options.quick else DEFAULT_N_MODES
    options.say(f"[{scenario.name}] fem: model, Warp assembly, {n_modes} modes ({n_sub} elements per panel)")
    r = analyse(scenario, cables, elements_per_panel=n_sub, n_modes=n_modes)
    options.say(f"[{scenario.name}] fem: {r.n_dof} DOFs, S-V1 "
                f"{r.frequency('S-V1') if 'S-V1' in r.labels else float('nan'):.4f} Hz")
    return StageOutput(summary=fem_summary(r), write_h5=lambda grp: write_h5(grp, r), report=fem_report(r),
                       figures=fem_figures(r), data=r)


def _text(group, name: str, values, description: str) -> None:
    """Text as fixed-length ASCII bytes (``S``), as docs/results.md documents for ``/fem``."""
    write_dataset(group, name, np.array(list(values), dtype="S"), "", description)


def write_h5(grp, r: FemResult) -> None:
    """Fill ``results.h5:/fem``: every dataset through ``write_dataset`` with its unit and description.

    N = modes in ascending frequency, N_z = girder nodes in ascending z.  Mode shapes are the normalised
    shapes of Eq 4.31-4.32 (dimensionless; the modal coordinate carries the unit: m for vertical,
    lateral, longitudinal and cable modes, rad for torsional modes).
    """
    m = r.modes
    n, nz = len(m.labels), len(m.z_m)
    grp.attrs["n_dof"] = r.n_dof
    grp.attrs["n_elements"] = r.model.n_elements
    grp.attrs["elements_per_panel"] = r.model.n_sub
    grp.attrs["deck_length_m"] = r.model.deck_length_m
    grp.attrs["mid_span_z_m"] = r.model.mid_span_z_m
    grp.attrs["hanger_weight_residual"] = r.model.hanger_weight_residual
    grp.attrs["cable_node_residual_N"] = r.model.cable_node_residual_N
    write_dataset(grp, "frequencies_hz", m.frequencies_hz, "Hz", f"undamped eigenfrequencies, ({n},) ascending")
    _text(grp, "labels", m.labels, f"({n},) mode labels <symmetry>-<kind letter><count>, e.g. S-V1, SS-T1 "
          "(V vertical, T torsional, L lateral, Z longitudinal, C cable)")
    _text(grp, "kinds", m.kinds, f"({n},) vertical / torsional / lateral / longitudinal / cable, from the "
          "deck kinetic energy shares (docs/structure.md)")
    _text(grp, "symmetries", m.symmetries, f"({n},) S (symmetric) or SS (skew-symmetric) about mid-span")
    write_dataset(grp, "modal_masses", m.modal_masses, "kg or kg m^2",
                  f"({n},) phi^T M phi of the normalised 3D mode: kg where the modal coordinate is a "
                  "displacement (vertical, lateral, longitudinal, cable modes), kg m^2 for torsional modes")
    write_dataset(grp, "damping_ratios", m.damping_ratios, "1",
                  f"({n},) structural damping ratio: Table 3.4 ratio of the measured mode of the same "
                  "symmetry nearest in frequency")
    write_dataset(grp, "energy_shares", m.energy_shares, "1",
                  f"({n}, 4) shares of the deck kinetic energy: vertical, torsional, lateral, longitudinal")
    write_dataset(grp, "girder_energy_share", m.deck_share, "1",
                  f"({n},) deck kinetic energy (mu, J of Eq 4.7) / total modal kinetic energy")
    write_dataset(grp, "z_m", m.z_m, "m", f"({nz},) girder node positions, 0 at the left girder end")
    for name, what in (("U", "vertical deck displacement u_y; vertical modes max U = 1 (Eq 4.31)"),
                       ("Theta", "deck torsion theta_z; torsional modes max Theta = 1 (Eq 4.32)"),
                       ("V", "lateral deck displacement u_x; lateral modes max V = 1"),
                       ("W", "longitudinal deck displacement u_z; longitudinal modes max W = 1")):
        write_dataset(grp, name, getattr(m, name), "1",
                      f"({n}, {nz}) [mode, girder node] {what}; per unit modal coordinate (m, or rad for "
                      "torsional modes)")
    for name, what in (("uu", "U_i U_j"), ("ut", "U_i Theta_j"), ("tt", "Theta_i Theta_j")):
        write_dataset(grp, name, getattr(m, name), "1",
                      f"({n}, {n}) (1/L) int {what} dz over the whole deck length L (Eq 4.34 for all pairs)")
    pairs = m.pair_integrals()
    pg = grp.create_group("pairs")
    _text(pg, "j", [p["j"] for p in pairs], "(P,) bending mode of each pair: first three vertical modes of "
          "each symmetry")
    _text(pg, "k", [p["k"] for p in pairs], "(P,) torsional mode of each pair: first torsional mode of the "
          "bending mode's symmetry")
    for key, what in (("a_jj", "(1/L) int U_j^2 dz"), ("a_kk", "(1/L) int Theta_k^2 dz"),
                      ("a_jk", "(1/L) int U_j Theta_k dz")):
        write_dataset(pg, key, np.array([p[key] for p in pairs], dtype=np.float64), "1",
                      f"(P,) {key} = {what} of each pair (Eq 4.34, Table 3.6)")
    write_dataset(grp, "hanger_tension_N", r.model.hanger_tension_N, "N",
                  f"({len(r.model.hanger_tension_N)},) dead-load tension of each hanger of one cable plane, "
                  "ascending z")
