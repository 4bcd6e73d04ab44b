"""Pipeline stage ``fem``: 3D FEM eigen analysis of the bridge (thesis chapter 3).

``run(scenario, upstream, options)`` needs ``upstream["cable"].data`` (the CableSolution).
``options.quick``: 2 elements per hanger panel and 30 modes (tests, smoke runs); otherwise
DEFAULT_ELEMENTS_PER_PANEL and DEFAULT_N_MODES of :mod:`.analysis`.
HDF5 datasets of the ``fem`` group: docs/results_fem.md.
"""

from __future__ import annotations

import numpy as np

from ..config import Scenario
from ..errors import InputError
from ..stages import RunOptions, StageOutput
from .analysis import DEFAULT_ELEMENTS_PER_PANEL, DEFAULT_N_MODES, FemResult, analyse
from .plots import fem_figures

__all__ = ["run", "fem_summary", "fem_report", "THESIS_TABLE_3_5", "THESIS_TABLE_3_6"]

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


def fem_report(r: FemResult) -> str:
    m, s = r.modes, r.scenario
    measured = [(d.symmetry, d.frequency_hz) for d in s.damping] if s.reference_name is None else []
    abaqus = THESIS_TABLE_3_5.get(s.name, [])
    lines = [
        "## Structural dynamics: 3D FEM eigen analysis (thesis chapter 3)", "",
        f"{r.model.n_elements} elements, {r.n_dof} DOFs, {r.model.n_sub} elements per hanger panel; "
        f"hanger tensions balance the girder weight to {r.model.hanger_weight_residual:.1e} (relative), "
        f"largest cable-node imbalance {r.model.cable_node_residual_N:.1e} N.", "",
        "| mode | label | f [Hz] | deck energy V/T/L/Z | zeta | Table 3.4 measured | Table 3.5 ABAQUS |",
        "|---|---|---|---|---|---|---|",
    ]
    for i in range(min(12, len(m.labels))):
        e = "/".join(f"{x:.2f}" for x in m.energy_shares[i])
        meas = f"{measured[i][0]} {measured[i][1]:.3f}" if i < len(measured) else ""
        aba = f"{abaqus[i][0]} {abaqus[i][1]:.3f}" if i < len(abaqus) else ""
        lines.append(f"| {i + 1} | {m.labels[i]} | {m.frequencies_hz[i]:.4f} | {e} | {m.damping_ratios[i]:.4f} "
                     f"| {meas} | {aba} |")
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

    def write_h5(grp) -> None:
        m = r.modes
        grp.attrs["n_dof"] = r.n_dof
        grp.attrs["n_elements"] = r.model.n_elements
        grp.attrs["elements_per_panel"] = r.model.n_sub
        grp.attrs["deck_length_m"] = r.model.deck_length_m
        grp.attrs["mid_span_z_m"] = r.model.mid_span_z_m
        grp.attrs["hanger_weight_residual"] = r.model.hanger_weight_residual
        grp.attrs["cable_node_residual_N"] = r.model.cable_node_residual_N
        grp.create_dataset("frequencies_hz", data=m.frequencies_hz)
        for name in ("labels", "kinds", "symmetries"):
            grp.create_dataset(name, data=np.array(getattr(m, name), dtype="S"))
        grp.create_dataset("modal_masses", data=m.modal_masses)
        grp.create_dataset("damping_ratios", data=m.damping_ratios)
        grp.create_dataset("energy_shares", data=m.energy_shares)
        grp.create_dataset("girder_energy_share", data=m.deck_share)
        grp.create_dataset("z_m", data=m.z_m)
        for name in ("U", "Theta", "V", "W"):
            grp.create_dataset(name, data=getattr(m, name))
        grp.create_dataset("uu", data=m.uu)
        grp.create_dataset("ut", data=m.ut)
        grp.create_dataset("tt", data=m.tt)
        pairs = m.pair_integrals()
        pg = grp.create_group("pairs")
        pg.create_dataset("j", data=np.array([p["j"] for p in pairs], dtype="S"))
        pg.create_dataset("k", data=np.array([p["k"] for p in pairs], dtype="S"))
        for key in ("a_jj", "a_kk", "a_jk"):
            pg.create_dataset(key, data=np.array([p[key] for p in pairs], dtype=np.float64))
        grp.create_dataset("hanger_tension_N", data=r.model.hanger_tension_N)

    return StageOutput(summary=fem_summary(r), write_h5=write_h5, report=fem_report(r),
                       figures=fem_figures(r), data=r)
