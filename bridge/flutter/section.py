"""2-DOF sectional model (heave and pitch of a rigid deck section on springs, axis at mid-chord): the
``[section]`` table of a scenario of ``kind = "section"``.

Keys (units in the names):
    mass_per_length_kg_m, inertia_per_length_kg_m2_m (about mid-chord), heave_frequency_hz,
    pitch_frequency_hz, deck_width_m (B, the chord)                                  - required
    heave_damping_ratio, pitch_damping_ratio (default 0), air_density_kg_m3 and aerodynamics
    (optional overrides of the [air] density and of [flutter].aerodynamics)
    lateral_frequency_hz, lateral_damping_ratio (optional): a third DOF, sway (lateral translation
    downwind), with the same mass per length as heave
The flutter solvers see it as :meth:`ModalModel.section`: uu = diag(1, 0), tt = diag(0, 1),
ut[heave, pitch] = 1, L = 1 m; with sway also rr = 1 on the sway mode, ur[heave, sway] = 1 and
rt[sway, pitch] = 1 (each DOF is a mode of unit amplitude along the unit length).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

from bridge.errors import InputError, check_range, check_table
from bridge.flutter.modal import ModalModel
from bridge.flutter.options import AERODYNAMIC_MODELS

__all__ = ["SectionModel"]

_POSITIVE = ("mass_per_length_kg_m", "inertia_per_length_kg_m2_m", "heave_frequency_hz", "pitch_frequency_hz",
             "deck_width_m")
_RATIOS = ("heave_damping_ratio", "pitch_damping_ratio")


@dataclass(frozen=True)
class SectionModel:
    """A validated 2-DOF sectional model (see the module docstring)."""

    mass_per_length_kg_m: float
    inertia_per_length_kg_m2_m: float
    heave_frequency_hz: float
    pitch_frequency_hz: float
    deck_width_m: float
    heave_damping_ratio: float = 0.0
    pitch_damping_ratio: float = 0.0
    air_density_kg_m3: float | None = None
    aerodynamics: str | None = None
    lateral_frequency_hz: float | None = None
    lateral_damping_ratio: float = 0.0

    def __post_init__(self) -> None:
        self._validate("section")

    def _validate(self, where: str) -> None:
        for key in _POSITIVE:
            object.__setattr__(self, key, check_range(f"{where}.{key}", getattr(self, key), low=0.0, low_open=True))
        for key in _RATIOS:
            object.__setattr__(self, key, check_range(f"{where}.{key}", getattr(self, key), low=0.0, high=1.0,
                                                      high_open=True))
        if self.lateral_frequency_hz is not None:
            object.__setattr__(self, "lateral_frequency_hz", check_range(
                f"{where}.lateral_frequency_hz", self.lateral_frequency_hz, low=0.0, low_open=True))
        object.__setattr__(self, "lateral_damping_ratio", check_range(
            f"{where}.lateral_damping_ratio", self.lateral_damping_ratio, low=0.0, high=1.0, high_open=True))
        if self.air_density_kg_m3 is not None:
            object.__setattr__(self, "air_density_kg_m3", check_range(
                f"{where}.air_density_kg_m3", self.air_density_kg_m3, low=0.0, low_open=True, high=10.0))
        if self.aerodynamics is not None and self.aerodynamics not in AERODYNAMIC_MODELS:
            raise InputError(f"{where}.aerodynamics", self.aerodynamics, f"one of {', '.join(AERODYNAMIC_MODELS)}")

    @classmethod
    def from_mapping(cls, mapping: Mapping[str, Any], where: str = "section") -> SectionModel:
        """Validate a ``[section]`` table; unknown/missing keys and bad values raise InputError naming
        ``where.key``, the value and the allowed range."""
        check_table(where, mapping, [f.name for f in fields(cls)])
        for key in _POSITIVE:
            if key not in mapping:
                raise InputError(f"{where}.{key}", None, "missing (required key)")
        obj = cls.__new__(cls)
        for f in fields(cls):
            object.__setattr__(obj, f.name, mapping.get(f.name, f.default))
        obj._validate(where)
        return obj

    def modal_model(self) -> ModalModel:
        return ModalModel.section(mass_per_length_kg_m=self.mass_per_length_kg_m,
                                  inertia_per_length_kg_m2_m=self.inertia_per_length_kg_m2_m,
                                  heave_frequency_hz=self.heave_frequency_hz,
                                  pitch_frequency_hz=self.pitch_frequency_hz, deck_width_m=self.deck_width_m,
                                  heave_damping_ratio=self.heave_damping_ratio,
                                  pitch_damping_ratio=self.pitch_damping_ratio,
                                  lateral_frequency_hz=self.lateral_frequency_hz,
                                  lateral_damping_ratio=self.lateral_damping_ratio)
