"""The buffeting stage of the pipeline: the deck's response to turbulent wind below the flutter speed.

``run(scenario, upstream, options) -> StageOutput``.  Inputs: the modes of the flutter stage
(``upstream["flutter"].data.modal_model``, the fem stage's vertical, torsional and lateral modes) with their
shapes along the deck (``upstream["fem"].data.modes``), the flutter stage's aerodynamic model and air density
(:func:`bridge.flutter.stage.options_and_aerodynamics`; completed by the quasi-steady lateral terms of the
static coefficients when it has none, bridge.flutter.aerodynamics.WithLateral), and the options of
``scenario.buffeting`` (:class:`bridge.buffeting.options.BuffetingOptions`; defaults if absent).

Static coefficients, in this order: ``[buffeting.static_coefficients]``, the aero stage's static runs (the
deck's own, with ``[flutter] aerodynamics = "cfd"``), ``[flutter.quasi_steady]``; none of them is an
InputError.  Speeds: ``speed_steps`` from ``min_speed_m_s`` to ``max_speed_m_s`` (default 90 % of the lowest
flutter or divergence speed of the flutter stage, which with all modes together is where the response grows
without bound), and the reference speed of the summary when it lies below that speed.  Method:
bridge.buffeting.response; HDF5 datasets: docs/results.md, ``/buffeting``; figures ``buffeting_spectra.png``
(response spectra at mid-span) and ``buffeting_rms.png`` (RMS at mid-span and the largest along the span
against the wind speed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from bridge.buffeting.loads import DeckModes
from bridge.buffeting.options import BuffetingOptions
from bridge.buffeting.response import DOFS, BuffetingResponse, buffeting_response, frequency_grid
from bridge.errors import InputError
from bridge.flutter.aerodynamics import QuasiSteady, WithLateral, has_lateral
from bridge.flutter.stage import options_and_aerodynamics
from bridge.results import write_dataset
from bridge.stages import RunOptions, StageOutput

__all__ = ["run", "BuffetingStageResult", "QUICK_FREQUENCY_STEPS", "QUICK_SPEED_STEPS", "SPEED_FRACTION"]

QUICK_FREQUENCY_STEPS = 1001
QUICK_SPEED_STEPS = 4
SPEED_FRACTION = 0.9          # default top speed: this fraction of the flutter stage's lowest instability
_UNITS = {"vertical": ("m", 1.0), "torsional": ("deg", 180.0 / math.pi), "lateral": ("m", 1.0)}


@dataclass(frozen=True)
class BuffetingStageResult:
    """``StageOutput.data`` of the buffeting stage: the response and what it was computed with.
    ``outside_data`` (n_V, N): 1 where a mode's natural reduced frequency w_i B / V lies outside the
    aerodynamic model's range (its self-excited FRFs held at the table's end there)."""

    response: BuffetingResponse
    options: BuffetingOptions
    aerodynamics: str
    air_density_kg_m3: float
    coefficients: QuasiSteady
    coefficients_source: str
    speed_limit_m_s: float
    speed_limit_what: str
    reference_speed_m_s: float | None
    natural_frequencies_hz: np.ndarray   # the modes', in the order of response.labels
    outside_data: np.ndarray


def _coefficients(bopts: BuffetingOptions, fopts: Any, upstream: dict) -> tuple[QuasiSteady, str]:
    if bopts.static_coefficients is not None:
        return bopts.static_coefficients, "[buffeting.static_coefficients]"
    aero = upstream.get("aero")
    static = getattr(getattr(aero, "data", None), "static", None)
    if fopts.aerodynamics == "cfd" and static is not None and static.angles_deg.size >= 2:
        return static.quasi_steady(), "the aero stage's static runs"
    if fopts.quasi_steady is not None:
        return fopts.quasi_steady, "[flutter.quasi_steady]"
    raise InputError("buffeting.static_coefficients", None, "needed: give [buffeting.static_coefficients] or "
                     "[flutter.quasi_steady] (lift_coefficient, lift_slope_per_rad, drag_coefficient, "
                     "moment_coefficient, moment_slope_per_rad), or run the deck's CFD with static angles")


def _stability_limit(flutter: Any, max_searched: float) -> tuple[float, str]:
    """The lowest flutter or divergence speed the flutter stage found, and what it is."""
    found = []
    if flutter.governing is not None:
        pair = "+".join(flutter.governing.pair)
        found.append((flutter.governing.critical_speed_m_s, f"two-mode flutter speed ({pair})"))
    for mm, what in ((flutter.multimode, "multimode flutter speed"),
                     (getattr(flutter.lateral, "multimode", None), "multimode flutter speed with the lateral modes")):
        if mm is not None and mm.flutter:
            found.append((mm.critical_speed_m_s, what))
        if mm is not None and math.isfinite(mm.divergence_speed_m_s):
            found.append((mm.divergence_speed_m_s, "static divergence speed"))
    lateral = getattr(flutter.lateral, "governing", None)
    if lateral is not None and lateral.flutter:
        found.append((lateral.critical_speed_m_s, f"flutter speed of {'+'.join(lateral.pair)}"))
    found = [(float(v), w) for v, w in found if math.isfinite(v)]
    return min(found) if found else (float(max_searched), "highest speed the flutter stage searched (no flutter)")


def _speeds(bopts: BuffetingOptions, limit: float, what: str, quick: bool) -> tuple[np.ndarray, float | None]:
    top = bopts.max_speed_m_s if bopts.max_speed_m_s is not None else SPEED_FRACTION * limit
    if top >= limit and bopts.self_excited:
        raise InputError("buffeting.max_speed_m_s", top, f"below the {what}, {limit:.2f} m/s (the response grows "
                         "without bound there)")
    if top <= bopts.min_speed_m_s:
        raise InputError("buffeting.min_speed_m_s", bopts.min_speed_m_s, f"below the highest speed, {top:.2f} m/s "
                         f"({SPEED_FRACTION:g} of the {what}, {limit:.2f} m/s, unless max_speed_m_s is given)")
    steps = min(bopts.speed_steps, QUICK_SPEED_STEPS) if quick else bopts.speed_steps
    speeds = np.linspace(bopts.min_speed_m_s, top, steps)
    ref = float(bopts.reference_speed_m_s)
    if ref >= limit:
        return speeds, None
    near = int(np.argmin(np.abs(speeds - ref)))
    if steps > 1 and abs(speeds[near] - ref) < 0.25 * (speeds[1] - speeds[0]) and 0 < near < steps - 1:
        speeds[near] = ref                  # the reference speed in place of a speed of the grid next to it
        return speeds, ref
    return np.unique(np.append(speeds, ref)), ref


def run(scenario: Any, upstream: dict, options: RunOptions) -> StageOutput:
    bopts: BuffetingOptions = scenario.buffeting or BuffetingOptions()
    flutter = upstream["flutter"].data
    fem = getattr(upstream.get("fem"), "data", None)
    if not hasattr(fem, "modes"):
        raise InputError("buffeting", scenario.kind, "needs the mode shapes along the deck: a bridge's fem stage")
    fopts, aero = options_and_aerodynamics(scenario, upstream)
    coefficients, source = _coefficients(bopts, fopts, upstream)
    if not has_lateral(aero):        # drag buffets the lateral modes: their aerodynamic damping from the same data
        aero = WithLateral(aero, coefficients)
    model = flutter.modal_model
    model = model.subset([i for i in range(model.n_modes) if model.kinds[i] != "lateral" or model.rr[i, i] > 0.0])
    modes = DeckModes.from_mode_set(fem.modes, model.labels)
    limit, what = _stability_limit(flutter, fopts.max_speed_m_s)
    speeds, ref = _speeds(bopts, limit, what, options.quick)
    s_lo, s_hi = aero.speed_range
    if speeds.min() < s_lo or speeds.max() > s_hi:
        raise InputError("buffeting.max_speed_m_s", float(speeds.max()), f"the aerodynamic model covers V in "
                         f"[{s_lo:g}, {s_hi:g}] m/s; no extrapolation")
    f_max = bopts.max_frequency_hz or 1.25 * float(np.max(model.frequencies_hz))
    steps = min(bopts.frequency_steps, QUICK_FREQUENCY_STEPS) if options.quick else bopts.frequency_steps
    f = frequency_grid(f_max, steps)
    rho = flutter.air_density_kg_m3
    options.say(f"buffeting: {model.n_modes} modes, {speeds.size} speeds {speeds[0]:.1f}-{speeds[-1]:.1f} m/s, "
                f"{aero.name} self-excited forces, static coefficients from {source}")
    response = buffeting_response(model, modes, aero, rho, coefficients, bopts.turbulence, bopts.admittance_model,
                                  speeds, f, self_excited=bopts.self_excited, say=options.say)
    o_lo, o_hi = aero.omega_range
    omega = model.angular_frequencies[None, :] * model.deck_width_m / speeds[:, None]
    # a lateral mode's own terms are closed forms when quasi-steady ones complete the table: never held
    closed = isinstance(aero, WithLateral) and "h_qr" in aero.filled
    table = np.array([kind != "lateral" or not closed for kind in model.kinds])
    outside = (((omega < o_lo) | (omega > o_hi)) & table[None, :]).astype(np.int8)
    data = BuffetingStageResult(response, bopts, aero.name, float(rho), coefficients, source, limit, what, ref,
                                np.asarray(model.frequencies_hz, dtype=np.float64), outside)
    return StageOutput(summary=_summary(data), write_h5=lambda g: _write_h5(g, data), report=_report(data),
                       figures=_figures(data), data=data)


def _at_reference(d: BuffetingStageResult) -> int | None:
    r = d.response
    if d.reference_speed_m_s is None:
        return None
    return int(np.argmin(np.abs(r.speeds_m_s - d.reference_speed_m_s)))


def outside_data_text(d: BuffetingStageResult) -> str | None:
    """'MODE a-b m/s[, ...]; ...' for the modes whose natural reduced frequency lies outside the aerodynamic
    table at some of the speeds (its self-excited FRFs held there), or None."""
    v = d.response.speeds_m_s
    parts = []
    for i, label in enumerate(d.response.labels):
        out = d.outside_data[:, i].astype(bool)
        if not out.any():
            continue
        edges = np.flatnonzero(np.diff(np.concatenate([[0], out.astype(np.int8), [0]])))
        parts.append(f"{label} " + ", ".join(f"{v[a]:.1f} m/s" if b == a + 1 else f"{v[a]:.1f}-{v[b - 1]:.1f} m/s"
                                             for a, b in zip(edges[::2], edges[1::2], strict=True)))
    return "; ".join(parts) if parts else None


def _summary(d: BuffetingStageResult) -> dict[str, float | int | bool | str | None]:
    r, o = d.response, d.options
    i = _at_reference(d)
    s: dict[str, float | int | bool | str | None] = {
        "buffeting.reference_speed_m_s": d.reference_speed_m_s,
        "buffeting.min_speed_m_s": float(r.speeds_m_s[0]), "buffeting.max_speed_m_s": float(r.speeds_m_s[-1]),
        "buffeting.speed_limit_m_s": float(d.speed_limit_m_s), "buffeting.speed_limit": d.speed_limit_what,
        "buffeting.spectrum": o.spectrum, "buffeting.admittance": o.admittance,
        "buffeting.static_coefficients": d.coefficients_source, "buffeting.self_excited": o.self_excited,
        "buffeting.aerodynamics": d.aerodynamics,
        "buffeting.frequency_resolution_change_percent": float(100.0 * r.resolution_change.max()),
        "buffeting.self_excited_outside_data": outside_data_text(d)}
    for k, dof in enumerate(DOFS):
        unit = "rad" if dof == "torsional" else "m"
        s[f"buffeting.rms_{dof}_midspan_{unit}"] = None if i is None else float(r.rms_midspan[i, k])
        s[f"buffeting.max_rms_{dof}_{unit}"] = None if i is None else float(r.rms_along_span[i, k].max())
    return s


def _write_h5(group: Any, d: BuffetingStageResult) -> None:
    """Fill ``results.h5:/buffeting`` (docs/results.md, ``/buffeting``)."""
    r, o, c = d.response, d.options, d.coefficients
    t = o.turbulence
    attrs = {"aerodynamics": d.aerodynamics, "air_density_kg_m3": d.air_density_kg_m3, "spectrum": o.spectrum,
             "turbulence_intensity_u": t.intensity_u, "turbulence_intensity_w": t.iw,
             "length_scale_u_m": t.length_scale_u_m, "length_scale_w_m": t.lw, "coherence_decay_u": t.decay_u,
             "coherence_decay_w": t.decay_w, "admittance": o.admittance, "self_excited": int(o.self_excited),
             "static_coefficients": d.coefficients_source, "drag_coefficient": c.drag_coefficient,
             "drag_slope_per_rad": c.drag_slope_per_rad, "lift_coefficient": c.lift_coefficient,
             "lift_slope_per_rad": c.lift_slope_per_rad, "moment_coefficient": c.moment_coefficient,
             "moment_slope_per_rad": c.moment_slope_per_rad, "speed_limit_m_s": d.speed_limit_m_s,
             "speed_limit": d.speed_limit_what, "mid_span_z_m": r.mid_span_z_m,
             "reference_speed_m_s": np.nan if d.reference_speed_m_s is None else d.reference_speed_m_s}
    for key, value in attrs.items():
        group.attrs[key] = value
    n, nv, nf, nz = len(r.labels), r.speeds_m_s.size, r.frequencies_hz.size, r.z_m.size
    write_dataset(group, "labels", [str(s) for s in r.labels], "", f"({n},) the modes of the response")
    write_dataset(group, "natural_frequencies_hz", d.natural_frequencies_hz, "Hz", f"({n},) their natural frequencies")
    write_dataset(group, "speed_m_s", r.speeds_m_s, "m/s", f"({nv},) mean wind speeds")
    write_dataset(group, "frequency_hz", r.frequencies_hz, "Hz", f"({nf},) frequencies of the spectra (even grid)")
    write_dataset(group, "z_m", r.z_m, "m", f"({nz},) deck stations along the bridge (girder nodes)")
    for dof, unit in (("vertical", "m"), ("torsional", "rad"), ("lateral", "m")):
        k = DOFS.index(dof)
        write_dataset(group, f"psd_midspan_{dof}", r.midspan_spectra[:, k], f"{unit}^2/Hz",
                      f"({nv}, {nf}) [speed, frequency] one-sided spectrum of the {dof} displacement at mid-span")
        write_dataset(group, f"rms_midspan_{dof}", r.rms_midspan[:, k], unit,
                      f"({nv},) RMS of the {dof} displacement at mid-span")
        write_dataset(group, f"rms_{dof}", r.rms_along_span[:, k], unit,
                      f"({nv}, {nz}) [speed, station] RMS of the {dof} displacement along the deck")
    write_dataset(group, "modal_covariance", r.modal_covariance, "m^2, m or 1 by the modes' kinds",
                  f"({nv}, {n}, {n}) covariance of the modal coordinates (vertical and lateral modes in m, "
                  "torsional ones dimensionless: shapes normalised to max 1)")
    write_dataset(group, "resolution_change", r.resolution_change, "1",
                  f"({nv},) largest relative change of a span-integrated variance with every other frequency")
    write_dataset(group, "outside_data", d.outside_data, "",
                  f"({nv}, {n}) flag: 1 where the mode's natural reduced frequency lies outside the aerodynamic "
                  "data (self-excited FRFs held at the table's end)")


def _report(d: BuffetingStageResult) -> str:
    r, o, c = d.response, d.options, d.coefficients
    t = o.turbulence
    i = _at_reference(d)
    forces = (f"with the self-excited forces of the {d.aerodynamics} aerodynamics" if o.self_excited
              else "without self-excited forces")
    lines = ["## Buffeting", "",
             f"Multimode buffeting in the frequency domain (docs/buffeting.md) on {len(r.labels)} modes, {forces}; "
             f"{o.spectrum.replace('_', ' ')} spectra with I_u = {t.intensity_u:g}, I_w = {t.iw:g}, "
             f"L_u = {t.length_scale_u_m:g} m, L_w = {t.lw:g} m; Davenport coherence C_u = {t.decay_u:g}, "
             f"C_w = {t.decay_w:g}; {o.admittance} admittance; static coefficients from {d.coefficients_source} "
             f"(on B, per radian): C_D = {c.drag_coefficient:.4g}, C_D' = {c.drag_slope_per_rad:.4g}, "
             f"C_L = {c.lift_coefficient:.4g}, C_L' = {c.lift_slope_per_rad:.4g}, C_M = {c.moment_coefficient:.4g}, "
             f"C_M' = {c.moment_slope_per_rad:.4g}; air density {d.air_density_kg_m3:g} kg/m^3.  Speeds up to "
             f"{r.speeds_m_s[-1]:.1f} m/s; the {d.speed_limit_what} is {d.speed_limit_m_s:.1f} m/s.  Frequencies "
             f"0-{r.frequencies_hz[-1]:.3g} Hz in {r.frequencies_hz.size} points (every other point changes a "
             f"variance by at most {100 * r.resolution_change.max():.2g} %).", "",
             "| V [m/s] | vertical RMS, mid-span [m] | torsional RMS, mid-span [deg] | lateral RMS, mid-span [m] | "
             "largest along the span: vertical [m], torsional [deg], lateral [m] |", "|---|---|---|---|---|"]
    for n, v in enumerate(r.speeds_m_s):
        mid = [r.rms_midspan[n, k] * _UNITS[dof][1] for k, dof in enumerate(DOFS)]
        top = [r.rms_along_span[n, k].max() * _UNITS[dof][1] for k, dof in enumerate(DOFS)]
        mark = "**" if n == i else ""
        lines.append(f"| {mark}{v:.1f}{mark} | {mid[0]:.4g} | {mid[1]:.4g} | {mid[2]:.4g} | "
                     f"{top[0]:.4g}, {top[1]:.4g}, {top[2]:.4g} |")
    lines.append("")
    if i is None:
        lines.append(f"The reference speed {o.reference_speed_m_s:g} m/s is not below the {d.speed_limit_what}: no "
                     "summary values.")
    else:
        lines.append(f"In bold the reference speed of the summary, {d.reference_speed_m_s:g} m/s.")
    outside = outside_data_text(d)
    if outside:
        lines.append(f"Self-excited forces held at the end of the aerodynamic data (a mode's natural reduced frequency "
                     f"outside them; bridge/buffeting/response.py): {outside}.")
    return "\n".join(lines) + "\n"


def _figures(d: BuffetingStageResult) -> dict[str, Any]:
    from matplotlib.figure import Figure  # Agg canvas, no pyplot state

    r = d.response
    names = {"vertical": "vertical [m^2/Hz]", "torsional": "torsional [rad^2/Hz]", "lateral": "lateral [m^2/Hz]"}
    shown = sorted(set(np.linspace(0, r.speeds_m_s.size - 1, 4).round().astype(int).tolist()
                       + ([_at_reference(d)] if _at_reference(d) is not None else [])))
    spectra = Figure(figsize=(8.0, 8.0), layout="constrained")
    axes = spectra.subplots(3, 1, sharex=True)
    for k, dof in enumerate(DOFS):
        for n in shown:
            axes[k].semilogy(r.frequencies_hz[1:], np.maximum(r.midspan_spectra[n, k, 1:], 1e-300),
                             lw=1.6 if n == _at_reference(d) else 0.9, label=f"V = {r.speeds_m_s[n]:.1f} m/s")
        peak = r.midspan_spectra[shown, k, 1:].max()
        if peak > 0:
            axes[k].set_ylim(peak * 1e-6, peak * 3)
        axes[k].set_ylabel(f"PSD, {names[dof]}")
        axes[k].grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    axes[-1].set_xlabel("frequency f [Hz]")
    axes[0].set_title("Buffeting: one-sided response spectra at mid-span")
    rms = Figure(figsize=(8.0, 8.0), layout="constrained")
    axes = rms.subplots(3, 1, sharex=True)
    for k, dof in enumerate(DOFS):
        unit, scale = _UNITS[dof]
        axes[k].plot(r.speeds_m_s, r.rms_midspan[:, k] * scale, "o-", label="mid-span")
        axes[k].plot(r.speeds_m_s, r.rms_along_span[:, k].max(axis=1) * scale, "s--", label="largest along the span")
        if d.reference_speed_m_s is not None:
            axes[k].axvline(d.reference_speed_m_s, color="0.5", ls=":", label="reference speed")
        axes[k].set_ylabel(f"RMS {dof} [{unit}]")
        axes[k].grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    axes[-1].set_xlabel(f"mean wind speed V [m/s] ({d.speed_limit_what}: {d.speed_limit_m_s:.1f} m/s)")
    axes[0].set_title("Buffeting: RMS displacement against the mean wind speed")
    return {"buffeting_spectra.png": spectra, "buffeting_rms.png": rms}
