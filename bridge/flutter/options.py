"""Options of the flutter stage: the ``[flutter]`` table of a scenario file.

Keys (all optional; defaults give a Theodorsen thin-plate analysis up to 150 m/s):
    aerodynamics      "theodorsen" | "quasi_steady" | "table" | "derivatives" | "cfd"   (default "theodorsen";
                      "cfd": the deck's own, from the aero stage, bridge.aero.stage)
    table_path        HDF5 file of h_xy(Omega, V) (aerodynamics = "table"); relative paths are taken
                      from the scenario file's folder.  Schema: docs/results.md "Aerodynamic table (input)"
    table_group       group inside it (default "/")
    derivatives_path  CSV of flutter derivatives H1*-H6*, A1*-A6*, P1*-P6* (aerodynamics = "derivatives"),
                      in the convention it states (bridge.flutter.tables.DerivativeTable)
    [flutter.derivatives_convention]  vertical, lift, lateral, drag, pitch, moment, reference_length: the
                      table's convention (bridge.flutter.conventions); merged with the CSV's
                      ``# convention:`` line, a key stated differently by the two is an error
    missing_derivatives  "error" | "zero": a derivative column the table lacks (H1-H4, A1-A4, or the partner
                      of a lateral one it has) is an error, or zero (default "error")
    [flutter.quasi_steady]  lift_coefficient, lift_slope_per_rad, drag_coefficient, moment_coefficient,
                      moment_slope_per_rad (all required), drag_slope_per_rad (default 0): static
                      coefficients on the reference length B, slopes per radian.  With aerodynamics =
                      "quasi_steady" they are the whole model; with any other model they supply the
                      lateral terms (drag, sway) that model lacks (bridge.flutter.aerodynamics.WithLateral):
                      with "cfd" only when the aero stage held the deck still at no angle (its own static
                      coefficients are the deck's)
    air_density_kg_m3 overrides the scenario's [air] density (default: [air], else 1.225)
    max_speed_m_s     highest mean wind speed searched (default 150)
    min_speed_m_s     lowest speed searched (default 1 % of max_speed_m_s, or the table's lowest V)
    speed_steps       points of the V scan (default 120; >= 10)
    pairs             "thesis" (S-V1..3 with S-T1) | "all" (also SS-V1..3 with SS-T1)   (default "all")
    multimode         run the p-k multimode sweep as well (default true)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from bridge.errors import InputError, check_range, check_table
from bridge.flutter.aerodynamics import (
    AerodynamicModel,
    DerivativeTable,
    FRFTable,
    QuasiSteady,
    Theodorsen,
    WithLateral,
)
from bridge.flutter.conventions import Convention
from bridge.flutter.tables import MISSING_DERIVATIVES

__all__ = ["FlutterOptions", "AERODYNAMIC_MODELS"]

AERODYNAMIC_MODELS = ("theodorsen", "quasi_steady", "table", "derivatives", "cfd")
PAIRS = ("thesis", "all")
_QS_KEYS = ("lift_coefficient", "lift_slope_per_rad", "drag_coefficient", "moment_coefficient",
            "moment_slope_per_rad")
_QS_OPTIONAL = ("drag_slope_per_rad",)


def _number(where: str, key: str, value: Any, **bounds) -> float:
    return check_range(f"{where}.{key}", value, **bounds)


def _string(where: str, key: str, value: Any, allowed: tuple[str, ...] | None = None) -> str:
    if not isinstance(value, str):
        raise InputError(f"{where}.{key}", value, "must be a string")
    if allowed is not None and value not in allowed:
        raise InputError(f"{where}.{key}", value, f"one of {', '.join(allowed)}")
    return value


@dataclass(frozen=True)
class FlutterOptions:
    """Validated ``[flutter]`` table (see the module docstring for the keys)."""

    aerodynamics: str = "theodorsen"
    table_path: str | None = None
    table_group: str = "/"
    derivatives_path: str | None = None
    derivatives_convention: Convention | None = None
    missing_derivatives: str = "error"
    quasi_steady: QuasiSteady | None = None
    air_density_kg_m3: float | None = None
    max_speed_m_s: float = 150.0
    min_speed_m_s: float | None = None
    speed_steps: int = 120
    pairs: str = "all"
    multimode: bool = True

    def __post_init__(self) -> None:
        self._validate("flutter")

    def _validate(self, where: str) -> None:
        _string(where, "aerodynamics", self.aerodynamics, AERODYNAMIC_MODELS)
        _string(where, "pairs", self.pairs, PAIRS)
        _string(where, "table_group", self.table_group)
        _string(where, "missing_derivatives", self.missing_derivatives, MISSING_DERIVATIVES)
        if self.derivatives_convention is not None and not isinstance(self.derivatives_convention, Convention):
            raise InputError(f"{where}.derivatives_convention", self.derivatives_convention,
                             "a table of vertical, lift, lateral, drag, pitch, moment, reference_length")
        _number(where, "max_speed_m_s", self.max_speed_m_s, low=0.0, low_open=True)
        if self.min_speed_m_s is not None:
            _number(where, "min_speed_m_s", self.min_speed_m_s, low=0.0, low_open=True,
                    high=float(self.max_speed_m_s), high_open=True)
        if self.air_density_kg_m3 is not None:
            _number(where, "air_density_kg_m3", self.air_density_kg_m3, low=0.0, low_open=True, high=10.0)
        if isinstance(self.speed_steps, bool) or not isinstance(self.speed_steps, int) or self.speed_steps < 10:
            raise InputError(f"{where}.speed_steps", self.speed_steps, "an integer >= 10")
        if not isinstance(self.multimode, bool):
            raise InputError(f"{where}.multimode", self.multimode, "true or false")
        needs = {"table": "table_path", "derivatives": "derivatives_path", "quasi_steady": "quasi_steady"}
        if self.aerodynamics in needs and getattr(self, needs[self.aerodynamics]) is None:
            raise InputError(f"{where}.{needs[self.aerodynamics]}", None,
                             f"required when aerodynamics = {self.aerodynamics!r}")
        for key in ("table_path", "derivatives_path"):
            if getattr(self, key) is not None:
                _string(where, key, getattr(self, key))

    @classmethod
    def from_mapping(cls, mapping: Mapping[str, Any], where: str = "flutter") -> FlutterOptions:
        """Validate a ``[flutter]`` table; unknown keys and bad values raise InputError naming ``where.key``."""
        check_table(where, mapping, [f.name for f in fields(cls)])
        values = dict(mapping)
        if "derivatives_convention" in values:
            values["derivatives_convention"] = Convention.from_mapping(values["derivatives_convention"],
                                                                       f"{where}.derivatives_convention")
        if "quasi_steady" in values:
            qs = values["quasi_steady"]
            if not isinstance(qs, Mapping):
                raise InputError(f"{where}.quasi_steady", qs, "must be a table")
            for key in qs:
                if key not in _QS_KEYS + _QS_OPTIONAL:
                    raise InputError(f"{where}.quasi_steady.{key}", qs[key],
                                     f"unknown key; allowed: {', '.join(_QS_KEYS + _QS_OPTIONAL)}")
            missing = [k for k in _QS_KEYS if k not in qs]
            if missing:
                raise InputError(f"{where}.quasi_steady.{missing[0]}", None, "missing (required key)")
            given = [k for k in _QS_KEYS + _QS_OPTIONAL if k in qs]
            for key in given:
                _number(f"{where}.quasi_steady", key, qs[key], **({"low": 0.0} if key == "drag_coefficient" else {}))
            values["quasi_steady"] = QuasiSteady(**{k: float(qs[k]) for k in given})
        for key in ("max_speed_m_s", "min_speed_m_s", "air_density_kg_m3"):
            if key in values:
                values[key] = _number(where, key, values[key])
        obj = cls.__new__(cls)
        for f in fields(cls):
            object.__setattr__(obj, f.name, values.get(f.name, f.default))
        obj._validate(where)
        return obj

    def aerodynamic_model(self, base_dir: str | Path | None = None, cfd: AerodynamicModel | None = None
                          ) -> AerodynamicModel:
        """Build (and for tables, read) the aerodynamic model; relative paths are taken from ``base_dir``;
        ``cfd`` is the aero stage's model (``aerodynamics = "cfd"``)."""
        def resolve(p: str) -> Path:
            q = Path(p)
            return q if q.is_absolute() or base_dir is None else Path(base_dir) / q

        if self.aerodynamics == "quasi_steady":
            return self.quasi_steady
        if self.aerodynamics == "theodorsen":
            base = Theodorsen()
        elif self.aerodynamics == "table":
            base = FRFTable.from_hdf5(resolve(self.table_path), self.table_group)
        elif self.aerodynamics == "cfd":
            if cfd is None:
                raise InputError("flutter.aerodynamics", "cfd", "needs the aero stage's result (run it: it is "
                                 "planned automatically with the flutter stage)")
            # the aero stage completes its table with the lateral terms of its static runs: the deck's own, which
            # [flutter.quasi_steady] (static coefficients for models without them) does not replace; without
            # static runs ([aero] static_angles_deg = []) the scenario's coefficients complete it (below)
            if isinstance(cfd, WithLateral):
                return cfd
            base = cfd
        elif self.aerodynamics == "derivatives":
            base = DerivativeTable.from_csv(resolve(self.derivatives_path), convention=self.derivatives_convention,
                                            missing=self.missing_derivatives)
        else:
            raise InputError("flutter.aerodynamics", self.aerodynamics, f"one of {', '.join(AERODYNAMIC_MODELS)}")
        return base if self.quasi_steady is None else WithLateral(base, self.quasi_steady)
