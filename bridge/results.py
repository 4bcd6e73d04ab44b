"""Writing a run's results: ``results.h5``, ``summary.json``, ``report.md`` and PNG plots.

Results are never lost or misplaced:

* a result folder that exists is not replaced unless the caller says ``overwrite`` (command line
  ``--overwrite``); then only the files the earlier run wrote (listed in its ``summary.json`` under
  ``run.files``) are replaced, and every other file in the folder is kept;
* everything is written into a temporary folder beside the target, and the finished folder is renamed
  into place: a failed or interrupted run leaves the earlier result as it was;
* every file gets the same permissions (:mod:`bridge.files`); ``summary.json`` is strict JSON (RFC 8259:
  ``null`` for a number that does not exist, ``true``/``false`` for flags, never NaN or Infinity).

The HDF5 schema is documented in ``docs/results.md``.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import tempfile
from collections.abc import Mapping
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from . import __version__
from .config import Scenario, scenario_fields
from .errors import InputError
from .files import file_mode, folder_mode
from .interrupts import sigint_held
from .stages import StageOutput

__all__ = ["write_results", "write_dataset", "check_target", "summary_json", "headline", "SCHEMA_VERSION"]

SCHEMA_VERSION = "1"


def write_dataset(group: h5py.Group, name: str, data: Any, unit: str, description: str) -> None:
    """Write one dataset with its ``unit`` ("1": dimensionless number, "": text or flag) and
    ``description`` attributes (strings become UTF-8)."""
    arr = np.asarray(data)
    if arr.dtype.kind in "UO":
        arr = np.asarray(arr, dtype=h5py.string_dtype())
    ds = group.create_dataset(name, data=arr)
    ds.attrs["unit"] = unit  # always both attributes: "" for text and flags (docs/results.md)
    ds.attrs["description"] = description


def json_value(v: Any) -> Any:
    """A value as strict JSON: NumPy scalars and arrays unwrapped, NaN and infinities (no result) as null,
    through lists, tuples and dicts."""
    if isinstance(v, np.ndarray):
        v = v.tolist()
    if isinstance(v, (np.bool_, bool)):
        return bool(v)
    if isinstance(v, (np.floating, np.integer)):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, (list, tuple)):
        return [json_value(x) for x in v]
    if isinstance(v, Mapping):
        return {k: json_value(x) for k, x in v.items()}
    return v


def summary_json(summary: Mapping[str, Any]) -> str:
    """``summary`` as strict JSON text (raises ValueError rather than write NaN or Infinity)."""
    return json.dumps(json_value(summary), indent=2, allow_nan=False) + "\n"


def _fmt(v: Any, spec: str, unit: str = "") -> str | None:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        return None
    return f"{v:{spec}}{unit}"


def headline(summary: Mapping[str, Any]) -> list[str]:
    """The few numbers a user runs the program for, one line each, from the summary keys of the stages
    that ran: the flutter speed with its frequency and governing modes, which aerodynamics gave it and how
    far to trust them, where the aerodynamic data leave the search blind, the multimode speed and the
    divergence speed; without the flutter stage, the first frequencies or the cable force."""
    s, lines = summary, []
    if "flutter.critical_speed_m_s" in s:
        vc_value = s.get("flutter.critical_speed_m_s")
        vc = _fmt(vc_value, ".1f", " m/s")
        aero = s.get("flutter.aerodynamics")
        aero = f", {aero} aerodynamics" if isinstance(aero, str) else ""
        blind = s.get("flutter.blind_below_critical")
        data = _data_range(s)
        if vc is None:
            top = _fmt(s.get("flutter.max_speed_searched_m_s"), ".0f", " m/s") or "the highest speed searched"
            if s.get("flutter.data_span_every_pair", True):
                lines.append(f"no flutter of any mode pair below {top}{aero}")
            else:
                lines.append(f"NO FLUTTER SPEED FOUND, AND NONE RULED OUT below {top}: the aerodynamic data{data} do "
                             "not span the mode pairs' frequencies at every speed searched"
                             + (f"; they miss them entirely {blind}" if blind else "")
                             + " (report.md lists where); widen the reduced velocities")
        else:
            f = _fmt(s.get("flutter.frequency_hz"), ".4f", " Hz")
            om = _fmt(s.get("flutter.reduced_frequency"), ".3f")
            lines.append(f"flutter speed V_c = {vc} at f = {f} (Omega = {om}), governing modes "
                         f"{s.get('flutter.mode_pair')} (two-mode determinant{aero})")
            if blind:
                lines.append(f"not searched {blind}: there the aerodynamic data{data} do not reach the modes' "
                             "frequencies, so a flutter speed there is not ruled out")
        trust = _trust(s, vc_value)
        if trust:
            lines.append(trust)
        partly = ("no flutter where the data cover the modes, which for some modes is only part of the speeds "
                  "searched (report.md lists where)")
        if "flutter.multimode_critical_speed_m_s" in s:
            mm = _fmt(s.get("flutter.multimode_critical_speed_m_s"), ".1f", " m/s")
            gaps = s.get("flutter.multimode_uncovered")
            if mm:
                lines.append(f"multimode p-k V_c = {mm}")
            else:
                lines.append(f"multimode p-k: {partly if gaps else 'no flutter in the speeds searched'}")
        if "flutter.multimode_with_lateral_critical_speed_m_s" in s:
            ml = _fmt(s.get("flutter.multimode_with_lateral_critical_speed_m_s"), ".1f", " m/s")
            pct = _fmt(s.get("flutter.multimode_lateral_effect_percent"), "+.1f", " %")
            none = partly if s.get("flutter.multimode_uncovered") else "no multimode flutter in the speeds searched"
            lines.append(f"with the lateral modes: multimode p-k V_c = {ml}" + (f" ({pct})" if pct else "")
                         if ml else f"with the lateral modes: {none}")
        if "flutter.divergence_speed_m_s" in s:
            dv = _fmt(s.get("flutter.divergence_speed_m_s"), ".1f", " m/s")
            lines.append(f"static divergence at V = {dv}" if dv else "no static divergence in the speeds searched")
    elif any(k.startswith("fem.frequency_") for k in s):
        parts = [f"{k[len('fem.frequency_'):-3].replace('_', '-', 1)} {_fmt(v, '.4f', ' Hz')}"
                 for k, v in s.items() if k.startswith("fem.frequency_") and _fmt(v, ".4f")]
        lines.append("first modes: " + ", ".join(parts))
    elif "cable.horizontal_force_per_cable_N" in s:
        lines.append(f"cable horizontal force H = {_fmt(s['cable.horizontal_force_per_cable_N'], '.4g', ' N')} "
                     f"per cable, f_1 estimate (Eq 3.2) "
                     f"{_fmt(s.get('cable.first_vertical_frequency_eq_3_2_hz'), '.4f', ' Hz')}")
    return lines


def _data_range(s: Mapping[str, Any]) -> str:
    lo, hi = s.get("flutter.data_reduced_velocity_min"), s.get("flutter.data_reduced_velocity_max")
    return f" (U/(fB) {lo:.3g}-{hi:.3g})" if isinstance(lo, float) and isinstance(hi, float) else ""


# What each [flutter] aerodynamics option is, for the headline's trust line (the CFD's is its grid study).
_AERODYNAMICS_IN_WORDS = {
    "theodorsen": "Theodorsen's thin plate in potential flow, not the deck's own aerodynamics (--aerodynamics cfd "
                  "runs the deck's CFD)",
    "quasi_steady": "quasi-steady, from the static coefficients of [flutter.quasi_steady] (no unsteady "
                    "aerodynamics; --aerodynamics cfd runs the deck's CFD)",
    "table": "the tabulated frequency response functions given in [flutter] table_path",
    "derivatives": "the flutter derivatives given in [flutter] derivatives_path",
}


def _trust(s: Mapping[str, Any], vc: Any) -> str:
    """One line saying which aerodynamics gave V_c and how far to trust them: for the CFD, its preset and
    the grid error the grid study measured for it (:mod:`bridge.aero.accuracy`), or that none did."""
    option = s.get("flutter.aerodynamics_option")
    if option != "cfd":
        words = _AERODYNAMICS_IN_WORDS.get(option)
        return f"aerodynamics: {words}" if words else ""
    quality, study = s.get("aero.quality"), s.get("aero.grid_study") or "no grid study recorded"
    turbulence = "URANS with k-omega SST" if s.get("aero.turbulence") == "sst" else "laminar Navier-Stokes"
    line = f"aerodynamics: the deck's own, from forced-motion CFD ({turbulence}, preset '{quality}'); {study}"
    lo, hi = s.get("aero.vc_grid_error_low_percent"), s.get("aero.vc_grid_error_high_percent")
    if not (isinstance(vc, float) and isinstance(lo, float) and isinstance(hi, float)):
        return line
    from .aero.accuracy import STUDIED_MAIN_SPAN_M

    span = s.get("scenario.main_span_m")
    if isinstance(span, float) and abs(span - STUDIED_MAIN_SPAN_M) > 0.5:
        # the V_c error depends on where the bridge flutters, not only on the deck's grid (docs/flutter.md)
        return line + (f"; that V_c error was measured with the {STUDIED_MAIN_SPAN_M:g} m bridge's modes, not this "
                       f"{span:g} m one's (how far V_c moves with the grid depends on where a bridge flutters; "
                       "docs/flutter.md)")
    low, high = f"{vc / (1 - lo / 100):.0f}", f"{vc / (1 - hi / 100):.0f}"
    return line + f": grid-converged V_c about {low if low == high else f'{low}-{high}'} m/s"


def _written_by_us(folder: Path) -> set[str]:
    """Names of the files an earlier run wrote into ``folder``: its ``summary.json`` lists them under
    ``run.files``; for a folder from a version before that list, its three fixed files and the plots
    its ``report.md`` links to."""
    try:
        listed = json.loads((folder / "summary.json").read_text()).get("run.files")
    except (OSError, ValueError, AttributeError):
        return set()
    if isinstance(listed, list):
        return {n for n in listed if isinstance(n, str) and "/" not in n}
    try:
        summary = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError):
        return set()
    if not (isinstance(summary, dict) and "scenario.name" in summary and "stages" in summary):
        return set()   # not a summary this program wrote: nothing in the folder is ours
    try:
        report = (folder / "report.md").read_text()
    except OSError:
        report = ""
    plots = set(re.findall(r"!\[[^\]]*\]\(([^)/]+\.png)\)", report))
    return {"results.h5", "summary.json", "report.md"} | plots


def check_target(out_root: Path, name: str, overwrite: bool) -> Path:
    """The result folder ``out_root/name``; an InputError if it exists and ``overwrite`` is not set."""
    final = Path(out_root) / name
    if final.exists() and not overwrite:
        raise InputError("--out", str(final), "already holds results of an earlier run; pass --overwrite to "
                         "replace them (other files there are kept) or choose another --out")
    if final.exists() and not final.is_dir():
        raise InputError("--out", str(final), "is a file, not a result folder")
    return final


def _swap_into_place(tmp: Path, final: Path, new_files: set[str]) -> None:
    """Replace ``final`` by ``tmp``, carrying over every entry of ``final`` that no run of ours wrote.

    The earlier run's files go (this run's replace them); entries we did not write (a user's notes,
    their own plots) move into the new folder first.  A clash between such an entry and a file of this
    run is refused: a file that is not ours is never overwritten.  On any failure the earlier folder is
    put back as it was.
    """
    if not final.exists():
        os.replace(tmp, final)
        return
    ours = _written_by_us(final)
    keep = [p for p in final.iterdir() if p.name not in ours]
    clash = sorted(p.name for p in keep if p.name in new_files)
    if clash:
        raise InputError("--overwrite", str(final / clash[0]), "this file was not written by the program; "
                         "move it away first (it would be replaced)")
    moved: list[str] = []
    old: Path | None = None
    with sigint_held():   # a few renames: Ctrl-C waits for them, so no entry is left half-moved
        try:
            for p in keep:
                moved.append(p.name)   # before the move: an entry is never out of its folder unrecorded
                os.replace(p, tmp / p.name)
            old = Path(tempfile.mkdtemp(prefix=f".{final.name}.", suffix=".old", dir=final.parent))
            os.replace(final, old / "previous")
            os.replace(tmp, final)
        except BaseException:
            if old is not None and not final.exists() and (old / "previous").exists():
                os.replace(old / "previous", final)
            for n in moved:  # the user's entries back where they were
                if (tmp / n).exists():
                    os.replace(tmp / n, final / n)
            if old is not None:
                shutil.rmtree(old, ignore_errors=True)
            raise
        shutil.rmtree(old, ignore_errors=True)


def write_results(out_root: Path, scenario: Scenario, outputs: Mapping[str, StageOutput],
                  overwrite: bool = False, run_key: str | None = None) -> Path:
    """Write all stage outputs of ``scenario`` to ``out_root/<scenario.name>/`` atomically; return that folder.

    ``run_key`` (optional) is stored in ``summary.json`` as ``run.key``: the sweep uses it to tell a
    finished case of the same inputs from one run with other inputs or stages.
    """
    from .cache import store

    final = check_target(out_root, scenario.name, overwrite)
    out_root.mkdir(parents=True, exist_ok=True)
    outputs = {name: store(out) for name, out in outputs.items()}  # figures rendered: nothing left to fail
    tmp = Path(tempfile.mkdtemp(prefix=f".{scenario.name}.", suffix=".tmp", dir=out_root))
    try:
        stamp = datetime.now(UTC).isoformat(timespec="seconds")
        summary: dict[str, Any] = {"scenario.name": scenario.name, "scenario.kind": scenario.kind,
                                   "stages": list(outputs)}
        with h5py.File(tmp / "results.h5", "w") as h5:
            h5.attrs["schema_version"] = SCHEMA_VERSION
            h5.attrs["program_version"] = __version__
            h5.attrs["created_utc"] = stamp
            h5.attrs["scenario_name"] = scenario.name
            inputs = h5.create_group("scenario")
            for key, value in scenario_fields(scenario).items():  # every input, dotted keys with units
                inputs.attrs[key] = value
            for name, out in outputs.items():
                out.write_h5(h5.create_group(name))
                summary.update(out.summary)
        lines = headline(summary)
        report = [f"# {scenario.name}: results", ""]
        if lines:
            report += ["**" + lines[0][0].upper() + lines[0][1:] + ".**  "] + [ln[0].upper() + ln[1:] + ".  "
                                                                               for ln in lines[1:]] + [""]
        report += [f"{scenario.description}  ", f"Written {stamp} by bridge {__version__}; stages: "
                   f"{', '.join(outputs)}.  Details per stage follow.", ""]
        for out in outputs.values():
            report += [out.report.rstrip(), ""]
            for fname, data in out.figures.items():
                (tmp / fname).write_bytes(data)
                report += [f"![{fname}]({fname})" if fname.endswith(".png") else f"File [{fname}]({fname}).", ""]
        (tmp / "report.md").write_text("\n".join(report))
        files = sorted(p.name for p in tmp.iterdir()) + ["summary.json"]
        summary["run.files"] = files
        if run_key is not None:
            summary["run.key"] = run_key
        (tmp / "summary.json").write_text(summary_json(summary))
        for p in tmp.iterdir():
            os.chmod(p, file_mode())
        os.chmod(tmp, folder_mode())
        _swap_into_place(tmp, final, set(files))
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return final
