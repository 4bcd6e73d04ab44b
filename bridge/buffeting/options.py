"""Options of the buffeting stage: the ``[buffeting]`` table of a scenario file.

Keys (all optional; defaults and their sources: bridge.buffeting.wind, docs/buffeting.md):
    spectrum                  "kaimal" | "von_karman" (default "kaimal")
    turbulence_intensity_u    I_u = sigma_u / V, in (0, 1] (default 0.11)
    turbulence_intensity_w    I_w, in [0, 1] (default I_u / 2)
    length_scale_u_m          integral length scale of u along the wind, > 0 (default 180)
    length_scale_w_m          that of w, > 0 (default length_scale_u_m / 12)
    coherence_decay_u         Davenport's C_u, >= 0 (default 10; 0: full spanwise coherence)
    coherence_decay_w         C_w, >= 0 (default 6.5)
    admittance                "sears" | "liepmann" | "none" | "table" (default "sears"; bridge.buffeting.admittance)
    admittance_reduced_frequency, admittance_squared
                              with admittance = "table": f B / V (ascending, >= 0) and |chi|^2 (>= 0)
    self_excited              include the self-excited forces of the flutter stage's aerodynamics (default true)
    [buffeting.static_coefficients]
                              lift_coefficient, lift_slope_per_rad, drag_coefficient, moment_coefficient,
                              moment_slope_per_rad (required), drag_slope_per_rad (default 0): on B, per radian.
                              Default: the aero stage's static runs (the deck's own, with [flutter]
                              aerodynamics = "cfd"), else [flutter.quasi_steady]
    min_speed_m_s             lowest mean wind speed, > 0 (default 10)
    max_speed_m_s             highest, > min_speed_m_s (default 90 % of the lowest flutter or divergence speed
                              the flutter stage found, else its highest speed searched)
    speed_steps               speeds from min to max, an integer >= 2 (default 10)
    reference_speed_m_s       the speed of the summary's numbers, > 0 (default 40: EN 1991-1-4 with the Danish
                              basic wind speed of 24 m/s gives 36-38 m/s 70 m above open water); added to the
                              speeds when below the flutter speed
    max_frequency_hz          top of the frequency grid, > 0 (default 1.25 times the highest natural frequency)
    frequency_steps           points of the frequency grid, an integer >= 101 (default 4001)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

from bridge.buffeting.admittance import Admittance
from bridge.buffeting.wind import Turbulence
from bridge.errors import InputError, check_range, check_table
from bridge.flutter.aerodynamics import QuasiSteady

__all__ = ["BuffetingOptions", "STATIC_KEYS"]

STATIC_KEYS = ("lift_coefficient", "lift_slope_per_rad", "drag_coefficient", "moment_coefficient",
               "moment_slope_per_rad")
_STATIC_OPTIONAL = ("drag_slope_per_rad",)
_TURBULENCE = {"spectrum": "spectrum", "turbulence_intensity_u": "intensity_u",
               "turbulence_intensity_w": "intensity_w", "length_scale_u_m": "length_scale_u_m",
               "length_scale_w_m": "length_scale_w_m", "coherence_decay_u": "decay_u",
               "coherence_decay_w": "decay_w"}


_DEFAULT = Turbulence()   # the turbulence defaults live in bridge.buffeting.wind; the table's keys take them


def _integer(key: str, value: Any, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise InputError(key, value, f"an integer >= {low}")
    return value


@dataclass(frozen=True)
class BuffetingOptions:
    """Validated ``[buffeting]`` table (module docstring)."""

    spectrum: str = _DEFAULT.spectrum
    turbulence_intensity_u: float = _DEFAULT.intensity_u
    turbulence_intensity_w: float | None = _DEFAULT.intensity_w
    length_scale_u_m: float = _DEFAULT.length_scale_u_m
    length_scale_w_m: float | None = _DEFAULT.length_scale_w_m
    coherence_decay_u: float = _DEFAULT.decay_u
    coherence_decay_w: float = _DEFAULT.decay_w
    admittance: str = "sears"
    admittance_reduced_frequency: tuple[float, ...] = ()
    admittance_squared: tuple[float, ...] = ()
    self_excited: bool = True
    static_coefficients: QuasiSteady | None = None
    min_speed_m_s: float = 10.0
    max_speed_m_s: float | None = None
    speed_steps: int = 10
    reference_speed_m_s: float = 40.0
    max_frequency_hz: float | None = None
    frequency_steps: int = 4001

    def __post_init__(self) -> None:
        _ = (self.turbulence, self.admittance_model)     # each checks its own keys
        if not isinstance(self.self_excited, bool):
            raise InputError("buffeting.self_excited", self.self_excited, "true or false")
        if self.static_coefficients is not None and not isinstance(self.static_coefficients, QuasiSteady):
            raise InputError("buffeting.static_coefficients", self.static_coefficients,
                             "a table of " + ", ".join(STATIC_KEYS + _STATIC_OPTIONAL))
        lo = check_range("buffeting.min_speed_m_s", self.min_speed_m_s, low=0.0, low_open=True)
        if self.max_speed_m_s is not None:
            check_range("buffeting.max_speed_m_s", self.max_speed_m_s, low=lo, low_open=True)
        _integer("buffeting.speed_steps", self.speed_steps, 2)
        check_range("buffeting.reference_speed_m_s", self.reference_speed_m_s, low=0.0, low_open=True)
        if self.max_frequency_hz is not None:
            check_range("buffeting.max_frequency_hz", self.max_frequency_hz, low=0.0, low_open=True)
        _integer("buffeting.frequency_steps", self.frequency_steps, 101)

    @property
    def turbulence(self) -> Turbulence:
        return Turbulence(**{attr: getattr(self, key) for key, attr in _TURBULENCE.items()})

    @property
    def admittance_model(self) -> Admittance:
        return Admittance(self.admittance, tuple(self.admittance_reduced_frequency), tuple(self.admittance_squared))

    @classmethod
    def from_mapping(cls, mapping: Mapping[str, Any], where: str = "buffeting") -> BuffetingOptions:
        """Validate a ``[buffeting]`` table; unknown keys and bad values raise InputError naming ``where.key``,
        the value and what is allowed."""
        check_table(where, mapping, [f.name for f in fields(cls)])
        values = dict(mapping)
        for key in ("admittance_reduced_frequency", "admittance_squared"):
            if key in values:
                v = values[key]
                if not isinstance(v, (list, tuple)) or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                               for x in v):
                    raise InputError(f"{where}.{key}", v, "a list of numbers")
                values[key] = tuple(float(x) for x in v)
        for key in ("spectrum", "admittance"):
            if key in values and not isinstance(values[key], str):
                raise InputError(f"{where}.{key}", values[key], "must be a string")
        if "static_coefficients" in values:
            values["static_coefficients"] = _static(values["static_coefficients"], f"{where}.static_coefficients")
        try:
            return cls(**values)
        except InputError as err:   # the same key under the caller's name
            key = err.key.replace("buffeting.", f"{where}.", 1) if err.key.startswith("buffeting.") else err.key
            raise InputError(key, err.value, err.allowed) from None


def _static(table: Any, where: str) -> QuasiSteady:
    """The static coefficients of a ``[buffeting.static_coefficients]`` table."""
    if not isinstance(table, Mapping):
        raise InputError(where, table, "must be a table")
    for key in table:
        if key not in STATIC_KEYS + _STATIC_OPTIONAL:
            raise InputError(f"{where}.{key}", table[key],
                             f"unknown key; allowed: {', '.join(STATIC_KEYS + _STATIC_OPTIONAL)}")
    for key in STATIC_KEYS:
        if key not in table:
            raise InputError(f"{where}.{key}", None, "missing (required key)")
    values = {k: check_range(f"{where}.{k}", table[k], **({"low": 0.0} if k == "drag_coefficient" else {}))
              for k in table}
    return QuasiSteady(**values, name="quasi_steady ([buffeting.static_coefficients])")
