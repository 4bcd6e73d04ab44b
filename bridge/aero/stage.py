"""Pipeline stage ``aero``: the deck section's own flutter derivatives from forced-motion CFD.

``run(scenario, upstream, options)``: for every reduced velocity U/(fB) of ``[aero]``
(:class:`bridge.aero.options.AeroOptions`) one heave and one pitch case (thesis 5.3: harmonic motion with
the thesis's velocity amplitudes) of the ``[deck_section]`` (default: the Great Belt box,
:func:`bridge.cfd.sections.great_belt_section`) in a uniform wind, on the preset grid
(:data:`bridge.aero.presets.QUALITY`); the transient periods are dropped and the FRFs fitted over
the whole periods left (:func:`bridge.aero.frequency_response.forced_motion_response`).

The result is non-dimensional (CFD units B = V = rho = 1) and, with one Reynolds number per preset,
independent of the wind speed: ``data.model`` is a :class:`bridge.flutter.tables.DerivativeTable` over
the reduced frequencies run - completed, when the section was also held still (``static_angles_deg``), by
the quasi-steady lateral terms of its static coefficients (:class:`bridge.flutter.aerodynamics.WithLateral`)
- which the flutter stage uses with ``[flutter] aerodynamics = "cfd"``.
Cases are checkpointed under ``<cache>/aero-runs/`` (a killed run resumes); the stage result itself is
cached like every stage's and shared by bridges with the same deck (``Stage.shared``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from bridge.aero.accuracy import GridRecord, grid_accuracy
from bridge.aero.forced_motion import ForcedCase, StaticCase, checkpoint_path, run_cases, whole_periods
from bridge.aero.frequency_response import distortion, forced_motion_response
from bridge.aero.options import AeroOptions
from bridge.aero.presets import body_fitted_walls, preset, section_polygons
from bridge.aero.snapshots import snapshot_files
from bridge.aero.static import SHEDDING_THRESHOLD, StaticCoefficients, static_coefficients
from bridge.flutter.aerodynamics import WithLateral
from bridge.flutter.derivatives import DERIVATIVE_NAMES, FRF, VERTICAL_TORSIONAL, derivatives_from_frf
from bridge.flutter.tables import DerivativeTable
from bridge.results import write_dataset
from bridge.stages import RunOptions, StageOutput

__all__ = ["run", "AeroResult", "scenario_preset", "write_aero_h5", "aero_report", "write_static_h5", "static_report"]


@dataclass(frozen=True)
class AeroResult:
    """``StageOutput.data`` of the aero stage: the table of h_xy and derivatives against K, and the
    model the flutter stage reads."""

    section: str
    quality: str
    reynolds: float
    cells: int                         # cells of the forced-motion runs (both grids of an overset pair)
    reduced_frequency: np.ndarray      # K = w B / V, ascending
    frf: FRF                           # arrays over K (vertical-torsional; drag terms when recorded)
    stderr: FRF
    model: Any                         # DerivativeTable, completed by the static coefficients' lateral terms
    records: tuple[dict, ...]          # per case: dof, K, steps, wall_s, resumed_from_step, periods
    warning: str = ""                  # e.g. the section under-resolved on this preset
    static: StaticCoefficients | None = None
    static_records: tuple[dict, ...] = ()   # per static case: angle_deg, steps, wall_s, t, lift, drag, moment
    grid: str = "single"               # [aero] grid: "single" or "overset"
    grids: str = ""                    # the grids in words, e.g. "480 x 144 cells"
    turbulence: str = "laminar"        # [aero] turbulence: "laminar" or "sst"
    sst_walls: str = "equilibrium"     # [aero] sst_walls: "equilibrium", "function" or "blended" (with "sst")
    grid_study: str = ""               # the preset's grid error as measured (bridge.aero.accuracy), or "none"
    cells_per_chord: int = 0           # the body grid's cells per chord (the preset's, or [aero] cells_per_chord)
    grid_record: GridRecord | None = None   # the study's record of the preset (V_c's band), where one covers it

    @property
    def reduced_velocity(self) -> np.ndarray:
        return 2 * np.pi / self.reduced_frequency

    @property
    def derivatives(self):
        return derivatives_from_frf(self.reduced_frequency, self.frf)


def scenario_preset(scenario: Any, quality: str | None = None):
    """The deck section a scenario's CFD moves and its preset (bridge.aero.presets.Quality): ``quality`` or the
    scenario's ``[aero] quality``, on its grid, with the deck's own Reynolds number when the flow is turbulent.
    Returns (section, quality)."""
    from bridge.cfd.sections import great_belt_section

    section = scenario.deck_section or great_belt_section()
    aopts: AeroOptions = scenario.aero or AeroOptions()
    q = preset(quality or aopts.quality, aopts.grid)
    if aopts.cells_per_chord and q.name != "tiny":   # the preset on another grid; a smoke run stays coarse
        q = q.with_(cells_per_chord=aopts.cells_per_chord)
    if aopts.turbulence != "laminar":   # the deck's own Reynolds number, with the SST model
        air = scenario.air
        nu_air = air.kinematic_viscosity_m2_s if air is not None else 1.48e-5
        q = q.with_(turbulence=aopts.turbulence, reynolds=aopts.wind_speed_m_s * section.chord_m / nu_air,
                    sst_walls=aopts.sst_walls)
        if aopts.grid == "body_fitted":   # its wall treatment follows the first cell's y+ (the report says which)
            q = q.with_(sst_walls=body_fitted_walls(q))
    return section, q


def run(scenario: Any, upstream: dict, options: RunOptions) -> StageOutput:
    section, q = scenario_preset(scenario, options.quality or ("tiny" if options.quick else None))
    aopts: AeroOptions = scenario.aero or AeroOptions()
    quality = q.name
    poly = section_polygons(section)
    warning = preset_warnings(q, quality, section)
    if warning:
        options.say(f"aero: WARNING {warning}")
    Ks = np.array(sorted(2 * np.pi / np.asarray(aopts.reduced_velocities)))
    runs = options.cache / "aero-runs" if options.cache is not None else None
    options.say(f"aero: {section.describe()}; {len(Ks)} reduced frequencies x heave and pitch on the "
                f"{quality!r} preset ({aopts.grid} grid, {q.grid.cells_per_chord} cells per chord, "
                f"Re = {q.physics.reynolds:.3g}, {_flow_model(q)})")
    values = {n: np.zeros(len(Ks), dtype=complex) for n in VERTICAL_TORSIONAL + ("h_qu", "h_qtheta")}
    errors = {n: np.zeros(len(Ks), dtype=complex) for n in values}
    records, cells, grids = [], 0, ""
    cases = _forced_cases(Ks, aopts)
    jobs = []
    for n, case in enumerate(cases):
        what = ", ".join(f"{2 * np.pi / k:.3g}" for k in case.reduced_frequencies)
        jobs.append((case, checkpoint_path(runs, poly, case, q),
                     f"aero case {n + 1}/{len(cases)}, {case.dof} U/(fB) = {what}"))
    angles = aopts.static_angles_deg
    for n, angle in enumerate(angles):
        case = StaticCase(angle, grid_angle_deg=max(abs(a) for a in angles))
        jobs.append((case, checkpoint_path(runs, poly, case, q),
                     f"aero static {n + 1}/{len(angles)}, angle {angle:g} deg"))
    # all cases at once, side by side on the cores where that pays (bridge.aero.forced_motion.run_cases)
    done = run_cases(poly, jobs, q, aopts.checkpoint_every, progress=options.say, workers=options.workers,
                     scheduler=options.scheduler)
    for case, rec in zip(cases, done[:len(cases)], strict=True):
        ks = case.reduced_frequencies
        sel = whole_periods(rec, case, q)
        # a multi-frequency run's drag is no FRF: drag is quadratic in the motion, and twice one frequency is
        # another of the set (h_qu, h_qtheta then come from the static runs' quasi-steady model)
        drag = rec.drag[sel] if len(ks) == 1 else None
        responses = forced_motion_response(rec.t[sel], rec.motion[sel], list(ks), dof=case.dof, speed_m_s=1.0,
                                           deck_width_m=1.0, air_density_kg_m3=1.0, lift=rec.lift[sel],
                                           moment=rec.moment[sel], drag=drag, fundamental=case.fundamental)
        for k, resp in zip(ks, responses, strict=True):
            i = int(np.argmin(np.abs(Ks - k)))
            for name in resp.provides:
                if name in values:
                    values[name][i] = getattr(resp.frf, name)
                    errors[name][i] = getattr(resp.stderr, name)
        if len(ks) > 1:
            warning = check_distortion(rec, sel, case, warning, options)
        cells, grids = rec.meta["cells"], rec.meta["grids"]
        records.append({"dof": case.dof, "K": case.fundamental, "Ks": list(ks), "steps": rec.steps,
                        "wall_s": rec.wall_s, "resumed_from_step": rec.resumed_from_step,
                        "periods": responses[0].periods, "t": rec.t, "lift": rec.lift, "moment": rec.moment,
                        "motion": rec.motion, "window": (float(rec.t[sel][0]), float(rec.t[sel][-1])),
                        "snapshot": rec.snapshot})
    for dof in ("heave", "pitch"):   # keep the flow of the case whose forces are plotted (_figures), drop the rest
        same = [r for r in records if r["dof"] == dof]
        for r in same:
            if r is not same[len(same) // 2]:
                r["snapshot"] = None
    static, static_records = _static_results(done[len(cases):], section, aopts, options)
    frf, stderr = FRF(**values), FRF(**errors)
    measured = VERTICAL_TORSIONAL + (("h_qu", "h_qtheta") if aopts.excitation == "single" else ())
    table = DerivativeTable(Ks, derivatives_from_frf(Ks, frf), source=f"cfd ({section.name}, {quality})",
                            provides=measured)
    sst = ", SST" if q.physics.turbulence == "sst" else ""
    tilt = f", about {aopts.mean_angle_deg:g} deg" if aopts.mean_angle_deg else ""
    table.name = f"cfd ({section.name}, {quality}, Re {q.physics.reynolds:.3g}{sst}{tilt})"
    model = table if static is None else WithLateral(table, static.quasi_steady())
    study, _, record = grid_accuracy(section, aopts, quality, q.physics.reynolds)
    data = AeroResult(section.describe(), quality, q.physics.reynolds, cells, Ks, frf, stderr, model,
                      tuple(records), warning, static, tuple(static_records), aopts.grid, grids, q.physics.turbulence,
                      q.physics.sst_walls,
                      study, q.grid.cells_per_chord, record)
    return StageOutput(summary=_summary(data), write_h5=lambda g: write_aero_h5(g, data), report=aero_report(data),
                       figures=_figures(data), data=data)


def preset_warnings(q, quality: str, section) -> str:
    """What the stage warns of before its runs, for the preset ``q`` (named ``quality``) and the section:
    a section fewer than 2 cells thick, SST finer than its tested grids, the blended wall (under study)."""
    cells_across = (section.depth_m / section.chord_m) * q.grid.cells_per_chord / q.grid.dy_over_dx
    notes = [] if cells_across >= 2.0 else [
        f"the section is {cells_across:.1f} cells thick on the {quality!r} grid (fewer than 2): the immersed "
        "boundary barely sees it and the forces are not to be trusted; use a finer preset"]
    h = section.chord_m / q.grid.cells_per_chord      # the body grid's cell along the chord (its larger side)
    for i, part in enumerate(section.polygons()[1:], start=2):
        x, y = part.vertices[:, 0], part.vertices[:, 1]
        perimeter = float(np.hypot(np.diff(x, append=x[0]), np.diff(y, append=y[0])).sum())
        thickness = 2 * part.area / perimeter    # a strip's thickness; a rectangle's harmonic mean of its sides
        if thickness < 2 * h:
            need = math.ceil(2 * section.chord_m / thickness)
            notes.append(f"part {i} of the section (about {thickness:.2g} m thick) spans {thickness / h:.1f} cells "
                         f"of the {quality!r} grid (fewer than 2): the grid barely sees it and its share of the "
                         f"forces is not to be trusted; two cells across it take {need} cells per chord "
                         "('fine' has 80)")
    if q.physics.turbulence == "sst" and q.grid.cells_per_chord > 80:
        notes.append(f"SST on the {quality!r} preset ({q.grid.cells_per_chord} cells per chord) is untested: the "
                     "finest SST "
                     "runs had 80 cells per chord (the Great Belt deck's grid study, docs/aero.md, \"Grid study\"); a "
                     "run that "
                     "diverges stops with exit status 3")
    if q.physics.turbulence == "sst" and q.physics.sst_walls == "blended":
        notes.append("[aero] sst_walls = \"blended\" is under study: it brought the thin plate onto a body-fitted "
                     "code's, but on the Great Belt deck at Re 1e8 on the 16-cell 'quick' grid it turned the static "
                     "lift slope negative and A2* positive (docs/cfd.md, \"Turbulence model and walls\")")
    return "; ".join(notes)


def _flow_model(q) -> str:
    physics = q.physics
    return "laminar" if physics.turbulence == "laminar" else f"k-omega SST-2003 with {_WALLS[physics.sst_walls]}"


_WALLS = {"function": "Spalding's wall function", "blended": "Spalding's wall function where the layer is turbulent",
          "equilibrium": "Spalding's wall function and the log layer's production of k", "resolved": "resolved walls"}


# a multi-frequency run's load with more than this share of its moved-line amplitude at lines it was not moved
# at is flagged: the products that land there land on the moved lines too (the issue's multi-vs-single 3 %)
DISTORTION_LIMIT = 0.03


def check_distortion(rec, sel, case: ForcedCase, warning: str, options: RunOptions) -> str:
    """Warn when a multi-frequency run's lift or moment is not linear in the motion (``distortion``); returns
    the stage's warning with the finding added."""
    worst = max((distortion(rec.t[sel], getattr(rec, load)[sel], case.reduced_frequencies, case.fundamental), load)
                for load in ("lift", "moment"))
    if worst[0] <= DISTORTION_LIMIT:
        return warning
    found = (f"the multi-frequency {case.dof} run's {worst[1]} has {100 * worst[0]:.0f} % of its amplitude at "
             "frequencies the section was not moved at: it answers nonlinearly at these amplitudes, and the same "
             "products bias the fitted FRFs; use excitation = \"single\" (or smaller heave_rate / pitch_rate)")
    options.say(f"aero: WARNING {found}")
    return "; ".join(w for w in (warning, found) if w)


def _forced_cases(Ks: np.ndarray, aopts: AeroOptions) -> list[ForcedCase]:
    """The heave and pitch runs: one per reduced frequency (``excitation = "single"``), or one per degree of
    freedom moving at all of them at once (``"multi"``, :meth:`ForcedCase.multi_frequency`)."""
    rates = (("heave", aopts.heave_rate), ("pitch", aopts.pitch_rate))
    a0 = math.radians(aopts.mean_angle_deg)
    if aopts.excitation == "multi":
        return [ForcedCase.multi_frequency(dof, tuple(float(k) for k in Ks), rate, a0) for dof, rate in rates]
    return [ForcedCase(dof, (float(K),), (rate / float(K),), mean_angle=a0) for K in Ks for dof, rate in rates]


def _static_results(recs, section, aopts: AeroOptions, options: RunOptions):
    """The records of the section held still at each of ``aopts.static_angles_deg``: (StaticCoefficients or
    None, their summaries)."""
    angles = aopts.static_angles_deg
    if not angles:
        return None, []
    records = [{"angle_deg": angle, "steps": rec.steps, "wall_s": rec.wall_s,
                "resumed_from_step": rec.resumed_from_step, "t": rec.t, "lift": rec.lift,
                "drag": rec.drag, "moment": rec.moment} for angle, rec in zip(angles, recs, strict=True)]
    st = static_coefficients(recs, angles, section.depth_m / section.chord_m)
    cd0 = st.fit(st.drag)[0]
    if cd0 < 0.0:
        options.say(f"aero: WARNING the static runs give a negative drag coefficient ({cd0:.4g}) at 0 degrees: "
                    "the quasi-steady lateral terms use 0; the runs are not to be trusted (a finer preset?)")
    return st, records


def _summary(d: AeroResult) -> dict[str, Any]:
    err = None if d.grid_record is None else d.grid_record.vc_low_percent
    s: dict[str, Any] = {"aero.section": d.section, "aero.quality": d.quality, "aero.reynolds": d.reynolds,
                         "aero.turbulence": d.turbulence,
                         **({"aero.sst_walls": d.sst_walls} if d.turbulence == "sst" else {}),
                         "aero.cases": len(d.records), "aero.grid_cells": d.cells, "aero.grid": d.grid,
                         "aero.cells_per_chord": d.cells_per_chord,
                         "aero.reduced_velocity_min": float(d.reduced_velocity.min()),
                         "aero.reduced_velocity_max": float(d.reduced_velocity.max()),
                         "aero.cfd_wall_s": float(sum(r["wall_s"] for r in d.records + d.static_records)),
                         "aero.grid_study": d.grid_study,
                         "aero.vc_grid_error_low_percent": None if err is None else err[0],
                         "aero.vc_grid_error_high_percent": None if err is None else err[1]}
    if d.static is not None:
        (cd, dcd), (cl, dcl), (cm, dcm) = d.static.fits()
        i0 = int(np.argmin(np.abs(d.static.angles_deg)))
        st = float(d.static.strouhal[i0])
        s.update({"aero.static.drag_coefficient": cd, "aero.static.drag_slope_per_rad": dcd,
                  "aero.static.lift_coefficient": cl, "aero.static.lift_slope_per_rad": dcl,
                  "aero.static.moment_coefficient": cm, "aero.static.moment_slope_per_rad": dcm,
                  "aero.static.strouhal_on_depth": None if math.isnan(st) else st})
    return s


def write_aero_h5(group: Any, d: AeroResult) -> None:
    """Fill ``results.h5:/aero`` (docs/results.md, section ``/aero``)."""
    n = d.reduced_frequency.size
    group.attrs["section"] = d.section
    group.attrs["quality"] = d.quality
    group.attrs["grid"] = d.grid
    group.attrs["reynolds"] = d.reynolds
    group.attrs["turbulence"] = d.turbulence
    if d.turbulence == "sst":
        group.attrs["sst_walls"] = d.sst_walls
    write_dataset(group, "reduced_frequency", d.reduced_frequency, "1", f"({n},) K = Omega = w B / V of the runs")
    write_dataset(group, "reduced_velocity", d.reduced_velocity, "1", f"({n},) U / (f B) = 2 pi / K")
    for name in values_of(d):
        write_dataset(group, name, getattr(d.frf, name), "1",
                      f"({n},) complex {name} (Eq 4.37; lift up, theta nose-up; CFD at Re = {d.reynolds:g})")
        write_dataset(group, f"{name}_stderr", getattr(d.stderr, name), "1",
                      f"({n},) standard error of {name} (real, imaginary parts) from the period-to-period scatter")
    der = d.derivatives
    for name in DERIVATIVE_NAMES:
        v = np.broadcast_to(np.asarray(getattr(der, name), dtype=float), (n,))
        if np.any(v):
            write_dataset(group, f"derivatives/{name}", v, "1",
                          f"({n},) Scanlan's {name}* (B form, h and L down, alpha and M nose-up)")
    if d.static is not None:
        write_static_h5(group.create_group("static"), d.static)
    r = d.grid_record
    if r is not None and r.derivative_change:
        g = group.create_group("grid_study")
        g.attrs["finest_cells_per_chord"] = r.finest_cells
        g.attrs["basis"] = r.basis
        m = len(r.reduced_velocities)
        write_dataset(g, "reduced_velocity", np.array(r.reduced_velocities), "1",
                      f"({m},) U / (f B) of the grid study (bridge/aero/accuracy.py)")
        for name, change in r.derivative_change:
            write_dataset(g, name, np.array(change), "1",
                          f"({m},) {name}* on the study's finest grid over this preset's, less 1 (how far it moves "
                          "from the preset's grid to the finest studied, on this deck; not converged there either)")


def write_static_h5(g: Any, st: StaticCoefficients) -> None:
    """``results.h5:/aero/static``: coefficients of the section held still (bridge/aero/static.py)."""
    n = st.angles_deg.size
    g.attrs["window_start"], g.attrs["window_end"] = st.window
    g.attrs["depth_over_chord"] = st.depth_over_chord
    write_dataset(g, "angle_of_attack", st.angles_deg, "deg", f"({n},) angle of attack, nose-up")
    for name, values, what in (("drag_coefficient", st.drag, "C_D = drag / ((1/2) rho V^2 B), downwind"),
                               ("lift_coefficient", st.lift, "C_L = lift / ((1/2) rho V^2 B), up"),
                               ("moment_coefficient", st.moment,
                                "C_M = moment / ((1/2) rho V^2 B^2), nose-up about the reference point"),
                               ("lift_rms", st.lift_rms, "rms of the lift coefficient's fluctuation")):
        write_dataset(g, name, values, "1", f"({n},) {what}, mean over the second half of the run")
    write_dataset(g, "shedding_frequency", st.frequency, "1",
                  f"({n},) dominant frequency of the lift, f B / V (NaN: steady wake, or fewer than 2 periods in "
                  "the window)")
    write_dataset(g, "strouhal_on_depth", st.strouhal, "1", f"({n},) St = f D / V, D the section's depth")
    write_dataset(g, "settling", st.settling, "1",
                  f"({n}, 3) change of C_D, C_L, C_M from the third to the last quarter of the run (not settled "
                  "if large)")
    for name, values in (("drag", st.drag), ("lift", st.lift), ("moment", st.moment)):
        at0, slope = st.fit(values)
        write_dataset(g, f"fit/{name}_at_zero", at0, "1", f"C of {name} at alpha = 0 from the line fit")
        write_dataset(g, f"fit/{name}_slope", slope, "1/rad", f"dC/dalpha of {name} from the line fit")


def values_of(d: AeroResult) -> tuple[str, ...]:
    return tuple(n for n in VERTICAL_TORSIONAL + ("h_qu", "h_qtheta") if np.any(getattr(d.frf, n)))


def _change(c: float) -> str:
    """A derivative's relative change in words: per cent, a factor where it grows more than tenfold (a derivative
    near zero on the coarser grid), or its sign turning."""
    if c <= -1.0:
        return "sign turns"
    return f"x {1.0 + c:.0f}" if c > 9.0 else f"{100 * c:+.0f} %"


def aero_report(d: AeroResult) -> str:
    from bridge.flutter.aerodynamics import Theodorsen

    theo = derivatives_from_frf(d.reduced_frequency, Theodorsen().frf(d.reduced_frequency, 1.0))
    der = d.derivatives
    lines = ["## Aerodynamics of the deck section from forced-motion CFD (thesis 5.2-5.3)", "",
             f"{d.section}; preset {d.quality!r}, {d.grid} grid of {d.cells_per_chord} cells per chord "
             f"({d.grids}), " + (
                 f"laminar at Re = {d.reynolds:g} (a low Reynolds number: the deck's, about 1e8, needs "
                 "[aero] turbulence = \"sst\")" if d.turbulence == "laminar" else
                 f"URANS with the k-omega SST model (2003 variant) and {_WALLS[d.sst_walls]} at Re = "
                 f"{d.reynolds:.3g}") + ".  Heave and pitch with the thesis's velocity amplitudes, transient "
             "periods dropped, a least-squares harmonic fit over the whole periods left (docs/aero.md).", ""]
    if d.grid_study:
        lines += [f"Accuracy: {d.grid_study}.", ""]
    r = d.grid_record
    if r is not None and r.derivative_change:
        lines += [f"Each derivative's change from this preset's grid to {r.finest_cells} cells per chord, as the grid "
                  "study measured it:", "",
                  "| U/(fB) | " + " | ".join(f"{n}*" for n, _ in r.derivative_change) + " |",
                  "|---|" + "---|" * len(r.derivative_change)]
        for k, u in enumerate(r.reduced_velocities):
            lines.append(f"| {u:.4g} | " + " | ".join(_change(c[k]) for _, c in r.derivative_change) + " |")
        lines.append("")
    if d.warning:
        lines += [f"**Warning: {d.warning}.**", ""]
    lines += ["| U/(fB) | H1* | H1* Theodorsen | H3* | H3* Theodorsen | A1* | A1* Theodorsen | A2* "
              "| A2* Theodorsen | A3* | A3* Theodorsen |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for i in np.argsort(d.reduced_velocity):
        row = [f"{d.reduced_velocity[i]:.2f}"]
        for name in ("H1", "H3", "A1", "A2", "A3"):
            row += [f"{np.asarray(getattr(der, name))[i]:.3f}", f"{np.asarray(getattr(theo, name))[i]:.3f}"]
        lines.append("| " + " | ".join(row) + " |")
    if d.static is not None:
        lines += static_report(d.static)
    lines += ["", "Cases: " + "; ".join(f"{r['dof']} K = {_ks(r)}: {r['steps']} steps, {r['periods']} periods "
                                       f"fitted, {r['wall_s']:.0f} s" + (f" (resumed at step {r['resumed_from_step']})"
                                                                         if r["resumed_from_step"] else "")
                                       for r in d.records) + "."]
    return "\n".join(lines) + "\n"


def _ks(record: dict) -> str:
    return ", ".join(f"{k:.3f}" for k in record["Ks"])


def static_report(st: StaticCoefficients) -> list[str]:
    lines = ["", "Static coefficients (section held still; means over t V/B in "
             f"[{st.window[0]:.1f}, {st.window[1]:.1f}]; on B, moment nose-up about the reference point):", "",
             "| angle [deg] | C_D | C_L | C_M | lift rms | St = f D / V | settling (C_D, C_L, C_M) |",
             "|---|---|---|---|---|---|---|"]
    for i, a in enumerate(st.angles_deg):
        stn = f"{st.strouhal[i]:.4f}" if not math.isnan(st.strouhal[i]) else (
            "steady" if st.lift_rms[i] < SHEDDING_THRESHOLD else "unresolved (< 2 periods)")
        lines.append(f"| {a:g} | {st.drag[i]:.4f} | {st.lift[i]:.4f} | {st.moment[i]:.4f} | {st.lift_rms[i]:.2e} "
                     f"| {stn} | " + ", ".join(f"{x:+.1e}" for x in st.settling[i]) + " |")
    (cd, dcd), (cl, dcl), (cm, dcm) = st.fits()
    lines += ["", f"Line fits: C_D = {cd:.4f} + {dcd:.4f} alpha, C_L = {cl:.4f} + {dcl:.4f} alpha, "
              f"C_M = {cm:.4f} + {dcm:.4f} alpha (alpha in rad; thin-plate theory: dC_L/dalpha = 2 pi = 6.283, "
              "dC_M/dalpha = pi/2 = 1.571 about mid-chord).  With aerodynamics = \"cfd\" these give the flutter "
              "model its lateral (drag, sway) terms, quasi-steady."]
    return lines


def _figures(d: AeroResult) -> dict[str, Any]:
    from matplotlib.figure import Figure

    from bridge.flutter.aerodynamics import Theodorsen

    figs: dict[str, Any] = {}
    fig = Figure(figsize=(9.0, 6.0), layout="constrained")
    axes = fig.subplots(2, 4).ravel()
    uv = np.linspace(max(0.5, 0.8 * d.reduced_velocity.min()), 1.1 * d.reduced_velocity.max(), 120)
    theo = derivatives_from_frf(2 * np.pi / uv, Theodorsen().frf(2 * np.pi / uv, 1.0))
    der = d.derivatives
    for ax, name in zip(axes, ("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4"), strict=True):
        ax.plot(uv, getattr(theo, name), "k-", lw=0.8, label="Theodorsen (flat plate)")
        ax.plot(d.reduced_velocity, getattr(der, name), "C3o-", ms=4, label="CFD")
        ax.set_title(f"{name}*")
        ax.set_xlabel("U/(fB) [-]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle(f"Flutter derivatives (B form, h and L down): {d.section[:60]}, Re = {d.reynolds:g}", fontsize=9)
    figs["aero_derivatives.png"] = fig
    for dof in ("heave", "pitch"):
        recs = [r for r in d.records if r["dof"] == dof]
        if not recs:
            continue
        r = recs[len(recs) // 2]
        fig = Figure(figsize=(8.0, 4.0), layout="constrained")
        ax = fig.subplots()
        ax.plot(r["t"], r["lift"], lw=0.8, label="lift / (rho V^2 B)")
        ax.plot(r["t"], r["moment"], lw=0.8, label="moment / (rho V^2 B^2)")
        ax.axvspan(*r["window"], color="0.9", label="periods fitted")
        ax.set_xlabel("t V / B [-]")
        ax.set_ylabel("force coefficient [-]")
        ax2 = ax.twinx()
        unit = "chords" if dof == "heave" else "rad"
        ax2.plot(r["t"], r["motion"], "k--", lw=0.6)
        ax2.set_ylabel(f"{dof} ({'up' if dof == 'heave' else 'nose-up'}) [{unit}], dashed")
        ax.legend(fontsize=7, loc="upper left")
        ks = _ks(r)
        uvs = ", ".join(f"{2 * math.pi / k:.2f}" for k in r["Ks"])
        ax.set_title(f"Forced {dof}, K = {ks} (U/(fB) = {uvs})")
        figs[f"aero_{dof}_forces.png"] = fig
        if r.get("snapshot") is not None:
            figs.update(snapshot_files(f"aero_{dof}_flow", r["snapshot"], f"Forced {dof}, K = {_ks(r)}"))
    if d.static is not None:
        figs["aero_static.png"] = _static_figure(d)
    return figs


def _static_figure(d: AeroResult):
    from matplotlib.figure import Figure

    st = d.static
    fig = Figure(figsize=(9.0, 3.6), layout="constrained")
    ax, ax2 = fig.subplots(1, 2)
    for values, label in ((st.drag, "C_D"), (st.lift, "C_L"), (st.moment, "C_M (nose-up)")):
        ax.plot(st.angles_deg, values, "o-", ms=4, label=label)
    ax.set_xlabel("angle of attack, nose-up [deg]")
    ax.set_ylabel("coefficient on B [-]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("Static coefficients")
    r = d.static_records[int(np.argmin(np.abs(st.angles_deg)))]
    ax2.plot(r["t"], 2 * np.asarray(r["lift"]), lw=0.7, label="C_L")
    ax2.plot(r["t"], 2 * np.asarray(r["drag"]), lw=0.7, label="C_D")
    ax2.axvspan(*st.window, color="0.9", label="averaged")
    ax2.set_xlabel("t V / B [-]")
    ax2.set_ylabel("coefficient on B [-]")
    ax2.legend(fontsize=7)
    ax2.set_title(f"Held at {r['angle_deg']:g} deg from an impulsive start")
    fig.suptitle(f"{d.section[:70]}, Re = {d.reynolds:g}", fontsize=9)
    return fig
