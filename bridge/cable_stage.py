"""Pipeline stage ``cable``: up-scaling figures (Tables 1.1, 1.2, 3.6 mu and J) and cable statics (ch. 2)."""

from __future__ import annotations

from .cable import CableSolution, solve_cables
from .config import Scenario
from .errors import InputError
from .results import write_dataset
from .stages import RunOptions, StageOutput

__all__ = ["run", "cable_summary", "cable_figures"]


def cable_summary(s: Scenario, c: CableSolution) -> dict[str, float | int | str]:
    """Headline numbers with units in the key names."""
    g = s.geometry
    return {
        "scenario.main_span_m": g.main_span_m,
        "scenario.side_span_m": g.side_span_m,
        "scenario.sag_m": g.sag_m,
        "scenario.pylon_height_m": g.pylon_height_m,
        "scenario.extra_cross_beams": s.pylon.extra_cross_beams,
        "scenario.pylon_leg_inertia_ratio": s.pylon_inertia_ratio,
        "scenario.deck_mass_per_length_kg_m": s.deck_mass_per_length_kg_m,
        "scenario.deck_inertia_per_length_kg_m2_m": s.deck_inertia_per_length_kg_m2_m,
        "cable.area_m2": s.cable.area_m2,
        "cable.mass_per_length_main_kg_m": s.cable.mass_per_length_main_kg_m,
        "cable.mass_per_length_side_kg_m": s.cable.mass_per_length_side_kg_m,
        "cable.horizontal_force_per_cable_N": c.horizontal_force_per_cable_N,
        "cable.horizontal_force_total_N": c.horizontal_force_total_N,
        "cable.horizontal_force_parabolic_total_N": c.parabolic_estimate_total_N,
        "cable.stress_at_pylon_Pa": c.cable_stress_Pa(s.cable.area_m2),
        "cable.stress_eq_1_1_Pa": c.horizontal_force_total_N / (2 * s.cable.area_m2),
        "cable.main_span_length_m": c.main_cable_length_m,
        "cable.side_span_length_m": c.side_cable_length_m,
        "cable.anchor_slope": c.anchor_slope,
        "cable.vertical_reaction_pylon_per_cable_N": c.v_pylon_per_cable_N,
        "cable.vertical_reaction_anchor_per_cable_N": c.v_anchor_per_cable_N,
        "cable.hanger_count_per_cable": int(len(c.hanger_z_m)),
        "cable.hanger_spacing_main_m": c.main_panel_m,
        "cable.hanger_spacing_side_m": c.side_panel_m,
        "cable.hanger_length_min_m": float(c.hanger_length_m.min()),
        "cable.hanger_length_max_m": float(c.hanger_length_m.max()),
        "cable.main_iterations": c.main_iterations,
        "cable.main_iteration_residual": c.main_residual,
        "cable.equilibrium_residual": c.equilibrium_residual,
        "cable.first_vertical_frequency_eq_3_2_hz": c.first_vertical_frequency_estimate_hz,
    }


def cable_figures(s: Scenario, c: CableSolution) -> dict:
    """Cable geometry of main and side spans (as thesis Fig 2.5-2.6) and hanger lengths."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    left, main, right = c.spans
    fig_main = Figure(figsize=(8, 3.6))
    ax = fig_main.subplots()
    x = main.z_m - (s.geometry.side_span_m + 0.5 * s.geometry.main_span_m)
    ax.plot(x, main.elevation_m - main.elevation_m.min(), lw=1.5, label="cable (RK4)")
    ax.plot(c.hanger_z_m[c.hanger_span == 1] - (s.geometry.side_span_m + 0.5 * s.geometry.main_span_m),
            c.hanger_cable_elevation_m[c.hanger_span == 1] - main.elevation_m.min(), "k.", ms=3, label="hangers")
    ax.set_xlabel("x from mid-span [m]")
    ax.set_ylabel("y above low point [m]")
    ax.set_title(f"{s.name}: main span, H = {c.horizontal_force_per_cable_N:.4g} N per cable")
    ax.grid(alpha=0.3)
    ax.legend()

    fig_side = Figure(figsize=(6, 3.6))
    ax = fig_side.subplots()
    ax.plot(left.z_m, left.elevation_m - left.elevation_m[0], lw=1.5, label="cable (shooting)")
    chord = left.z_m * (left.elevation_m[-1] - left.elevation_m[0]) / left.z_m[-1]
    ax.plot(left.z_m, chord, "k--", lw=0.8, label="chord")
    ax.set_xlabel("x from anchor [m]")
    ax.set_ylabel("y above anchor [m]")
    ax.set_title(f"{s.name}: side span, anchor slope {c.anchor_slope:.4f}")
    ax.grid(alpha=0.3)
    ax.legend()

    fig_h = Figure(figsize=(8, 3))
    ax = fig_h.subplots()
    ax.plot(c.hanger_z_m, c.hanger_length_m, ".-", ms=3)
    ax.set_xlabel("z along the bridge from the left anchor [m]")
    ax.set_ylabel("hanger length [m]")
    ax.grid(alpha=0.3)
    return {"cable_main_span.png": fig_main, "cable_side_span.png": fig_side, "hanger_lengths.png": fig_h}


def _report(s: Scenario, c: CableSolution) -> str:
    g = s.geometry
    return "\n".join([
        "## Cable statics (thesis chapter 2)",
        "",
        "| quantity | value |",
        "|---|---|",
        f"| main span L / side span L_s / sag h | {g.main_span_m:.1f} / {g.side_span_m:.1f} / {g.sag_m:.2f} m |",
        f"| cable area A_c (one cable) | {s.cable.area_m2:.4f} m^2 |",
        f"| cable mass main / side (one cable) | {s.cable.mass_per_length_main_kg_m:.1f} / "
        f"{s.cable.mass_per_length_side_kg_m:.1f} kg/m |",
        f"| mu = mu_b + 2 mu_c, J = J_b + B^2 mu_c / 2 (Eq 4.7) | {s.deck_mass_per_length_kg_m:.4g} kg/m, "
        f"{s.deck_inertia_per_length_kg_m2_m:.4g} kg m^2/m |",
        f"| pylon height / extra cross beams | {g.pylon_height_m:.1f} m / {s.pylon.extra_cross_beams} |",
        f"| H per cable / both cables | {c.horizontal_force_per_cable_N:.5g} N / {c.horizontal_force_total_N:.5g} N |",
        f"| H both cables, parabolic (Eq 1.1, 2.4) | {c.parabolic_estimate_total_N:.5g} N |",
        f"| H iterations (|H1/H0-1| < 1e-6) | {c.main_iterations} (last {c.main_residual:.1e}) |",
        f"| anchor slope alpha_0 (shooting iterations) | {c.anchor_slope:.5f} ({c.side_iterations}) |",
        f"| cable length main span / one side span | {c.main_cable_length_m:.2f} / {c.side_cable_length_m:.2f} m |",
        f"| vertical reaction per cable: pylon top (main + side) / anchor | {c.v_pylon_per_cable_N:.5g} / "
        f"{c.v_anchor_per_cable_N:.5g} N |",
        f"| cable stress at pylon / Eq 1.1 H/(2A_c) | {c.cable_stress_Pa(s.cable.area_m2) / 1e6:.1f} / "
        f"{c.horizontal_force_total_N / (2 * s.cable.area_m2) / 1e6:.1f} MPa |",
        f"| hangers per cable, spacing main / side | {len(c.hanger_z_m)}, {c.main_panel_m:.2f} / "
        f"{c.side_panel_m:.2f} m |",
        f"| hanger length min / max | {c.hanger_length_m.min():.2f} / {c.hanger_length_m.max():.2f} m |",
        f"| equilibrium residual Eq 2.13 | {c.equilibrium_residual:.2e} |",
        f"| first vertical frequency, Eq 3.2 (upper bound) | {c.first_vertical_frequency_estimate_hz:.4f} Hz |",
    ])


def run(scenario: Scenario, upstream: dict, options: RunOptions) -> StageOutput:
    if scenario.kind != "suspension_bridge":
        raise InputError("stages", "cable", f"the cable stage needs a suspension bridge, not kind {scenario.kind!r}")
    options.say(f"[{scenario.name}] cable statics")
    c = solve_cables(scenario, steps_per_panel=4 if options.quick else 8)

    def write_h5(grp) -> None:
        grp.attrs["horizontal_force_per_cable_N"] = c.horizontal_force_per_cable_N
        grp.attrs["horizontal_force_total_N"] = c.horizontal_force_total_N
        grp.attrs["equilibrium_residual"] = c.equilibrium_residual
        grp.attrs["anchor_slope"] = c.anchor_slope
        grp.attrs["first_vertical_frequency_eq_3_2_hz"] = c.first_vertical_frequency_estimate_hz
        for sp in c.spans:
            sg = grp.create_group(sp.name)
            n = len(sp.z_m)
            write_dataset(sg, "z", sp.z_m, "m", f"({n},) position along the bridge at the RK4 nodes of the "
                          f"{sp.name} span, 0 at the left anchor")
            write_dataset(sg, "elevation", sp.elevation_m, "m", f"({n},) cable elevation above the pylon "
                          "foundations at z")
            write_dataset(sg, "slope", sp.slope, "1", f"({n},) cable slope dy/dz at z")
            sg.attrs["cable_length_m"] = sp.length_m
        hg = grp.create_group("hangers")
        n = len(c.hanger_z_m)
        write_dataset(hg, "z", c.hanger_z_m, "m", f"({n},) hanger positions along the bridge (one cable)")
        write_dataset(hg, "cable_elevation", c.hanger_cable_elevation_m, "m",
                      f"({n},) cable elevation at each hanger")
        write_dataset(hg, "length", c.hanger_length_m, "m", f"({n},) hanger length from the cable to the "
                      "girder axis")
        write_dataset(hg, "span", c.hanger_span, "", f"({n},) span code of each hanger: 0 left side span, "
                      "1 main span, 2 right side span")
        hg["span"].attrs["unit"] = ""  # a code, no unit; write_dataset leaves an empty unit out
        rg = grp.create_group("reactions")
        rg.attrs["pylon_main_per_cable_N"] = c.v_pylon_main_per_cable_N
        rg.attrs["pylon_side_per_cable_N"] = c.v_pylon_side_per_cable_N
        rg.attrs["anchor_per_cable_N"] = c.v_anchor_per_cable_N
        rg.attrs["total_weight_N"] = c.total_weight_N

    return StageOutput(summary=cable_summary(scenario, c), write_h5=write_h5, report=_report(scenario, c),
                       figures=cable_figures(scenario, c), data=c)
