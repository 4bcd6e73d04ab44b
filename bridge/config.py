"""Scenarios: the inputs of one bridge, read from TOML and validated.

A scenario file is TOML with units in the key names (``main_span_m``, ``mass_per_length_kg_m``).
Two forms exist:

* a full bridge (``scenarios/great_belt.toml``): every input of the thesis, sections 1.4, 3.2, Table 3.1-3.4;
* an up-scaled bridge (``scenarios/model_c.toml``): ``reference = "great_belt"`` and ``main_span_m = 4000``;
  the up-scaled inputs are computed by :mod:`bridge.upscaling` (thesis 1.5), never typed in.  Any table of
  such a file changes the reference's inputs key by key before the up-scaling (``[girder] width_m = 40.0``;
  :func:`load_scenario`).

Two more kinds run the flutter stage alone: ``kind = "section"``, a 2-DOF sectional model (a
``[section]`` table, :mod:`bridge.flutter.section`), and ``kind = "modal"``, modes given directly (a
``[modal]`` table, :class:`bridge.flutter.modal.ModalModel`).

Every value is checked when read: a missing or unknown key, a wrong type or a value outside its range
raises :class:`bridge.errors.InputError` naming the dotted key, the value and the allowed range.
Derived quantities (mu and J of Eq 4.7, shear modulus, box-section properties) are computed, never
stored twice.
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

from .errors import InputError
from .inputs import (
    GRAVITY_M_S2,
    Air,
    BoxSection,
    Cable,
    DampingEntry,
    Geometry,
    Girder,
    Hanger,
    Material,
    Pylon,
    Scenario,
)
from .toml_table import Table
from .upscaling import upscale

__all__ = [
    "Material", "BoxSection", "Geometry", "Girder", "Cable", "Hanger", "Pylon", "DampingEntry", "Air",
    "Scenario", "load_scenario", "scenario_path", "check_name", "SCENARIO_DIR", "GRAVITY_M_S2", "with_aerodynamics",
    "AERODYNAMIC_CHOICES",
    "check_deck_chord", "flutter_deck_width", "CHORD_TOLERANCE",
]

SCENARIO_DIR = Path(__file__).resolve().parent.parent / "scenarios"


# ----------------------------------------------------------------------------------------- parsing
_KINDS = ("suspension_bridge", "section", "modal")


def _box(t: Table, name: str) -> BoxSection:
    s = t.table(name)
    try:
        box = BoxSection(s.number("a_m"), s.number("b_m"), s.number("t_m"))
    except InputError as err:  # re-key the message to the full dotted path
        raise InputError(s.key(err.key.split(".")[-1]), err.value, err.allowed) from None
    s.done()
    return box


def _air(t: Table) -> Air:
    """The optional [air] table (thesis 5.2.4 values as defaults)."""
    a = t.table("air", default={})
    air = Air(a.number("density_kg_m3", default=Air.density_kg_m3),
              a.number("kinematic_viscosity_m2_s", default=Air.kinematic_viscosity_m2_s))
    a.done()
    return air


def _materials(t: Table) -> dict[str, Material]:
    out = {}
    for name in t.data:
        m = t.table(name)
        out[name] = Material(name, m.number("youngs_modulus_Pa"), m.number("poisson_ratio", 0.0, 0.5,
                             low_open=False, high_open=True), m.number("density_kg_m3"))
        m.done()
    if not out:
        raise InputError("materials", {}, "needs at least one material table")
    return out


def _material_name(t: Table, materials: Mapping[str, Material]) -> str:
    name = t.string("material")
    if name not in materials:
        raise InputError(t.key("material"), name, f"must be one of the [materials] tables: {', '.join(materials)}")
    return name


def _parse_bridge(t: Table, name: str, description: str, source: str | None) -> Scenario:
    materials = _materials(t.table("materials"))

    g = t.table("geometry")
    geometry = Geometry(
        main_span_m=g.number("main_span_m"), side_span_m=g.number("side_span_m"), sag_m=g.number("sag_m"),
        hanger_spacing_target_m=g.number("hanger_spacing_target_m"),
        cable_plane_spacing_m=g.number("cable_plane_spacing_m"),
        girder_elevation_m=g.number("girder_elevation_m"), pylon_height_m=g.number("pylon_height_m"))
    g.done()

    b = t.table("girder")
    girder = Girder(
        area_m2=b.number("area_m2"), i_vertical_m4=b.number("i_vertical_m4"),
        i_lateral_m4=b.number("i_lateral_m4"), torsion_constant_m4=b.number("torsion_constant_m4"),
        mass_per_length_kg_m=b.number("mass_per_length_kg_m"),
        mass_moment_of_inertia_kg_m2_m=b.number("mass_moment_of_inertia_kg_m2_m"),
        width_m=b.number("width_m"), material=_material_name(b, materials))
    b.done()

    c = t.table("cable")
    cable = Cable(
        area_m2=c.number("area_m2"), mass_per_length_main_kg_m=c.number("mass_per_length_main_kg_m"),
        mass_per_length_side_kg_m=c.number("mass_per_length_side_kg_m"),
        allowable_stress_Pa=c.number("allowable_stress_Pa"), material=_material_name(c, materials))
    c.done()

    h = t.table("hanger")
    hanger = Hanger(area_m2=h.number("area_m2"), density_kg_m3=h.number("density_kg_m3"),
                    material=_material_name(h, materials))
    h.done()

    p = t.table("pylon")
    pylon = Pylon(
        lower_leg=_box(p, "lower_leg"), upper_leg=_box(p, "upper_leg"),
        lower_cross_beam=_box(p, "lower_cross_beam"), upper_cross_beam=_box(p, "upper_cross_beam"),
        lower_cross_beam_elevation_m=p.number("lower_cross_beam_elevation_m"),
        upper_cross_beam_elevation_m=p.number("upper_cross_beam_elevation_m"),
        extra_cross_beams=p.integer("extra_cross_beams", 0, 10, default=0),
        material=_material_name(p, materials))
    p.done()
    if not pylon.lower_cross_beam_elevation_m < pylon.upper_cross_beam_elevation_m <= geometry.pylon_height_m:
        raise InputError("pylon.upper_cross_beam_elevation_m", pylon.upper_cross_beam_elevation_m,
                         f"must lie above lower_cross_beam_elevation_m ({pylon.lower_cross_beam_elevation_m:g}) "
                         f"and not above geometry.pylon_height_m ({geometry.pylon_height_m:g})")

    d = t.table("damping")
    rows = d.raw("modes")
    if not isinstance(rows, list) or not rows:
        raise InputError(d.key("modes"), rows, "must be a non-empty list of {symmetry, frequency_hz, ratio}")
    damping = []
    for i, row in enumerate(rows):
        r = Table(row, f"damping.modes[{i}]")
        damping.append(DampingEntry(r.string("symmetry", ("S", "SS")), r.number("frequency_hz"),
                                    r.number("ratio", 0.0, 0.2, low_open=False)))
        r.done()
    d.done()

    air = _air(t)

    return Scenario(name=name, kind="suspension_bridge", description=description, geometry=geometry,
                    girder=girder, cable=cable, hanger=hanger, pylon=pylon, materials=materials,
                    damping=tuple(damping), air=air, source_path=source)


def _parse_optional_tables(t: Table, scenario: Scenario) -> Scenario:
    """[flutter], [section] and [modal] tables belong to the flutter package, [deck_section] to
    bridge.cfd.sections, [aero] to bridge.aero and [buffeting] to bridge.buffeting; each validates its own."""
    updates: dict[str, Any] = {}
    if "flutter" in t.data:
        from .flutter.options import FlutterOptions

        updates["flutter"] = FlutterOptions.from_mapping(t.raw("flutter"), "flutter")
    if "section" in t.data:
        from .flutter.section import SectionModel

        updates["section"] = SectionModel.from_mapping(t.raw("section"), "section")
    if "modal" in t.data:
        from .flutter.modal import ModalModel

        updates["modal"] = ModalModel.from_mapping(t.raw("modal"), "modal")
    if "deck_section" in t.data:
        from .cfd.sections import section_from_mapping

        folder = Path(scenario.source_path).parent if scenario.source_path else None  # of a relative outline_path
        updates["deck_section"] = section_from_mapping(t.raw("deck_section"), "deck_section", base_dir=folder)
    if "aero" in t.data:
        from .aero.options import AeroOptions

        updates["aero"] = AeroOptions.from_mapping(t.raw("aero"), "aero")
    if "buffeting" in t.data:
        from .buffeting.options import BuffetingOptions

        updates["buffeting"] = BuffetingOptions.from_mapping(t.raw("buffeting"), "buffeting")
    return replace(scenario, **updates) if updates else scenario


_NAME = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9._-]*")


def check_name(name: Any, where: str = "name") -> str:
    """A scenario name is the name of its result folder: a plain file name of letters, digits, ``-``,
    ``_`` and ``.``, not starting with ``.`` (so never ``..``, a path or a hidden folder)."""
    if not isinstance(name, str) or not _NAME.fullmatch(name) or len(name) > 200:
        raise InputError(where, name, "must be a plain file name: letters, digits, '-', '_' and '.', "
                         "not starting with '.' (at most 200 characters)")
    return name


def scenario_path(name_or_path: str | Path) -> Path:
    """``great_belt`` -> ``scenarios/great_belt.toml``; an existing path is used as given."""
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists():
        if not p.is_file():
            raise InputError("scenario", str(name_or_path), "file not found")
        return p
    candidate = SCENARIO_DIR / f"{name_or_path}.toml"
    if not candidate.is_file():
        known = sorted(q.stem for q in SCENARIO_DIR.glob("*.toml"))
        raise InputError("scenario", str(name_or_path), f"not a file and not one of: {', '.join(known)}")
    return candidate


def apply_overrides(data: dict, overrides: Mapping[str, Any]) -> dict:
    """Set dotted keys (``"girder.mass_per_length_kg_m"``) in raw TOML data; the key must already exist
    (a sweep cannot invent inputs), except inside tables the file leaves to defaults."""
    import copy

    data = copy.deepcopy(data)
    for dotted, value in overrides.items():
        parts = dotted.split(".")
        node = data
        for part in parts[:-1]:
            if not isinstance(node, dict) or part not in node:
                raise InputError(dotted, value, "no such scenario key to override")
            node = node[part]
        if not isinstance(node, dict) or parts[-1] not in node:
            raise InputError(dotted, value, "no such scenario key to override")
        node[parts[-1]] = value
    return data


# How far the CFD section's chord may differ from the structure's deck width B: the aero stage's derivatives are
# per the chord and the flutter stage uses them per B, so the two must be one length (a drawing's rounding).
CHORD_TOLERANCE = 0.01


def flutter_deck_width(scenario: Scenario) -> tuple[float | None, str]:
    """The deck width B the flutter stage normalises the aerodynamics with, and the key that gives it
    (None for a scenario that has none)."""
    if scenario.kind == "section" and scenario.section is not None:
        return float(scenario.section.deck_width_m), "section.deck_width_m"
    if scenario.kind == "modal" and scenario.modal is not None:
        return float(scenario.modal.deck_width_m), "modal.deck_width_m"
    if scenario.girder is not None:
        return float(scenario.girder.width_m), "girder.width_m"
    return None, ""


def check_deck_chord(scenario: Scenario, section: Any = None) -> None:
    """InputError unless the CFD's deck section (``section``, default the scenario's ``[deck_section]``) has
    the chord of the structure's deck width, within :data:`CHORD_TOLERANCE`."""
    section = section if section is not None else scenario.deck_section
    width, key = flutter_deck_width(scenario)
    if section is None or width is None:
        return
    chord = float(section.chord_m)
    if abs(chord - width) > CHORD_TOLERANCE * width:
        given = "deck_section.chord_m" if scenario.deck_section is not None else "deck_section"
        what = chord if scenario.deck_section is not None else f"not given: the Great Belt box, B = {chord:g} m"
        raise InputError(given, what, f"the CFD section's chord must equal {key} = {width:g} m (within "
                         f"{100 * CHORD_TOLERANCE:g} %): the derivatives the CFD gives are per its chord, and the "
                         "flutter stage applies them per the deck width")


def _checked(scenario: Scenario) -> Scenario:
    """Checks across tables, once every table is read: the CFD section's chord against the deck width."""
    check_deck_chord(scenario)
    return scenario


# The keys of a file that names a reference bridge which are its own, not tables of the reference.
_REFERENCE_KEYS = ("name", "description", "reference", "main_span_m")


def _read_toml(path: Path) -> dict:
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as err:
        raise InputError("scenario", str(path), f"is not valid TOML ({err})") from None


def _reference_path(ref: Any, where: Path) -> Path:
    """The file a ``reference = "..."`` names: a file of that name beside the referring one, else a
    shipped scenario."""
    if not isinstance(ref, str):
        raise InputError("reference", ref, "must be the name of a scenario (a string)")
    beside = where.parent / f"{ref}.toml"
    return beside if beside.is_file() else scenario_path(ref)


def _rebase_paths(table: Any, source: Path, target: Path) -> Any:
    """A table read from ``source`` for a scenario whose file is ``target``: its relative ``*_path`` values
    re-written so that they still name the same files from ``target``'s folder."""
    if not isinstance(table, dict) or source.parent.resolve() == target.parent.resolve():
        return table
    out = {}
    for k, v in table.items():
        if isinstance(v, dict):
            v = _rebase_paths(v, source, target)
        elif k.endswith("_path") and isinstance(v, str) and not Path(v).is_absolute():
            v = os.path.relpath(source.parent.resolve() / v, target.parent.resolve())
        out[k] = v
    return out


def _merge_tables(base: dict, own: Mapping[str, Any]) -> dict:
    """``own``'s tables laid over ``base``'s, key by key (a value that is a table merges into the table of the
    same name; any other value replaces).  A ``[deck_section]`` that names its ``shape`` is a section of its
    own and replaces the reference's whole (one without ``shape`` changes the reference's keys)."""
    out = dict(base)
    for k, v in own.items():
        b = out.get(k)
        whole = k == "deck_section" and isinstance(v, dict) and "shape" in v
        out[k] = _merge_tables(b, v) if isinstance(v, dict) and isinstance(b, dict) and not whole else v
    return out


def _resolved_reference(path: Path, seen: tuple[str, ...]) -> tuple[dict, str]:
    """The raw tables of the full bridge a file describes - its own, or those of its reference (and of the
    reference's reference...) with the file's tables laid over them - and the bridge's name."""
    data = _read_toml(path)
    if "reference" not in data:
        kind = data.get("kind", "suspension_bridge")
        if kind != "suspension_bridge":
            raise InputError("reference", path.stem, f"names a scenario of kind {kind!r}; only a suspension "
                             "bridge can be a reference")
        return data, data.get("name", path.stem)
    ref = data["reference"]
    if ref in seen:
        raise InputError("reference", ref, "circular reference between scenario files")
    ref_path = _reference_path(ref, path)
    base, _ = _resolved_reference(ref_path, seen + (ref,))
    base = {k: _rebase_paths(v, ref_path, path) for k, v in base.items()}
    own = {k: v for k, v in data.items() if k not in _REFERENCE_KEYS}
    if "kind" in own:
        raise InputError("kind", own["kind"], "not allowed beside reference = ...: a file that names a reference "
                         "bridge is a suspension bridge")
    merged = _merge_tables(base, own)
    for k in ("name", "description"):
        merged.pop(k, None)
    return merged, data.get("name", path.stem)


def load_scenario(name_or_path: str | Path, main_span_m: float | None = None,
                  overrides: Mapping[str, Any] | None = None) -> Scenario:
    """Read, validate and (if the file names a reference) up-scale a scenario.

    A file with ``reference = "<scenario>"`` is that bridge with the file's own tables laid over the
    reference's, key by key (``[girder] width_m = 40.0`` changes the girder's width and nothing else;
    ``[aero]`` and ``[flutter]`` likewise; a ``[deck_section]`` with a ``shape`` is a section of its own), then
    up-scaled to the file's ``main_span_m`` by the rules of thesis 1.5 (:mod:`bridge.upscaling`), applied
    once, from the full bridge at the end of a chain of references.  ``main_span_m`` overrides the file's
    main span (command line ``--main-span``).  ``overrides`` sets dotted input keys before validation (for
    sweeps); the key must exist in the file or, for an up-scaled bridge, in the tables it has with its
    reference.
    """
    path = scenario_path(name_or_path)
    data = _read_toml(path)
    if "reference" not in data:
        data = apply_overrides(data, overrides or {})
    t = Table(data, "")
    if "name" in data:
        name = check_name(t.string("name"))
    else:  # the file's own name: a copy saved under another name writes to its own folder
        name = check_name(path.stem, f"name (from the file name {path.name}; rename the file or set name = ...)")
    description = t.string("description", default="")

    if "reference" in data:  # a bridge up-scaled from a reference (or the reference with some inputs changed)
        t.string("reference")
        span = t.number("main_span_m")
        tables, ref_name = _resolved_reference(path, (name,))
        merged = Table(apply_overrides(tables, overrides or {}), "")
        merged.used.add("kind")   # checked by _resolved_reference: a suspension bridge
        reference = _parse_bridge(merged, ref_name, description, str(path))
        reference = _parse_optional_tables(merged, reference)
        merged.done()             # a table name that no parser knows (a typo such as [girdr])
        t.used.update(data)       # the file's own tables were read through ``merged``
        t.done()
        target = main_span_m if main_span_m is not None else span
        if main_span_m is not None and not math.isclose(main_span_m, span):
            name = f"{name}_L{main_span_m:g}"
        scenario = upscale(reference, target)
        scenario = replace(scenario, name=name, description=description or scenario.description,
                           source_path=str(path))
        return _checked(scenario)

    kind = t.string("kind", _KINDS, default="suspension_bridge")
    if kind in ("section", "modal"):
        scenario = Scenario(name=name, kind=kind, description=description, source_path=str(path))
        scenario = replace(scenario, air=_air(t))
        scenario = _parse_optional_tables(t, scenario)
        table = "section" if kind == "section" else "modal"
        if getattr(scenario, table) is None:
            raise InputError(table, None, f"missing: a scenario of kind {kind!r} needs a [{table}] table")
        if main_span_m is not None:
            raise InputError("--main-span", main_span_m, f"only applies to bridge scenarios, not to kind {kind!r}")
        t.done()
        return _checked(scenario)

    scenario = _parse_bridge(t, name, description, str(path))
    scenario = _parse_optional_tables(t, scenario)
    t.done()
    if main_span_m is not None and not math.isclose(main_span_m, scenario.geometry.main_span_m):
        scenario = replace(upscale(scenario, main_span_m), name=f"{name}_L{main_span_m:g}")
    return _checked(scenario)


# What --aerodynamics may choose on the command line: the deck's CFD, or a closed form for a quick answer (the
# table and derivative models need their files, named in the scenario).
AERODYNAMIC_CHOICES = ("cfd", "theodorsen", "quasi_steady")


def with_aerodynamics(scenario: Scenario, aerodynamics: str | None) -> Scenario:
    """The scenario with the flutter stage's aerodynamics set to ``aerodynamics`` (command line
    ``--aerodynamics``; None: unchanged), in ``[flutter]`` and, for a sectional model, in ``[section]``."""
    if aerodynamics is None:
        return scenario
    from .flutter.options import FlutterOptions

    try:
        flutter = replace(scenario.flutter or FlutterOptions(), aerodynamics=aerodynamics)
        section = scenario.section
        if scenario.kind == "section" and section is not None and section.aerodynamics is not None:
            section = replace(section, aerodynamics=aerodynamics)
    except InputError as err:   # e.g. quasi_steady without [flutter.quasi_steady]
        raise InputError("--aerodynamics", aerodynamics, f"{err.key} {err.allowed}") from None
    return replace(scenario, flutter=flutter, section=section)


def scenario_fields(obj: Any, include_none: bool = False) -> dict[str, Any]:
    """Flatten a dataclass tree into ``{"geometry.main_span_m": 1624.0, ...}`` (for reports, HDF5 attrs
    and the stage cache's keys): numbers, strings and flags, sequences of them (as lists) and arrays
    (as NumPy arrays); with ``include_none`` also the fields left unset (None), which the cache key
    needs to tell "not given" from a value."""
    import numpy as np

    out: dict[str, Any] = {}

    def walk(prefix: str, value: Any) -> None:
        if hasattr(value, "__dataclass_fields__"):
            for f in fields(value):
                walk(f"{prefix}.{f.name}" if prefix else f.name, getattr(value, f.name))
        elif isinstance(value, Mapping):
            for k, v in value.items():
                walk(f"{prefix}.{k}", v)
        elif isinstance(value, (tuple, list)) and value and hasattr(value[0], "__dataclass_fields__"):
            for i, v in enumerate(value):
                walk(f"{prefix}[{i}]", v)
        elif isinstance(value, np.ndarray):
            out[prefix] = value
        elif isinstance(value, (tuple, list)) and all(isinstance(v, (bool, int, float, str)) for v in value):
            if value:
                out[prefix] = list(value)
        elif isinstance(value, (bool, int, float, str, np.bool_)):
            out[prefix] = value
        elif value is None and include_none:
            out[prefix] = None

    walk("", obj)
    return out
