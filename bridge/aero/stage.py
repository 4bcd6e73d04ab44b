"""Pipeline stage ``aero``: the deck section's own flutter derivatives from forced-motion CFD.

``run(scenario, upstream, options)``: for every reduced velocity U/(fB) of ``[aero]``
(:class:`bridge.aero.options.AeroOptions`) one heave and one pitch case (thesis 5.3: harmonic motion with
the thesis's velocity amplitudes) of the ``[deck_section]`` (default: the Great Belt box,
:func:`bridge.cfd.sections.great_belt_section`) in a uniform wind, on the preset grid
(:data:`bridge.aero.forced_motion.QUALITY`); the transient periods are dropped and the FRFs fitted over
the whole periods left (:func:`bridge.aero.frequency_response.forced_motion_response`).

The result is non-dimensional (CFD units B = V = rho = 1) and, with one Reynolds number per preset,
independent of the wind speed: ``data.model`` is a :class:`bridge.flutter.tables.DerivativeTable` over
the reduced frequencies run, which the flutter stage uses with ``[flutter] aerodynamics = "cfd"``.
Cases are checkpointed under ``<cache>/aero-runs/`` (a killed run resumes); the stage result itself is
cached like every stage's and shared by bridges with the same deck (``Stage.shared``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from bridge.aero.forced_motion import QUALITY, ForcedCase, case_key, run_case, whole_periods
from bridge.aero.frequency_response import forced_motion_response
from bridge.aero.options import AeroOptions
from bridge.flutter.derivatives import DERIVATIVE_NAMES, FRF, VERTICAL_TORSIONAL, derivatives_from_frf
from bridge.flutter.tables import DerivativeTable
from bridge.results import write_dataset
from bridge.stages import RunOptions, StageOutput

__all__ = ["run", "AeroResult"]


@dataclass(frozen=True)
class AeroResult:
    """``StageOutput.data`` of the aero stage: the table of h_xy and derivatives against K, and the
    model the flutter stage reads."""

    section: str
    quality: str
    reynolds: float
    cells: tuple[int, int]
    reduced_frequency: np.ndarray      # K = w B / V, ascending
    frf: FRF                           # arrays over K (vertical-torsional; drag terms when recorded)
    stderr: FRF
    model: DerivativeTable
    records: tuple[dict, ...]          # per case: dof, K, steps, wall_s, resumed_from_step, periods
    warning: str = ""                  # e.g. the section under-resolved on this preset

    @property
    def reduced_velocity(self) -> np.ndarray:
        return 2 * np.pi / self.reduced_frequency

    @property
    def derivatives(self):
        return derivatives_from_frf(self.reduced_frequency, self.frf)


def _unit_polygon(section):
    """The section's outline scaled to chord 1 (the CFD's unit of length)."""
    return _unit_polygons(section)[0]


def _unit_polygons(section) -> list:
    """Every part of the section (the box and, if any, its railings) scaled to chord 1."""
    from bridge.cfd import Polygon

    return [Polygon(p.vertices / section.chord_m) for p in section.polygons()]


def run(scenario: Any, upstream: dict, options: RunOptions) -> StageOutput:
    from bridge.cfd.sections import great_belt_section

    section = getattr(scenario, "deck_section", None) or great_belt_section()
    aopts: AeroOptions = getattr(scenario, "aero", None) or AeroOptions()
    quality = options.quality or ("tiny" if options.quick else aopts.quality)
    q = QUALITY[quality]
    poly = _unit_polygons(section)
    cells_across = (section.depth_m / section.chord_m) * q.cells_per_chord / q.dy_over_dx
    warning = ("" if cells_across >= 2.0 else
               f"the section is {cells_across:.1f} cells thick on the {quality!r} grid (fewer than 2): the immersed "
               "boundary barely sees it and the forces are not to be trusted; use a finer preset")
    if warning:
        options.say(f"aero: WARNING {warning}")
    Ks = np.array(sorted(2 * np.pi / np.asarray(aopts.reduced_velocities)))
    runs = options.cache / "aero-runs" if options.cache is not None else None
    options.say(f"aero: {section.describe()}; {len(Ks)} reduced frequencies x heave and pitch on the "
                f"{quality!r} preset (Re = {q.reynolds:g}, laminar)")
    values = {n: np.zeros(len(Ks), dtype=complex) for n in VERTICAL_TORSIONAL + ("h_qu", "h_qtheta")}
    errors = {n: np.zeros(len(Ks), dtype=complex) for n in values}
    records, cells = [], (0, 0)
    n_cases = 2 * len(Ks)
    for i, K in enumerate(Ks):
        for dof, rate in (("heave", aopts.heave_rate), ("pitch", aopts.pitch_rate)):
            case = ForcedCase(dof, (float(K),), (rate / float(K),))
            label = f"aero case {len(records) + 1}/{n_cases}, {dof} U/(fB) = {2 * np.pi / K:.3g}"
            checkpoint = None if runs is None else runs / f"{case_key(poly, case, q)[:24]}.h5"
            rec = run_case(poly, case, q, checkpoint, aopts.checkpoint_every, progress=options.say, label=label)
            sel = whole_periods(rec, case, q.discard_periods)
            (resp,) = forced_motion_response(rec.t[sel], rec.motion[sel], [float(K)], dof=dof, speed_m_s=1.0,
                                             deck_width_m=1.0, air_density_kg_m3=1.0, lift=rec.lift[sel],
                                             moment=rec.moment[sel], drag=rec.drag[sel], fundamental=float(K))
            for name in resp.provides:
                if name in values:
                    values[name][i] = getattr(resp.frf, name)
                    errors[name][i] = getattr(resp.stderr, name)
            cells = (rec.meta["nx"], rec.meta["ny"])
            records.append({"dof": dof, "K": float(K), "steps": rec.steps, "wall_s": rec.wall_s,
                            "resumed_from_step": rec.resumed_from_step, "periods": resp.periods,
                            "t": rec.t, "lift": rec.lift, "moment": rec.moment, "motion": rec.motion,
                            "window": (float(rec.t[sel][0]), float(rec.t[sel][-1]))})
    frf, stderr = FRF(**values), FRF(**errors)
    model = DerivativeTable(Ks, derivatives_from_frf(Ks, frf), source=f"cfd ({section.name}, {quality})",
                            provides=VERTICAL_TORSIONAL + ("h_qu", "h_qtheta"))
    model.name = f"cfd ({section.name}, {quality}, Re {q.reynolds:g})"
    data = AeroResult(section.describe(), quality, q.reynolds, cells, Ks, frf, stderr, model, tuple(records),
                      warning)
    return StageOutput(summary=_summary(data), write_h5=lambda g: _write_h5(g, data), report=_report(data),
                       figures=_figures(data), data=data)


def _summary(d: AeroResult) -> dict[str, Any]:
    s: dict[str, Any] = {"aero.section": d.section, "aero.quality": d.quality, "aero.reynolds": d.reynolds,
                         "aero.cases": len(d.records), "aero.grid_cells": d.cells[0] * d.cells[1],
                         "aero.reduced_velocity_min": float(d.reduced_velocity.min()),
                         "aero.reduced_velocity_max": float(d.reduced_velocity.max()),
                         "aero.cfd_wall_s": float(sum(r["wall_s"] for r in d.records))}
    return s


def _write_h5(group: Any, d: AeroResult) -> None:
    """Fill ``results.h5:/aero`` (docs/results.md, section ``/aero``)."""
    n = d.reduced_frequency.size
    group.attrs["section"] = d.section
    group.attrs["quality"] = d.quality
    group.attrs["reynolds"] = d.reynolds
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


def values_of(d: AeroResult) -> tuple[str, ...]:
    return tuple(n for n in VERTICAL_TORSIONAL + ("h_qu", "h_qtheta") if np.any(getattr(d.frf, n)))


def _report(d: AeroResult) -> str:
    from bridge.flutter.aerodynamics import Theodorsen

    theo = derivatives_from_frf(d.reduced_frequency, Theodorsen().frf(d.reduced_frequency, 1.0))
    der = d.derivatives
    lines = ["## Aerodynamics of the deck section from forced-motion CFD (thesis 5.2-5.3)", "",
             f"{d.section}; preset {d.quality!r}: {d.cells[0]} x {d.cells[1]} cells, laminar at Re = {d.reynolds:g} "
             "(the deck's Re of about 1e8 needs the turbulence model of a later stage: these are low-Reynolds "
             "numbers).  Heave and pitch with the thesis's velocity amplitudes, transient periods dropped, a "
             "least-squares harmonic fit over the whole periods left (docs/aero.md).", ""]
    if d.warning:
        lines += [f"**Warning: {d.warning}.**", ""]
    lines += ["| U/(fB) | H1* | H1* Theodorsen | H3* | H3* Theodorsen | A1* | A1* Theodorsen | A2* "
              "| A2* Theodorsen | A3* | A3* Theodorsen |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for i in np.argsort(d.reduced_velocity):
        row = [f"{d.reduced_velocity[i]:.2f}"]
        for name in ("H1", "H3", "A1", "A2", "A3"):
            row += [f"{np.asarray(getattr(der, name))[i]:.3f}", f"{np.asarray(getattr(theo, name))[i]:.3f}"]
        lines.append("| " + " | ".join(row) + " |")
    lines += ["", "Cases: " + "; ".join(f"{r['dof']} K = {r['K']:.3f}: {r['steps']} steps, {r['periods']} periods "
                                       f"fitted, {r['wall_s']:.0f} s" + (f" (resumed at step {r['resumed_from_step']})"
                                                                         if r["resumed_from_step"] else "")
                                       for r in d.records) + "."]
    return "\n".join(lines) + "\n"


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
        ax.set_title(f"Forced {dof}, K = {r['K']:.3f} (U/(fB) = {2 * math.pi / r['K']:.2f})")
        figs[f"aero_{dof}_forces.png"] = fig
    return figs
