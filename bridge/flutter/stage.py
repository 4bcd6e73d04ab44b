"""The flutter stage of the pipeline: modes in, critical wind speed out.

``run(scenario, upstream, options) -> StageOutput``.  Modes come from, in this order,
``upstream["fem"].data.modal_model`` (a :class:`ModalModel`), ``scenario.section`` (a
:class:`SectionModel`, when ``scenario.kind == "section"``) or ``scenario.modal`` (a ModalModel).
Options from ``scenario.flutter`` (a :class:`FlutterOptions`; defaults if absent).  Air density:
``section.air_density_kg_m3``, else ``flutter.air_density_kg_m3``, else ``scenario.air.density_kg_m3``,
else 1.225.  Every (bending, torsion) pair is solved by the determinant method; the governing pair is
the one with the lowest critical speed; the p-k multimode sweep runs on all vertical and torsional
modes.  HDF5 datasets: docs/results.md, section ``/flutter``.  Summary values are strict JSON: None
for a number that does not exist (no flutter, no divergence below the highest speed searched), True/False
for flags.  Figures: the determinant map of the governing pair, the p-k damping plot, and, when the modes
come from the fem stage, the mode shapes of the governing pair (and of the p-k mode that goes unstable)
that the fem stage did not already draw.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from bridge.errors import InputError
from bridge.flutter.aerodynamics import has_lateral
from bridge.flutter.determinant import FlutterResult, governing, solve_pair
from bridge.flutter.modal import ModalModel
from bridge.flutter.multimode import MultimodeResult, pk_sweep
from bridge.flutter.options import FlutterOptions
from bridge.results import write_dataset
from bridge.stages import RunOptions, StageOutput

__all__ = ["run", "FlutterStageResult", "LateralEffect", "air_density"]

QUICK_SPEED_STEPS = 40


@dataclass(frozen=True)
class FlutterStageResult:
    """``StageOutput.data`` of the flutter stage."""

    modal_model: ModalModel
    aerodynamics: str
    air_density_kg_m3: float
    pairs: tuple[FlutterResult, ...]
    governing: FlutterResult | None
    multimode: MultimodeResult | None
    lateral: LateralEffect | None = None


@dataclass(frozen=True)
class LateralEffect:
    """The flutter analysis again with the lateral modes, when the aerodynamics give lateral terms.

    ``mode``: the lateral mode added to the governing pair (the one of its symmetry most coupled to the
    pair's torsional mode, |rt| / sqrt(rr tt)); ``governing``: that three-mode determinant solution;
    ``multimode``: the p-k sweep over the vertical, torsional and lateral modes."""

    mode: str | None
    governing: FlutterResult | None
    multimode: MultimodeResult | None


def _lateral_effect(modal: ModalModel, aero: Any, rho: float, gov: FlutterResult | None, fopts: FlutterOptions,
                    kw: dict) -> LateralEffect | None:
    """:class:`LateralEffect`, or None when the modes or the aerodynamics have no lateral part."""
    lateral = [i for i in range(modal.n_modes) if modal.kinds[i] == "lateral" and modal.rr[i, i] > 0.0]
    if not (lateral and modal.has_lateral and has_lateral(aero)):
        return None
    triple, mode = None, None
    if gov is not None:
        j, k = modal.index(gov.pair[0]), modal.index(gov.pair[1])
        same = [i for i in lateral if modal.symmetries[i] == modal.symmetries[k]]
        if same:
            link = [abs(modal.rt[i, k]) / np.sqrt(modal.rr[i, i] * max(modal.tt[k, k], 1e-300)) for i in same]
            lat = same[int(np.argmax(link))]
            mode = modal.labels[lat]
            triple = solve_pair(modal.subset([j, k, lat]), aero, rho, fopts.max_speed_m_s, **kw)
    mm = pk_sweep(modal, aero, rho, fopts.max_speed_m_s, lateral=True, **kw) if fopts.multimode else None
    return LateralEffect(mode, triple, mm)


def _modes(scenario: Any, upstream: dict) -> tuple[ModalModel, str]:
    if "fem" in upstream:
        return upstream["fem"].data.modal_model, "fem stage"
    if scenario.kind == "section" and scenario.section is not None:
        return scenario.section.modal_model(), "sectional model"
    if scenario.modal is not None:
        return scenario.modal, "[modal] table"
    raise InputError("flutter", None, "needs modes: run the fem stage or give [modal] data")


def air_density(scenario: Any, fopts: FlutterOptions | None = None) -> float:
    """The air density of the flutter stage (module doc): a [section]'s, else [flutter]'s, else [air]'s."""
    fopts = fopts or scenario.flutter or FlutterOptions()
    section = scenario.section if scenario.kind == "section" else None
    for value in (getattr(section, "air_density_kg_m3", None), fopts.air_density_kg_m3,
                  scenario.air.density_kg_m3):
        if value is not None:
            return float(value)
    return 1.225


def options_and_aerodynamics(scenario: Any, upstream: dict) -> tuple[FlutterOptions, Any]:
    """The scenario's flutter options (a [section]'s aerodynamics taking the place of [flutter]'s) and the
    aerodynamic model they name (tables read from the scenario's folder; the aero stage's in ``upstream``)."""
    fopts: FlutterOptions = scenario.flutter or FlutterOptions()
    section = scenario.section if scenario.kind == "section" else None
    if section is not None and section.aerodynamics is not None:
        fopts = replace(fopts, aerodynamics=section.aerodynamics)
    src = scenario.source_path
    cfd = upstream["aero"].data.model if "aero" in upstream else None
    return fopts, fopts.aerodynamic_model(Path(src).parent if src else None, cfd=cfd)


def run(scenario: Any, upstream: dict, options: RunOptions) -> StageOutput:
    fopts, aero = options_and_aerodynamics(scenario, upstream)
    modal, source = _modes(scenario, upstream)
    rho = air_density(scenario, fopts)
    n_speed = min(fopts.speed_steps, QUICK_SPEED_STEPS) if options.quick else fopts.speed_steps
    kw = dict(min_speed_m_s=fopts.min_speed_m_s, n_speed=n_speed)

    options.say(f"flutter: {modal.n_modes} modes from the {source}, {aero.name} aerodynamics, rho = {rho:g}")
    pairs = tuple(solve_pair(modal.subset(p), aero, rho, fopts.max_speed_m_s, **kw)
                  for p in modal.pairs(fopts.pairs))
    gov = governing(list(pairs))
    mm = pk_sweep(modal, aero, rho, fopts.max_speed_m_s, **kw) if fopts.multimode else None
    lateral = _lateral_effect(modal, aero, rho, gov, fopts, kw)
    if lateral is not None:
        options.say(f"flutter: again with the lateral modes ({aero.name})")
    data = FlutterStageResult(modal, aero.name, rho, pairs, gov, mm, lateral)
    return StageOutput(summary=_summary(data, fopts), write_h5=lambda g: _write_h5(g, data),
                       report=_report(data, source, fopts),
                       figures={**_mode_shape_figures(data, upstream), **_figures(data)}, data=data)


def _pair_name(r: FlutterResult) -> str:
    return "+".join(r.pair)


def _number(x: float) -> float | None:
    """A summary number, or None where it does not exist (NaN/inf): summary.json stays strict JSON."""
    return float(x) if math.isfinite(x) else None


def _summary(d: FlutterStageResult, fopts: FlutterOptions) -> dict[str, float | int | bool | str | None]:
    """Headline numbers; None where there is no solution below the highest speed searched."""
    g = d.governing
    s: dict[str, float | int | bool | str | None] = {
        "flutter.flutter": g is not None, "flutter.aerodynamics": d.aerodynamics,
        "flutter.aerodynamics_option": fopts.aerodynamics,
        "flutter.max_speed_searched_m_s": float(fopts.max_speed_m_s),
        "flutter.critical_speed_m_s": None if g is None else _number(g.critical_speed_m_s),
        "flutter.frequency_hz": None if g is None else _number(g.frequency_hz),
        "flutter.reduced_frequency": None if g is None else _number(g.reduced_frequency),
        "flutter.mode_pair": None if g is None else _pair_name(g)}
    for r in d.pairs:
        key = f"flutter.pair_{_pair_name(r)}"
        s[f"{key}.critical_speed_m_s"] = _number(r.critical_speed_m_s) if r.flutter else None
        s[f"{key}.frequency_hz"] = _number(r.frequency_hz) if r.flutter else None
        s[f"{key}.no_root_in_covered_range"] = r.no_root_in_covered_range   # a table's range, not "no flutter"
    s.update(_coverage_summary(d, fopts))
    if d.multimode is not None:
        m = d.multimode
        s["flutter.multimode_critical_speed_m_s"] = _number(m.critical_speed_m_s) if m.flutter else None
        s["flutter.divergence_speed_m_s"] = _number(m.divergence_speed_m_s)
        gaps = pk_coverage(m)
        s["flutter.multimode_uncovered"] = "; ".join(gaps) if gaps else None
    s.update(_lateral_summary(d))
    return s


def _coverage_summary(d: FlutterStageResult, fopts: FlutterOptions) -> dict[str, float | bool | str | None]:
    """Where the aerodynamic data leave the two-mode search blind, for the headline.

    A pair's flutter frequency lies between its two natural frequencies, so at a speed V the search can find
    it only where the data's reduced frequencies Omega = w B / V reach that band: from V = B w_min / Omega_max
    up to B w_max / Omega_min.  ``flutter.blind_below_critical`` says, as text, below and above which speeds
    each pair's band is out of the data's reach entirely, within the speeds that matter (up to the flutter
    speed found, else the highest searched); ``flutter.data_span_every_pair`` is True when the data span every
    pair's whole band at every speed searched (only then does "no flutter" mean none below the top speed)."""
    m = d.modal_model
    lows, highs = zip(*(r.covered_omega_range for r in d.pairs), strict=True) if d.pairs else ((0.0,), (np.inf,))
    o_lo, o_hi = max(lows), min(highs)
    if o_lo <= 0.0 and not math.isfinite(o_hi):   # a closed form: every frequency at every speed
        return {"flutter.data_reduced_velocity_min": None, "flutter.data_reduced_velocity_max": None,
                "flutter.data_span_every_pair": True, "flutter.blind_below_critical": None}
    limit = d.governing.critical_speed_m_s if d.governing is not None else fopts.max_speed_m_s
    below, above = [], []
    for r in d.pairs:
        w = [2 * math.pi * m.frequencies_hz[m.index(label)] for label in r.pair]
        reach_from = m.deck_width_m * min(w) / o_hi
        reach_to = m.deck_width_m * max(w) / o_lo if o_lo > 0 else math.inf
        if reach_from > r.min_speed_searched_m_s:
            below.append((min(reach_from, limit), _pair_name(r)))
        if reach_to < limit:
            above.append((reach_to, _pair_name(r)))
    parts = []
    if below:
        lo, hi = min(v for v, _ in below), max(v for v, _ in below)
        parts.append(f"below {lo:.0f} m/s" if len(below) == 1 or hi - lo < 0.5 else
                     f"below {lo:.0f}-{hi:.0f} m/s (pair by pair: " + ", ".join(f"{p} {v:.0f}" for v, p in below) + ")")
    if above:
        parts.append("above " + ", ".join(f"{v:.0f} m/s for {p}" for v, p in above))
    return {"flutter.data_reduced_velocity_min": _number(2 * math.pi / o_hi),
            "flutter.data_reduced_velocity_max": _number(2 * math.pi / o_lo) if o_lo > 0 else None,
            "flutter.data_span_every_pair": all(not r.uncovered_speeds_m_s for r in d.pairs),
            "flutter.blind_below_critical": " and ".join(parts) if parts else None}


def _lateral_report(d: FlutterStageResult) -> list[str]:
    lat = d.lateral
    if lat is None:
        return []
    s = _lateral_summary(d)
    lines = ["", "**Lateral modes.** The aerodynamics give lateral terms (drag, sway; Scanlan's P*, H5*, H6*, "
             "A5*, A6*), so the analysis is repeated with the lateral modes that move the deck "
             "(docs/flutter.md, lateral motion)."]
    if lat.governing is not None:
        g = lat.governing
        pct = s.get("flutter.pair_lateral_effect_percent")
        lines.append(f"Governing pair with its most coupled lateral mode {lat.mode}: " + (
            f"V_c = {g.critical_speed_m_s:.2f} m/s, f_c = {g.frequency_hz:.4f} Hz"
            + (f" ({pct:+.2f} % against the pair alone)." if pct is not None else ".")
            if g.flutter else f"no flutter below {g.max_speed_searched_m_s:g} m/s."))
    if lat.multimode is not None:
        m = lat.multimode
        pct = s.get("flutter.multimode_lateral_effect_percent")
        lines.append(f"Multimode p-k with {len(m.labels)} modes including the lateral ones: " + (
            f"V_c = {m.critical_speed_m_s:.2f} m/s in mode {m.unstable_mode}"
            + (f" ({pct:+.2f} % against vertical and torsional modes only)." if pct is not None else ".")
            if m.flutter else f"no flutter below {m.max_speed_searched_m_s:g} m/s."))
    return lines


def _lateral_summary(d: FlutterStageResult) -> dict[str, float | str | None]:
    """The V_c with the lateral modes and their effect in per cent (present only when computed)."""
    lat = d.lateral
    if lat is None:
        return {}
    out: dict[str, float | str | None] = {"flutter.lateral_mode": lat.mode}
    if lat.governing is not None:
        v = lat.governing.critical_speed_m_s if lat.governing.flutter else math.nan
        out["flutter.pair_with_lateral_critical_speed_m_s"] = _number(v)
        if d.governing is not None:
            out["flutter.pair_lateral_effect_percent"] = _number(100.0 * (v / d.governing.critical_speed_m_s - 1))
    if lat.multimode is not None:
        v = lat.multimode.critical_speed_m_s if lat.multimode.flutter else math.nan
        out["flutter.multimode_with_lateral_critical_speed_m_s"] = _number(v)
        if d.multimode is not None and d.multimode.flutter:
            out["flutter.multimode_lateral_effect_percent"] = _number(
                100.0 * (v / d.multimode.critical_speed_m_s - 1))
    return out


def _text(group: Any, name: str, values: Any, description: str) -> None:
    write_dataset(group, name, [str(v) for v in values], "", description)


def _write_h5(group: Any, d: FlutterStageResult) -> None:
    """Fill ``results.h5:/flutter`` (``group`` is an h5py Group); see docs/results.md, section ``/flutter``.
    Every dataset has a ``unit`` ("1" dimensionless, "" text or flag) and a ``description`` (shape, meaning)."""
    group.attrs["aerodynamics"] = d.aerodynamics
    group.attrs["air_density_kg_m3"] = d.air_density_kg_m3
    m = d.modal_model
    n = m.n_modes
    g = group.create_group("modal")
    _text(g, "labels", m.labels, f"({n},) labels of the modes used, e.g. S-V1 (symmetry-kind letter count)")
    _text(g, "kinds", m.kinds, f"({n},) vertical / torsional / lateral")
    _text(g, "symmetries", m.symmetries, f"({n},) S (symmetric) or SS (skew-symmetric) about mid-span")
    write_dataset(g, "frequencies_hz", np.asarray(m.frequencies_hz, dtype=np.float64), "Hz",
                  f"({n},) undamped natural frequencies f_i")
    write_dataset(g, "damping_ratios", np.asarray(m.damping_ratios, dtype=np.float64), "1",
                  f"({n},) structural damping ratios zeta_i")
    for name, what in (("uu", "U_i U_j"), ("ut", "U_i Theta_j"), ("tt", "Theta_i Theta_j"),
                       ("rr", "R_i R_j"), ("ur", "U_i R_j"), ("rt", "R_i Theta_j")):
        write_dataset(g, name, np.asarray(getattr(m, name), dtype=np.float64), "1",
                      f"({n}, {n}) (1/L) int {what} dz over the deck length L (Eq 4.34; R: lateral deck "
                      "displacement, positive downwind)")
    given = m.generalised_masses is not None
    write_dataset(g, "modal_masses", np.asarray(m.modal_masses, dtype=np.float64), "kg or kg m^2",
                  f"({n},) " + ("generalised masses as given in [modal]" if given else
                                "m_i = L (mu (uu_ii + rr_ii) + J tt_ii) (Eq 4.33 with the lateral motion)")
                  + ": kg for vertical and lateral modes, kg m^2 for torsional modes")
    for name in ("mass_per_length_kg_m", "inertia_per_length_kg_m2_m", "deck_width_m", "deck_length_m"):
        g.attrs[name] = getattr(m, name)
    p = group.create_group("pairs")
    n_p = len(d.pairs)
    _text(p, "bending", [r.pair[0] for r in d.pairs], f"({n_p},) bending (vertical) mode of each pair")
    _text(p, "torsion", [r.pair[1] for r in d.pairs], f"({n_p},) torsional mode of each pair")
    write_dataset(p, "flutter", np.array([r.flutter for r in d.pairs], dtype=np.int8), "",
                  f"({n_p},) flag: 1 if the pair flutters below its maximum speed searched, else 0")
    write_dataset(p, "no_root_in_covered_range", np.array([r.no_root_in_covered_range for r in d.pairs],
                                                          dtype=np.int8), "",
                  f"({n_p},) flag: 1 if no root was found but the aerodynamic table did not cover the whole "
                  "search (not 'no flutter'), else 0")
    write_dataset(p, "covered_omega_range", np.array([r.covered_omega_range for r in d.pairs]), "1",
                  f"({n_p}, 2) [pair, (low, high)] reduced frequencies Omega = w B / V the aerodynamic model "
                  "covers (0, inf for a closed form)")
    for name, unit, what in (
            ("critical_speed_m_s", "m/s", "critical wind speed V_c (NaN if none)"),
            ("frequency_hz", "Hz", "flutter frequency f_c (NaN if none)"),
            ("reduced_frequency", "1", "reduced flutter frequency Omega_c = w_c B / V_c, Eq 4.38 (NaN if none)"),
            ("residual", "1", "|det D| / (|D11 D22| + |D12 D21|) at the solution (Eq 5.16)"),
            ("min_speed_searched_m_s", "m/s", "lowest wind speed of the bracketing scan"),
            ("max_speed_searched_m_s", "m/s", "highest wind speed of the bracketing scan")):
        write_dataset(p, name, np.array([getattr(r, name) for r in d.pairs], dtype=np.float64), unit,
                      f"({n_p},) {what}")
    write_dataset(p, "iterations", np.array([r.iterations for r in d.pairs], dtype=np.int64), "1",
                  f"({n_p},) Newton-Raphson iterations (Eq 5.19-5.21; 0 if no flutter)")
    gv = group.create_group("governing")
    gv.attrs["flutter"] = int(d.governing is not None)
    if d.governing is not None:
        r = d.governing
        gv.attrs["mode_pair"] = _pair_name(r)
        for name in ("critical_speed_m_s", "frequency_hz", "reduced_frequency", "iterations", "residual"):
            gv.attrs[name] = getattr(r, name)
    shown = d.governing or d.pairs[0]
    if shown.scan is not None:
        sc = shown.scan
        g = group.create_group("determinant_map")
        g.attrs["mode_pair"] = _pair_name(shown)
        shape = "x".join(str(k) for k in sc.f1.shape)
        write_dataset(g, "reduced_frequency", sc.reduced_frequency, "1",
                      f"({shape}) [Omega row, V column] Omega = w B / V at each scan point (w on a fixed grid)")
        write_dataset(g, "speed_m_s", sc.speed_m_s, "m/s", f"({sc.speed_m_s.size},) wind speeds of the columns")
        for name, part in (("f1", "real"), ("f2", "imaginary")):
            write_dataset(g, name, getattr(sc, name), "1",
                          f"({shape}) {part} part of det D(Omega, V), the reduced determinant of pair "
                          f"{_pair_name(shown)} (Eq 5.15-5.16); NaN outside a table's range")
    if d.multimode is not None:
        _write_multimode(group.create_group("multimode"), d.multimode, "vertical and torsional modes")
    if d.lateral is not None:
        lat = d.lateral
        g = group.create_group("lateral")
        g.attrs["lateral_mode"] = lat.mode or ""
        if lat.governing is not None:
            g.attrs["pair_with_lateral"] = _pair_name(lat.governing)
            g.attrs["pair_with_lateral_flutter"] = int(lat.governing.flutter)
            g.attrs["pair_with_lateral_critical_speed_m_s"] = lat.governing.critical_speed_m_s
            g.attrs["pair_with_lateral_frequency_hz"] = lat.governing.frequency_hz
        if lat.multimode is not None:
            _write_multimode(g.create_group("multimode"), lat.multimode,
                             "vertical, torsional and lateral modes")


def _write_multimode(g: Any, mm: MultimodeResult, which: str) -> None:
    """One p-k sweep into group ``g`` (``/flutter/multimode``, ``/flutter/lateral/multimode``)."""
    nv, nm = mm.damping_ratio.shape
    _text(g, "labels", mm.labels, f"({nm},) {which} of the p-k sweep (columns below)")
    write_dataset(g, "speed_m_s", mm.speed_m_s, "m/s", f"({nv},) wind speeds of the sweep (rows below)")
    write_dataset(g, "frequency_hz", mm.frequency_hz, "Hz",
                  f"({nv}, {nm}) [speed, mode] p-k frequency Im(s) / 2 pi; 0 on a non-oscillatory "
                  "branch (real eigenvalue); NaN where the mode left the aerodynamic model's range or "
                  "found no root")
    write_dataset(g, "damping_ratio", mm.damping_ratio, "1",
                  f"({nv}, {nm}) [speed, mode] total (structural + aerodynamic) damping ratio "
                  "-Re(s) / |s|; exactly +1 (decaying) or -1 (growing: static divergence) on a "
                  "non-oscillatory branch (real eigenvalue, frequency 0); NaN as for frequency_hz")
    g.attrs["flutter"] = int(mm.flutter)
    g.attrs["critical_speed_m_s"] = mm.critical_speed_m_s
    g.attrs["frequency_hz"] = mm.frequency_hz_at_flutter
    g.attrs["reduced_frequency"] = mm.reduced_frequency
    g.attrs["unstable_mode"] = mm.unstable_mode
    g.attrs["divergence_speed_m_s"] = mm.divergence_speed_m_s
    g.attrs["unresolved_points"] = len(mm.unresolved)
    if mm.unresolved:
        _text(g, "unresolved_mode", [u[0] for u in mm.unresolved],
              "modes whose p-k iteration found no root on the tracked branch (NaN in the sweep)")
        write_dataset(g, "unresolved_speed_m_s", [u[1] for u in mm.unresolved], "m/s",
                      "wind speeds of those points, one per unresolved_mode entry")


def pk_coverage(m: MultimodeResult) -> list[str]:
    """'MODE a-b m/s[, c-d m/s]' for each p-k mode whose damping the aerodynamic data leave out at some of the
    speeds searched: the stretches where it was computed.  A single missing point between two computed ones
    is an unresolved point (reported apart), not a gap in the data."""
    out = []
    v = m.speed_m_s
    for i, lab in enumerate(m.labels):
        ok = np.isfinite(m.damping_ratio[:, i])
        ok[1:-1] |= ok[:-2] & ok[2:]
        if ok.all():
            continue
        if not ok.any():
            out.append(f"{lab} at no speed searched")
            continue
        edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(np.int8), [0]])))
        out.append(f"{lab} " + ", ".join(f"{v[a]:.1f}-{v[b - 1]:.1f} m/s" for a, b in zip(edges[::2], edges[1::2],
                                                                                            strict=True)))
    return out


def _report(d: FlutterStageResult, source: str, fopts: FlutterOptions) -> str:
    lines = ["## Flutter", "",
             f"Modes from the {source}; {d.aerodynamics} aerodynamics; air density {d.air_density_kg_m3:g} kg/m^3; "
             f"speeds searched up to {fopts.max_speed_m_s:g} m/s.  Two-mode determinant method (thesis Eq 4.29, "
             "reduced form derived in docs/flutter.md), Newton-Raphson in (Omega, V) from a bracketing scan.", "",
             "| Pair | Flutter | V_c [m/s] | f_c [Hz] | Omega_c | Newton iterations | residual |",
             "|---|---|---|---|---|---|---|"]
    for r in d.pairs:
        if r.flutter:
            lines.append(f"| {_pair_name(r)} | yes | {r.critical_speed_m_s:.2f} | {r.frequency_hz:.4f} | "
                         f"{r.reduced_frequency:.4f} | {r.iterations} | {r.residual:.1e} |")
        elif r.no_root_in_covered_range:
            o_lo, o_hi = r.covered_omega_range
            lines.append(f"| {_pair_name(r)} | no root in the covered range (Omega {o_lo:.4g}-{o_hi:.4g}, "
                         f"V {r.min_speed_searched_m_s:g}-{r.max_speed_searched_m_s:g} m/s) | | | | | |")
        else:
            lines.append(f"| {_pair_name(r)} | none below {r.max_speed_searched_m_s:g} m/s | | | | | |")
    lines.append("")
    # where a table's Omega range left part of the search without data: which speeds, for which pair
    gaps = [r for r in d.pairs if not r.scan_covered]
    if gaps:
        o_lo, o_hi = gaps[0].covered_omega_range
        lines.append(f"The aerodynamic data cover Omega = w B / V in [{o_lo:.4g}, {o_hi:.4g}] only; no root is "
                     "searched outside (never extrapolated).  Speeds at which they do not cover the natural "
                     "frequencies of a pair (Omega outside the range for some f between the pair's two):")
        for r in gaps:
            f = [d.modal_model.frequencies_hz[d.modal_model.index(lab)] for lab in r.pair]
            where = ", ".join(f"{a:.1f}-{b:.1f} m/s" for a, b in r.uncovered_speeds_m_s) or "none"
            lines.append(f"* {_pair_name(r)} ({min(f):.4f}-{max(f):.4f} Hz): {where}"
                         + ("; no root in the covered range." if r.no_root_in_covered_range else "."))
        lines.append("")
    if d.governing is not None:
        g = d.governing
        lines.append(f"Governing pair {_pair_name(g)}: **V_c = {g.critical_speed_m_s:.2f} m/s**, "
                     f"f_c = {g.frequency_hz:.4f} Hz, Omega_c = {g.reduced_frequency:.4f}"
                     + (" (the lowest root found; see the speeds without data above)." if gaps else "."))
    elif gaps:
        lines.append(f"**No flutter found** where the aerodynamic data reach (up to {fopts.max_speed_m_s:g} m/s); "
                     "that is not 'no flutter': see the speeds without data above.")
    else:
        lines.append(f"**No flutter** of any pair below {fopts.max_speed_m_s:g} m/s.")
    lines += _lateral_report(d)
    if d.multimode is not None:
        m = d.multimode
        lines += ["", f"Multimode p-k with {len(m.labels)} modes ({', '.join(m.labels)}): " + (
            f"first zero damping at V = {m.critical_speed_m_s:.2f} m/s in mode {m.unstable_mode} "
            f"(f = {m.frequency_hz_at_flutter:.4f} Hz)." if m.flutter
            else f"no damping ratio of an oscillating mode crosses zero below {m.max_speed_searched_m_s:g} m/s.")]
        covered = pk_coverage(m)
        if covered:
            lines.append("Damping computed only where the aerodynamic data cover the mode's frequency (Omega inside "
                         "the table; elsewhere NaN, and a crossing there cannot be found): " + "; ".join(covered) + ".")
        if not math.isnan(m.divergence_speed_m_s):
            lines.append(f"Static divergence (frequency to zero) at V = {m.divergence_speed_m_s:.2f} m/s.")
        real = [lab for i, lab in enumerate(m.labels) if not m.oscillatory[:, i].all()]
        if real:
            lines.append(f"Non-oscillatory branches ({', '.join(real)}): above some speed the tracked p-k "
                         "eigenvalue is real (frequency 0), so -Re(s)/|s| is exactly +1 (decaying: aerodynamic "
                         "damping above critical) or -1 (growing: static divergence); these points are no "
                         "damping ratio of an oscillation and are drawn as crosses at f = 0 in "
                         "flutter_damping.png, not as damping ratios.")
        if m.unresolved:
            pts = ", ".join(f"{lab} at {v:.1f} m/s" for lab, v in m.unresolved[:8])
            lines.append(f"p-k found no frequency root on the tracked branch at {len(m.unresolved)} point(s) "
                         f"({pts}{', ...' if len(m.unresolved) > 8 else ''}): gaps (NaN) in the damping plot; "
                         "the determinant method is unaffected.")
    return "\n".join(lines) + "\n"


def _mode_shape_figures(d: FlutterStageResult, upstream: dict) -> dict[str, Any]:
    """Mode shapes of the governing pair and of the p-k mode that goes unstable, when the modes come from
    the fem stage (its result has the shapes; a [modal] table or a section has none); a figure the fem
    stage already made under the same file name is not drawn again."""
    fem = upstream.get("fem")
    result = getattr(fem, "data", None)
    if not hasattr(result, "modes"):          # modes from a table or a section model: no shapes to draw
        return {}
    from bridge.structure.plots import mode_shape_figure, mode_shape_file_name

    roles: dict[str, str] = {}
    if d.governing is not None:
        for label in d.governing.pair:
            roles[label] = f"governing flutter pair {_pair_name(d.governing)}"
    if d.multimode is not None and d.multimode.flutter:
        roles.setdefault(d.multimode.unstable_mode, "goes unstable in the multimode p-k sweep")
    return {mode_shape_file_name(label): mode_shape_figure(result, label, note)
            for label, note in roles.items() if mode_shape_file_name(label) not in fem.figures}


def _damping_figure(m: MultimodeResult) -> Any:
    """p-k damping ratio and frequency against V: the branch that goes unstable (or, without flutter, the
    least damped one) in colour, the others thin grey (S solid, SS dashed).  Non-oscillatory points (real
    eigenvalue, ``MultimodeResult.oscillatory`` False: zeta exactly +-1) are left out of the damping panel
    and marked by crosses at f = 0 in the frequency panel."""
    from matplotlib.figure import Figure  # Agg canvas, no pyplot state

    osc = m.oscillatory
    zeta = np.where(osc, m.damping_ratio, np.nan)
    if m.flutter:
        key = m.labels.index(m.unstable_mode)
        key_text = f"{m.unstable_mode}: goes unstable"
    else:
        key = int(np.argmin(np.nanmin(np.where(np.isnan(zeta), np.inf, zeta), axis=0)))
        key_text = f"{m.labels[key]}: least damped (no flutter)"
    fig = Figure(figsize=(8.0, 6.4), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for i, label in enumerate(m.labels):
        if i == key:
            continue
        style = dict(color="0.65", lw=0.8, ls="--" if label.startswith("SS-") else "-")
        ax1.plot(m.speed_m_s, zeta[:, i], **style)
        ax2.plot(m.speed_m_s, np.where(osc[:, i], m.frequency_hz[:, i], np.nan), **style)
    ax1.plot(m.speed_m_s, zeta[:, key], color="C3", lw=2.2, label=key_text)
    ax2.plot(m.speed_m_s, np.where(osc[:, key], m.frequency_hz[:, key], np.nan), color="C3", lw=2.2)
    ax1.plot([], [], color="0.65", lw=0.8, label="other modes (S solid, SS dashed)")
    real = ~osc & np.isfinite(m.frequency_hz)
    if real.any():
        rows = np.nonzero(real)[0]
        ax2.plot(m.speed_m_s[rows], np.zeros(rows.size), "x", color="0.35", ms=4,
                 label="non-oscillatory (real eigenvalue, f = 0: zeta = +-1, not drawn above)")
    ax1.axhline(0.0, color="k", lw=0.5)
    for ax, labelled in ((ax1, True), (ax2, False)):
        if m.flutter:
            ax.axvline(m.critical_speed_m_s, color="k", ls=":",
                       label=f"flutter V_c = {m.critical_speed_m_s:.1f} m/s" if labelled else None)
        if np.isfinite(m.divergence_speed_m_s):
            ax.axvline(m.divergence_speed_m_s, color="C1", ls="-.",
                       label=f"static divergence V_D = {m.divergence_speed_m_s:.1f} m/s" if labelled else None)
        ax.grid(alpha=0.3)
    ax1.set_ylabel("total damping ratio zeta [-]")
    ax2.set_ylabel("frequency [Hz]")
    ax2.set_xlabel("V [m/s]")
    ax1.legend(fontsize="small", loc="upper left")
    if real.any():
        ax2.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.18))
    ax1.set_title(f"Multimode p-k, {len(m.labels)} modes: damping ratio -Re(s)/|s| and frequency against V")
    return fig


def _figures(d: FlutterStageResult) -> dict[str, Any]:
    from matplotlib.figure import Figure  # Agg canvas, no pyplot state

    figs: dict[str, Any] = {}
    shown = d.governing or d.pairs[0]
    if shown.scan is not None:
        s = shown.scan
        fig = Figure(figsize=(6.4, 4.8))
        ax = fig.add_subplot()
        V = np.broadcast_to(s.speed_m_s, s.reduced_frequency.shape)
        ok = np.isfinite(s.f1)
        if np.any(ok):
            ax.contour(V, s.reduced_frequency, np.where(ok, s.f1, np.nan), levels=[0.0], colors="C0")
            ax.contour(V, s.reduced_frequency, np.where(ok, s.f2, np.nan), levels=[0.0], colors="C1",
                       linestyles="--")
        ax.plot([], [], "C0", label="f1 = Re det = 0")
        ax.plot([], [], "C1--", label="f2 = Im det = 0")
        if shown.flutter:
            ax.plot(shown.critical_speed_m_s, shown.reduced_frequency, "ko", label="(V_c, Omega_c)")
        ax.set_yscale("log")
        ax.set_xlabel("V [m/s]")
        ax.set_ylabel("reduced frequency Omega = w B / V [-]")
        ax.set_title(f"Determinant components, pair {_pair_name(shown)} (Eq 5.16)")
        ax.legend()
        figs["flutter_determinant.png"] = fig
    if d.multimode is not None:
        figs["flutter_damping.png"] = _damping_figure(d.multimode)
    return figs
