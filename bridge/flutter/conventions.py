"""Sign and normalisation conventions of flutter-derivative tables, and their conversion to the internal
h_xy of :mod:`bridge.flutter.derivatives`.

Published tables of flutter derivatives differ in which way heave, lift, sway, drag, pitch and moment are
positive, in the reference length (the deck width B, or the half chord b = B/2) and in the argument
(K = B w/U, k = b w/U, U/(fB), U/(wB)).  A number copied from one convention into another changes V_c, so
a table states its convention (:class:`Convention`) and is converted here; nothing is assumed.

Derivation (one rule for every derivative and every convention, no table typed per convention)
------------------------------------------------------------------------------------------------
A table in convention c writes each load F in {lift, drag, moment} per unit length as

    F_c = (1/2) rho U^2 B l^{n_F} sum_x [kappa X_d l^{d_x} xdot_c / U + kappa^2 X_s l^{d_x - 1} x_c]

over the three motions x in {vertical h, lateral p, pitch alpha}, with
    l          the reference length: B, or b = B/2;
    kappa      = l w / U, the reduced frequency on that length;
    n_F        0 for a force (lift, drag), 1 for the moment;
    d_x        0 for a translation (h, p), 1 for the rotation alpha;
    X_d, X_s   the derivative of the velocity and of the displacement (:data:`TERMS`):
               lift  H1 hdot, H4 h;  H2 alphadot, H3 alpha;  H5 pdot, H6 p
               drag  P5 hdot, P6 h;  P2 alphadot, P3 alpha;  P1 pdot, P4 p
               moment A1 hdot, A4 h;  A2 alphadot, A3 alpha;  A5 pdot, A6 p.
For l = B this is Simiu and Scanlan's form (1996, sec. 12.3; the IABSE form), the one of
:mod:`bridge.flutter.derivatives`; for l = b the prefactors (1/2) rho U^2 B = (1/2) rho U^2 (2b) and
(1/2) rho U^2 B b = (1/2) rho U^2 (2 b^2) with k = b w/U, hdot/U, b alphadot/U, h/b are Scanlan and
Tomko's (1971) (their lateral terms did not exist; they follow the same rule here).
Harmonic motion xdot = i w x gives kappa l^{d_x} xdot/U = i kappa^2 l^{d_x - 1} x, so the term is
    (1/2) rho U^2 B l^{n_F + d_x - 1} kappa^2 (X_s + i X_d) x_c.
The internal loads are F = (1/2) rho U^2 B^{n_F + d_x} h_Fx x (p, q, m per unit length; u up, r
downwind, theta nose-up).  With x_c = s_x x and F = s_F F_c, where s = +1 if the table's positive
direction is the internal one and -1 if not, and kappa = (l/B) K:

    h_Fx = s_F s_x (l/B)^{n_F + d_x + 1} K^2 (X_s + i X_d)          (:meth:`Convention.factor`)

so the factor of a derivative is a sign from each of its load and its motion times a power of l/B:
with l = b, 1/2 for a force from a translation (H1, H4, H5, H6, P1, P4, P5, P6), 1/4 for a force from
pitch or a moment from a translation (H2, H3, P2, P3, A1, A4, A5, A6), 1/8 for the moment from pitch
(A2, A3).  Converting a table from convention a to b: X_b = (factor_a / factor_b) X_a, exact in floating
point (signs and powers of 2).  For the Scanlan form (h, L down; p, D downwind; nose-up; l = B) the
rule gives back the table of :mod:`bridge.flutter.derivatives` (tested).

The argument column is converted to K = B w/U: ``K`` as it is, ``k`` = b w/U (K = 2k),
``reduced_velocity`` = U/(fB) (K = 2 pi / U_r), ``reduced_velocity_omega`` = U/(wB) (K = 1/U_r).

Stating a convention: the CSV's comment line(s)
    # convention: vertical=down lift=down lateral=downwind drag=downwind pitch=nose_up reference_length=B
and/or a ``[flutter.derivatives_convention]`` scenario table with the same keys (:meth:`Convention.parse`,
:meth:`Convention.from_mapping`).  ``moment`` is positive in the sense of ``pitch`` unless stated;
``lateral`` and ``drag`` are needed only by a table with lateral columns (H5, H6, A5, A6, P1-P6).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, fields

import numpy as np

from bridge.errors import InputError
from bridge.flutter.derivatives import DERIVATIVE_NAMES, FRF, FRF_NAMES

__all__ = ["Convention", "TERMS", "FRF_OF", "ARGUMENTS", "DIRECTIONS", "REFERENCE_LENGTHS", "SCANLAN",
           "SCANLAN_TOMKO", "to_reduced_frequency", "from_reduced_frequency", "EXAMPLE_LINE"]

# axis -> (internal direction, the other one)
DIRECTIONS: dict[str, tuple[str, str]] = {
    "vertical": ("up", "down"), "lift": ("up", "down"),
    "lateral": ("downwind", "upwind"), "drag": ("downwind", "upwind"),
    "pitch": ("nose_up", "nose_down"), "moment": ("nose_up", "nose_down")}
REFERENCE_LENGTHS: dict[str, float] = {"B": 1.0, "b": 0.5}   # l / B
KEYS = (*DIRECTIONS, "reference_length")

# derivative -> (load, motion, part of h_Fx / (factor K^2) it is: "real" X_s or "imag" X_d)
TERMS: dict[str, tuple[str, str, str]] = {
    "H1": ("lift", "vertical", "imag"), "H4": ("lift", "vertical", "real"),
    "H2": ("lift", "pitch", "imag"), "H3": ("lift", "pitch", "real"),
    "H5": ("lift", "lateral", "imag"), "H6": ("lift", "lateral", "real"),
    "P5": ("drag", "vertical", "imag"), "P6": ("drag", "vertical", "real"),
    "P2": ("drag", "pitch", "imag"), "P3": ("drag", "pitch", "real"),
    "P1": ("drag", "lateral", "imag"), "P4": ("drag", "lateral", "real"),
    "A1": ("moment", "vertical", "imag"), "A4": ("moment", "vertical", "real"),
    "A2": ("moment", "pitch", "imag"), "A3": ("moment", "pitch", "real"),
    "A5": ("moment", "lateral", "imag"), "A6": ("moment", "lateral", "real")}
# (load, motion) -> internal FRF
FRF_OF: dict[tuple[str, str], str] = {
    ("lift", "vertical"): "h_pu", ("lift", "lateral"): "h_pr", ("lift", "pitch"): "h_ptheta",
    ("drag", "vertical"): "h_qu", ("drag", "lateral"): "h_qr", ("drag", "pitch"): "h_qtheta",
    ("moment", "vertical"): "h_mu", ("moment", "lateral"): "h_mr", ("moment", "pitch"): "h_mtheta"}
_LOAD_POWER = {"lift": 0, "drag": 0, "moment": 1}       # n_F
_MOTION_POWER = {"vertical": 0, "lateral": 0, "pitch": 1}   # d_x

# argument column -> (K from x, x from K)
ARGUMENTS = {"K": (lambda x: x, lambda K: K),
             "k": (lambda x: 2.0 * x, lambda K: 0.5 * K),
             "reduced_velocity": (lambda x: 2.0 * np.pi / x, lambda K: 2.0 * np.pi / K),
             "reduced_velocity_omega": (lambda x: 1.0 / x, lambda K: 1.0 / K)}

EXAMPLE_LINE = ("# convention: vertical=down lift=down lateral=downwind drag=downwind pitch=nose_up "
                "reference_length=B")

assert set(TERMS) == set(DERIVATIVE_NAMES) and set(FRF_OF.values()) == set(FRF_NAMES)


def to_reduced_frequency(argument: str, x: np.ndarray) -> np.ndarray:
    """K = B w / U from a table's argument column ``argument`` (one of :data:`ARGUMENTS`)."""
    if argument not in ARGUMENTS:
        raise InputError("derivatives.argument", argument, f"one of {', '.join(ARGUMENTS)}")
    with np.errstate(divide="ignore"):
        return ARGUMENTS[argument][0](np.asarray(x, dtype=np.float64))


def from_reduced_frequency(argument: str, K: np.ndarray) -> np.ndarray:
    """The argument column ``argument`` at K = B w / U (inverse of :func:`to_reduced_frequency`)."""
    if argument not in ARGUMENTS:
        raise InputError("derivatives.argument", argument, f"one of {', '.join(ARGUMENTS)}")
    return ARGUMENTS[argument][1](np.asarray(K, dtype=np.float64))


def _check(where: str, key: str, value: object) -> str:
    allowed = tuple(REFERENCE_LENGTHS) if key == "reference_length" else DIRECTIONS[key]
    if not isinstance(value, str) or value not in allowed:
        raise InputError(f"{where}.{key}", value, f"one of {', '.join(allowed)}")
    return value


@dataclass(frozen=True)
class Convention:
    """The positive directions and the reference length of a derivative table; None = not stated.

    ``vertical``, ``lift``: "up" | "down"; ``lateral``, ``drag``: "downwind" | "upwind"; ``pitch``,
    ``moment``: "nose_up" | "nose_down" (``moment`` defaults to ``pitch``); ``reference_length``: "B" | "b"
    (module docstring).  The internal convention is up, up, downwind, downwind, nose_up, nose_up, B.
    """

    vertical: str | None = None
    lift: str | None = None
    lateral: str | None = None
    drag: str | None = None
    pitch: str | None = None
    moment: str | None = None
    reference_length: str | None = None

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if value is not None:
                _check("derivatives_convention", f.name, value)

    # ---------------------------------------------------------------- reading
    @classmethod
    def from_mapping(cls, mapping: Mapping[str, object], where: str = "flutter.derivatives_convention") -> Convention:
        """From a ``[flutter.derivatives_convention]`` table; unknown keys and values raise InputError."""
        if not isinstance(mapping, Mapping):
            raise InputError(where, mapping, "must be a table of " + ", ".join(KEYS))
        for key in mapping:
            if key not in KEYS:
                raise InputError(f"{where}.{key}", mapping[key], f"unknown key; allowed: {', '.join(KEYS)}")
        return cls(**{k: _check(where, k, v) for k, v in mapping.items()})

    @classmethod
    def parse(cls, text: str, where: str = "convention") -> Convention:
        """From ``key=value`` words separated by spaces or commas (the text after ``# convention:``)."""
        values: dict[str, str] = {}
        for word in re.sub(r"\s*=\s*", "=", text.replace(",", " ")).split():
            key, sep, value = (s.strip() for s in word.partition("="))
            if not sep:
                raise InputError(where, word, "key=value words, e.g. " + EXAMPLE_LINE.split(": ", 1)[1])
            if key not in KEYS:
                raise InputError(f"{where}.{key}", value, f"unknown key; allowed: {', '.join(KEYS)}")
            if key in values and values[key] != value:
                raise InputError(f"{where}.{key}", value, f"stated twice ({values[key]!r} and {value!r})")
            values[key] = _check(where, key, value)
        return cls(**values)

    def merged(self, other: Convention, what_self: str, what_other: str) -> Convention:
        """The keys of both; a key stated differently by the two is an InputError (one of them is wrong,
        and guessing which is exactly the mistake a stated convention is there to prevent)."""
        out = {}
        for f in fields(self):
            a, b = getattr(self, f.name), getattr(other, f.name)
            if a is not None and b is not None and a != b:
                raise InputError(f"derivatives_convention.{f.name}", (a, b),
                                 f"{what_self} says {a!r}, {what_other} says {b!r}; state it once or make them agree")
            out[f.name] = a if a is not None else b
        return Convention(**out)

    # ---------------------------------------------------------------- using
    @property
    def stated(self) -> tuple[str, ...]:
        return tuple(f.name for f in fields(self) if getattr(self, f.name) is not None)

    def needs(self, derivatives: Iterable[str]) -> tuple[str, ...]:
        """Keys that converting ``derivatives`` needs and this convention does not state."""
        need = {"reference_length"}
        for name in derivatives:
            load, motion, _ = TERMS[name]
            need |= {motion, "pitch" if load == "moment" and self.moment is None else load}
        return tuple(k for k in KEYS if k in need and getattr(self, k) is None)

    def require(self, derivatives: Iterable[str], source: str) -> Convention:
        """self, or InputError naming the keys that ``derivatives`` need and how to state them."""
        missing = self.needs(derivatives)
        if missing:
            raise InputError(f"{source}: convention", ", ".join(missing),
                             "state the table's convention (which way its motions and loads are positive, and "
                             "its reference length): a comment line such as '" + EXAMPLE_LINE + "' (the "
                             "directions of YOUR source) or a [flutter.derivatives_convention] table with these "
                             "keys; see docs/flutter.md, 'Derivative tables: conventions'")
        return self

    def sign(self, axis: str) -> float:
        """+1 if the table's positive ``axis`` is the internal direction, -1 if not."""
        value = getattr(self, axis)
        if value is None and axis == "moment":
            value = self.pitch
        if value is None:
            raise InputError(f"derivatives_convention.{axis}", None, "not stated")
        return 1.0 if value == DIRECTIONS[axis][0] else -1.0

    def factor(self, derivative: str) -> float:
        """c with h_Fx = c K^2 (X_s + i X_d): s_F s_x (l/B)^{n_F + d_x + 1} (module docstring)."""
        load, motion, _ = TERMS[derivative]
        if self.reference_length is None:
            raise InputError("derivatives_convention.reference_length", None, "not stated")
        ratio = REFERENCE_LENGTHS[self.reference_length]
        return self.sign(load) * self.sign(motion) * ratio ** (_LOAD_POWER[load] + _MOTION_POWER[motion] + 1)

    def converted(self, derivatives: Mapping[str, np.ndarray], to: Convention) -> dict[str, np.ndarray]:
        """The same derivatives written in convention ``to``: X_to = (factor_self / factor_to) X_self."""
        return {n: self.factor(n) / to.factor(n) * np.asarray(v, dtype=np.float64) for n, v in derivatives.items()}

    def frf(self, K: np.ndarray, derivatives: Mapping[str, np.ndarray]) -> FRF:
        """The nine h_xy at K = B w / U from derivatives in this convention (absent ones count as zero)."""
        K2 = np.asarray(K, dtype=np.float64) ** 2
        parts: dict[str, dict[str, np.ndarray]] = {n: {"real": 0.0, "imag": 0.0} for n in FRF_NAMES}
        for name, value in derivatives.items():
            load, motion, part = TERMS[name]
            parts[FRF_OF[load, motion]][part] = self.factor(name) * np.asarray(value, dtype=np.float64)
        return FRF(**{n: K2 * (p["real"] + 1j * np.asarray(p["imag"])) for n, p in parts.items()})

    def derivatives(self, K: np.ndarray, h: FRF, names: Iterable[str] = DERIVATIVE_NAMES) -> dict[str, np.ndarray]:
        """Derivatives ``names`` in this convention from h_xy at K > 0 (inverse of :meth:`frf`)."""
        K2 = np.asarray(K, dtype=np.float64) ** 2
        out = {}
        for name in names:
            load, motion, part = TERMS[name]
            v = np.asarray(getattr(h, FRF_OF[load, motion]), dtype=np.complex128) / (self.factor(name) * K2)
            out[name] = v.real if part == "real" else v.imag
        return out

    def header_line(self) -> str:
        """The CSV comment line that states this convention."""
        return "# convention: " + " ".join(f"{k}={getattr(self, k)}" for k in self.stated)


# the form of bridge.flutter.derivatives (Simiu and Scanlan 1996, IABSE): h, L down; p, D downwind; nose-up; B
SCANLAN = Convention(vertical="down", lift="down", lateral="downwind", drag="downwind", pitch="nose_up",
                     moment="nose_up", reference_length="B")
# Scanlan and Tomko (1971): the same directions on the half chord b (argument k = b w / U in their paper)
SCANLAN_TOMKO = Convention(vertical="down", lift="down", lateral="downwind", drag="downwind", pitch="nose_up",
                           moment="nose_up", reference_length="b")
