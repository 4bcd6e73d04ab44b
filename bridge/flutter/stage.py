"""The flutter stage of the pipeline: modes in, critical wind speed out.

``run(scenario, upstream, options) -> StageOutput``.  Modes come from, in this order,
``upstream["fem"].data.modal_model`` (a :class:`ModalModel`), ``scenario.section`` (a
:class:`SectionModel`, when ``scenario.kind == "section"``) or ``scenario.modal`` (a ModalModel).
Options from ``scenario.flutter`` (a :class:`FlutterOptions`; defaults if absent).  Air density:
``section.air_density_kg_m3``, else ``flutter.air_density_kg_m3``, else ``scenario.air.density_kg_m3``,
else 1.225.  Every (bending, torsion) pair is solved by the determinant method; the governing pair is
the one with the lowest critical speed; the p-k multimode sweep runs on all vertical and torsional
modes.  HDF5 datasets are documented in docs/results_flutter.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from bridge.errors import InputError
from bridge.flutter.determinant import FlutterResult, governing, solve_pair
from bridge.flutter.modal import ModalModel
from bridge.flutter.multimode import MultimodeResult, pk_sweep
from bridge.flutter.options import FlutterOptions
from bridge.results import write_dataset
from bridge.stages import RunOptions, StageOutput

__all__ = ["run", "FlutterStageResult"]

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


def _modes(scenario: Any, upstream: dict) -> tuple[ModalModel, str]:
    if "fem" in upstream:
        return upstream["fem"].data.modal_model, "fem stage"
    if getattr(scenario, "kind", None) == "section" and getattr(scenario, "section", None) is not None:
        return scenario.section.modal_model(), "sectional model"
    if getattr(scenario, "modal", None) is not None:
        return scenario.modal, "[modal] table"
    raise InputError("flutter", None, "needs modes: run the fem stage or give [modal] data")


def _air_density(scenario: Any, fopts: FlutterOptions) -> float:
    section = getattr(scenario, "section", None) if getattr(scenario, "kind", None) == "section" else None
    for value in (getattr(section, "air_density_kg_m3", None), fopts.air_density_kg_m3,
                  getattr(getattr(scenario, "air", None), "density_kg_m3", None)):
        if value is not None:
            return float(value)
    return 1.225


def run(scenario: Any, upstream: dict, options: RunOptions) -> StageOutput:
    fopts: FlutterOptions = getattr(scenario, "flutter", None) or FlutterOptions()
    modal, source = _modes(scenario, upstream)
    section = getattr(scenario, "section", None) if getattr(scenario, "kind", None) == "section" else None
    if section is not None and section.aerodynamics is not None:
        fopts = replace(fopts, aerodynamics=section.aerodynamics)
    src = getattr(scenario, "source_path", None)
    aero = fopts.aerodynamic_model(Path(src).parent if src else None)
    rho = _air_density(scenario, fopts)
    n_speed = min(fopts.speed_steps, QUICK_SPEED_STEPS) if options.quick else fopts.speed_steps
    kw = dict(min_speed_m_s=fopts.min_speed_m_s, n_speed=n_speed)

    options.say(f"flutter: {modal.n_modes} modes from the {source}, {aero.name} aerodynamics, rho = {rho:g}")
    pairs = tuple(solve_pair(modal.subset(p), aero, rho, fopts.max_speed_m_s, **kw)
                  for p in modal.pairs(fopts.pairs))
    gov = governing(list(pairs))
    mm = pk_sweep(modal, aero, rho, fopts.max_speed_m_s, **kw) if fopts.multimode else None
    data = FlutterStageResult(modal, aero.name, rho, pairs, gov, mm)
    return StageOutput(summary=_summary(data, fopts), write_h5=lambda g: _write_h5(g, data),
                       report=_report(data, source, fopts), figures=_figures(data), data=data)


def _pair_name(r: FlutterResult) -> str:
    return f"{r.pair[0]}+{r.pair[1]}"


def _summary(d: FlutterStageResult, fopts: FlutterOptions) -> dict[str, float | int | str]:
    g = d.governing
    s: dict[str, float | int | str] = {"flutter.flutter": int(g is not None),
                                       "flutter.max_speed_searched_m_s": float(fopts.max_speed_m_s)}
    if g is not None:
        s.update({"flutter.critical_speed_m_s": g.critical_speed_m_s, "flutter.frequency_hz": g.frequency_hz,
                  "flutter.reduced_frequency": g.reduced_frequency, "flutter.mode_pair": _pair_name(g)})
    else:
        s.update({k: "none" for k in ("flutter.critical_speed_m_s", "flutter.frequency_hz",
                                      "flutter.reduced_frequency", "flutter.mode_pair")})
    for r in d.pairs:
        key = f"flutter.pair_{r.pair[0]}+{r.pair[1]}"
        s[f"{key}.critical_speed_m_s"] = r.critical_speed_m_s if r.flutter else "none"
        s[f"{key}.frequency_hz"] = r.frequency_hz if r.flutter else "none"
    if d.multimode is not None:
        m = d.multimode
        s["flutter.multimode_critical_speed_m_s"] = m.critical_speed_m_s if m.flutter else "none"
        s["flutter.divergence_speed_m_s"] = "none" if math.isnan(m.divergence_speed_m_s) else m.divergence_speed_m_s
    return s


def _write_h5(group: Any, d: FlutterStageResult) -> None:
    """Fill ``results.h5:/flutter`` (``group`` is an h5py Group); see docs/results_flutter.md."""
    import h5py

    text = h5py.string_dtype()
    group.attrs["aerodynamics"] = d.aerodynamics
    group.attrs["air_density_kg_m3"] = d.air_density_kg_m3
    m = d.modal_model
    g = group.create_group("modal")
    g.create_dataset("labels", data=np.array(m.labels, dtype=object), dtype=text)
    g.create_dataset("kinds", data=np.array(m.kinds, dtype=object), dtype=text)
    g.create_dataset("symmetries", data=np.array(m.symmetries, dtype=object), dtype=text)
    for name in ("frequencies_hz", "damping_ratios", "uu", "ut", "tt", "modal_masses"):
        g.create_dataset(name, data=np.asarray(getattr(m, name), dtype=np.float64))
    for name in ("mass_per_length_kg_m", "inertia_per_length_kg_m2_m", "deck_width_m", "deck_length_m"):
        g.attrs[name] = getattr(m, name)
    p = group.create_group("pairs")
    p.create_dataset("bending", data=np.array([r.pair[0] for r in d.pairs], dtype=object), dtype=text)
    p.create_dataset("torsion", data=np.array([r.pair[1] for r in d.pairs], dtype=object), dtype=text)
    p.create_dataset("flutter", data=np.array([r.flutter for r in d.pairs], dtype=np.int8))
    for name in ("critical_speed_m_s", "frequency_hz", "reduced_frequency", "residual",
                 "min_speed_searched_m_s", "max_speed_searched_m_s"):
        p.create_dataset(name, data=np.array([getattr(r, name) for r in d.pairs], dtype=np.float64))
    p.create_dataset("iterations", data=np.array([r.iterations for r in d.pairs], dtype=np.int64))
    gv = group.create_group("governing")
    gv.attrs["flutter"] = int(d.governing is not None)
    if d.governing is not None:
        r = d.governing
        gv.attrs["mode_pair"] = _pair_name(r)
        for name in ("critical_speed_m_s", "frequency_hz", "reduced_frequency", "iterations", "residual"):
            gv.attrs[name] = getattr(r, name)
    shown = d.governing or d.pairs[0]
    if shown.scan is not None:
        s = group.create_group("determinant_map")
        s.attrs["mode_pair"] = _pair_name(shown)
        s.create_dataset("reduced_frequency", data=shown.scan.reduced_frequency)
        s.create_dataset("speed_m_s", data=shown.scan.speed_m_s)
        s.create_dataset("f1", data=shown.scan.f1)
        s.create_dataset("f2", data=shown.scan.f2)
    if d.multimode is not None:
        mm = d.multimode
        g = group.create_group("multimode")
        g.create_dataset("labels", data=np.array(mm.labels, dtype=object), dtype=text)
        g.create_dataset("speed_m_s", data=mm.speed_m_s)
        g.create_dataset("frequency_hz", data=mm.frequency_hz)
        g.create_dataset("damping_ratio", data=mm.damping_ratio)
        g.attrs["flutter"] = int(mm.flutter)
        g.attrs["critical_speed_m_s"] = mm.critical_speed_m_s
        g.attrs["frequency_hz"] = mm.frequency_hz_at_flutter
        g.attrs["reduced_frequency"] = mm.reduced_frequency
        g.attrs["unstable_mode"] = mm.unstable_mode
        g.attrs["divergence_speed_m_s"] = mm.divergence_speed_m_s
        g.attrs["unresolved_points"] = len(mm.unresolved)
        if mm.unresolved:
            write_dataset(g, "unresolved_mode", [u[0] for u in mm.unresolved], "",
                          "modes whose p-k iteration found no root on the tracked branch (NaN in the sweep)")
            write_dataset(g, "unresolved_speed_m_s", [u[1] for u in mm.unresolved], "m/s", "speeds of those points")


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
        else:
            lines.append(f"| {_pair_name(r)} | none below {r.max_speed_searched_m_s:g} m/s | | | | | |")
    lines.append("")
    if d.governing is not None:
        g = d.governing
        lines.append(f"Governing pair {_pair_name(g)}: **V_c = {g.critical_speed_m_s:.2f} m/s**, "
                     f"f_c = {g.frequency_hz:.4f} Hz, Omega_c = {g.reduced_frequency:.4f}.")
    else:
        lines.append(f"**No flutter** of any pair below {fopts.max_speed_m_s:g} m/s.")
    if d.multimode is not None:
        m = d.multimode
        lines += ["", f"Multimode p-k with {len(m.labels)} modes ({', '.join(m.labels)}): " + (
            f"first zero damping at V = {m.critical_speed_m_s:.2f} m/s in mode {m.unstable_mode} "
            f"(f = {m.frequency_hz_at_flutter:.4f} Hz)." if m.flutter
            else f"no damping ratio of an oscillating mode crosses zero below {m.max_speed_searched_m_s:g} m/s.")]
        if not math.isnan(m.divergence_speed_m_s):
            lines.append(f"Static divergence (frequency to zero) at V = {m.divergence_speed_m_s:.2f} m/s.")
        if m.unresolved:
            pts = ", ".join(f"{lab} at {v:.1f} m/s" for lab, v in m.unresolved[:8])
            lines.append(f"p-k found no frequency root on the tracked branch at {len(m.unresolved)} point(s) "
                         f"({pts}{', ...' if len(m.unresolved) > 8 else ''}): gaps (NaN) in the damping plot; "
                         "the determinant method is unaffected.")
    return "\n".join(lines) + "\n"


def _figures(d: FlutterStageResult) -> dict[str, Any]:
    import matplotlib
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
        ax.set_ylabel("Omega = w B / V")
        ax.set_title(f"Determinant components, pair {_pair_name(shown)} (Eq 5.16)")
        ax.legend()
        figs["flutter_determinant.png"] = fig
    if d.multimode is not None:
        m = d.multimode
        fig = Figure(figsize=(8.0, 6.4), layout="constrained")
        ax1, ax2 = fig.add_subplot(2, 1, 1), fig.add_subplot(2, 1, 2)
        colours = matplotlib.colormaps["tab20"]
        for i, label in enumerate(m.labels):
            style = dict(color=colours(i % 20), ls="--" if label.startswith("SS-") else "-", label=label)
            ax1.plot(m.speed_m_s, m.damping_ratio[:, i], **style)
            ax2.plot(m.speed_m_s, m.frequency_hz[:, i], **style)
        ax1.axhline(0.0, color="k", lw=0.5)
        if m.flutter:
            ax1.axvline(m.critical_speed_m_s, color="k", ls=":", label=f"V_c = {m.critical_speed_m_s:.1f} m/s")
        ax1.set_ylabel("damping ratio")
        ax2.set_ylabel("frequency [Hz]")
        ax2.set_xlabel("V [m/s]")
        ax1.legend(fontsize="small", loc="center left", bbox_to_anchor=(1.01, 0.0),
                   ncol=1 + len(m.labels) // 13)
        ax1.set_title("Multimode p-k: damping and frequency against wind speed")
        figs["flutter_damping.png"] = fig
    return figs
