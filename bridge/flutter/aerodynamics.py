"""Aerodynamic models of the deck: the four non-dimensional FRFs h_pu, h_ptheta, h_mu, h_mtheta (Eq 4.37)
as functions of the reduced frequency Omega = w B / V (Eq 4.38) and the mean wind speed V.

One interface, :class:`AerodynamicModel`: ``frf(omega, speed) -> FRF`` (complex arrays broadcast over
``omega`` and ``speed``; the nine FRFs of :mod:`bridge.flutter.derivatives`, lateral ones zero unless the
model's ``provides`` names them) and the ranges of Omega and V where the model may be used.  Sign conventions are
the thesis's (u, p positive up; theta, m nose-up; moment about mid-chord), see
:mod:`bridge.flutter.derivatives`.  Models:

* :class:`Theodorsen` - thin flat plate in potential flow, closed form (Theodorsen 1935, NACA Report 496).
* :class:`QuasiSteady` - from static coefficients and their slopes (no memory effects), all nine FRFs.
* :class:`WithLateral` - any of the others completed by the quasi-steady lateral terms.
* :class:`FRFTable` - h_xy tabulated over (Omega, V) in HDF5 (written by the CFD stage), linear
  interpolation of real and imaginary parts; asking outside the table raises InputError.
* :class:`DerivativeTable` - any of the 18 flutter derivatives against reduced velocity or K from a CSV
  file in the convention it states (:mod:`bridge.flutter.conventions`); assumed
  independent of V (Reynolds number), interpolated in K; outside the table's K raises InputError.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from scipy.special import hankel2

from bridge.errors import check_range
from bridge.flutter.derivatives import FRF, FRF_NAMES, LATERAL, VERTICAL_TORSIONAL
from bridge.flutter.tables import DerivativeTable, FRFTable, check_within

__all__ = ["AerodynamicModel", "Theodorsen", "QuasiSteady", "WithLateral", "FRFTable", "DerivativeTable",
           "theodorsen_function", "FRF_NAMES", "check_within", "has_lateral"]


def has_lateral(aero) -> bool:
    """True when the model gives any of the five lateral FRFs (a lateral mode then feels the wind)."""
    return any(n in getattr(aero, "provides", VERTICAL_TORSIONAL) for n in LATERAL)



class AerodynamicModel(Protocol):
    """What the flutter solvers need from an aerodynamic model."""

    name: str

    @property
    def omega_range(self) -> tuple[float, float]: ...

    @property
    def speed_range(self) -> tuple[float, float]: ...

    def frf(self, omega: np.ndarray | float, speed: np.ndarray | float) -> FRF: ...


def theodorsen_function(k: np.ndarray | float) -> np.ndarray:
    """Theodorsen's C(k) = H1(2)(k) / (H1(2)(k) + i H0(2)(k)), k = b w / U (b = half chord); C(0) = 1."""
    k = np.asarray(k, dtype=np.float64)
    out = np.ones(k.shape, dtype=np.complex128)
    pos = k > 0.0
    h1, h0 = hankel2(1, k[pos]), hankel2(0, k[pos])
    out[pos] = h1 / (h1 + 1j * h0)
    return out


class _ClosedForm:
    """A closed-form model: defined for every Omega >= 0 and V >= 0, so nothing is extrapolated."""

    omega_range: tuple[float, float] = (0.0, np.inf)
    speed_range: tuple[float, float] = (0.0, np.inf)


@dataclass(frozen=True)
class Theodorsen(_ClosedForm):
    """Thin flat plate, moment about mid-chord (a = 0), k = Omega / 2.

    Derived from Theodorsen's lift and moment (h down, L up, alpha nose-up) with u = -h:
        h_pu     = 2 pi k^2 - 4 pi i k C
        h_ptheta = i pi k + 2 pi C (1 + i k / 2)
        h_mu     = -i pi k C
        h_mtheta = (pi/2) [k^2/8 - i k/2 + C (1 + i k / 2)]
    For k -> 0: h_ptheta -> 2 pi, h_mtheta -> pi/2 (lift slope 2 pi, moment slope pi/2 per radian).
    """

    name: str = "theodorsen"
    provides: tuple[str, ...] = VERTICAL_TORSIONAL   # potential flow: no drag, no lateral terms

    def frf(self, omega, speed) -> FRF:
        omega, speed = np.broadcast_arrays(np.asarray(omega, dtype=np.float64),
                                           np.asarray(speed, dtype=np.float64))
        k = 0.5 * omega
        C = theodorsen_function(k)
        return FRF(h_pu=2.0 * np.pi * k**2 - 4j * np.pi * k * C,
                   h_ptheta=1j * np.pi * k + 2.0 * np.pi * C * (1.0 + 0.5j * k),
                   h_mu=-1j * np.pi * k * C,
                   h_mtheta=0.5 * np.pi * (k**2 / 8.0 - 0.5j * k + C * (1.0 + 0.5j * k)))


@dataclass(frozen=True)
class QuasiSteady(_ClosedForm):
    """Quasi-steady FRFs, all nine, from static coefficients (reference length B for all of them: a drag
    coefficient on the depth D is C_D^B = C_D^D D / B) and their slopes per radian.

    The deck at rest sees the wind U downwind; moving with (udot, rdot) it sees the relative wind
    (U - rdot, -udot): speed^2 ~ U^2 (1 - 2 rdot/U), inclination gamma ~ -udot/U, so the angle of attack
    is alpha_e = theta - udot/U.  Drag acts along the relative wind and lift across it; to first order
        p = (1/2) rho U^2 B   [C_L' theta - (C_L' + C_D) udot/U - 2 C_L rdot/U]
        q = (1/2) rho U^2 B   [C_D' theta + (C_L - C_D') udot/U - 2 C_D rdot/U]
        m = (1/2) rho U^2 B^2 [C_M' theta - C_M' udot/U - 2 C_M rdot/U]
    hence, with udot/U = i Omega u / B (Eq 4.37 normalisation):
        h_pu = -i Omega (C_L' + C_D)   h_pr = -2 i Omega C_L   h_ptheta = C_L'
        h_qu =  i Omega (C_L - C_D')   h_qr = -2 i Omega C_D   h_qtheta = C_D'
        h_mu = -i Omega C_M'           h_mr = -2 i Omega C_M   h_mtheta = C_M'
    The vertical block is Den Hartog's: a section free in heave alone gallops when C_L' + C_D < 0.  No
    pitch-rate term (the static coefficients carry no information on it).  ``drag_slope_per_rad`` defaults
    to 0 (older scenario files give only the other five coefficients).
    """

    lift_coefficient: float
    lift_slope_per_rad: float
    drag_coefficient: float
    moment_coefficient: float
    moment_slope_per_rad: float
    drag_slope_per_rad: float = 0.0
    name: str = "quasi_steady"
    provides: tuple[str, ...] = FRF_NAMES

    def __post_init__(self) -> None:
        for key in ("lift_coefficient", "lift_slope_per_rad", "moment_coefficient", "moment_slope_per_rad",
                    "drag_slope_per_rad"):
            object.__setattr__(self, key, check_range(f"flutter.quasi_steady.{key}", getattr(self, key)))
        object.__setattr__(self, "drag_coefficient",
                           check_range("flutter.quasi_steady.drag_coefficient", self.drag_coefficient, low=0.0))

    def frf(self, omega, speed) -> FRF:
        omega, _ = np.broadcast_arrays(np.asarray(omega, dtype=np.float64), np.asarray(speed, dtype=np.float64))
        one = np.ones_like(omega, dtype=np.complex128)
        cl, dcl = self.lift_coefficient, self.lift_slope_per_rad
        cd, dcd = self.drag_coefficient, self.drag_slope_per_rad
        cm, dcm = self.moment_coefficient, self.moment_slope_per_rad
        i_om = 1j * omega
        return FRF(h_pu=-i_om * (dcl + cd), h_ptheta=dcl * one, h_mu=-i_om * dcm, h_mtheta=dcm * one,
                   h_pr=-2.0 * i_om * cl, h_qu=i_om * (cl - dcd), h_qr=-2.0 * i_om * cd, h_qtheta=dcd * one,
                   h_mr=-2.0 * i_om * cm)


class WithLateral:
    """A model of the vertical and torsional aerodynamics (Theodorsen, a measured table) completed by the
    quasi-steady lateral terms of static coefficients wherever it has none (``base.provides`` lacks them):
    a deck with H*/A* measured but no P* still gets its drag, lateral damping and lateral coupling."""

    def __init__(self, base: AerodynamicModel, lateral: QuasiSteady):
        self.base, self.lateral = base, lateral
        self.filled = tuple(n for n in LATERAL if n not in getattr(base, "provides", VERTICAL_TORSIONAL))
        self.name = f"{base.name} + quasi-steady lateral" if self.filled else base.name
        self.provides = tuple(dict.fromkeys((*getattr(base, "provides", VERTICAL_TORSIONAL), *self.filled)))

    def data_arguments(self) -> dict[str, Any]:
        """The constructor's arguments, for the stage cache (:mod:`bridge.datastore`)."""
        return {"base": self.base, "lateral": self.lateral}

    @classmethod
    def from_data_arguments(cls, arguments: dict[str, Any]) -> WithLateral:
        return cls(**arguments)

    @property
    def omega_range(self) -> tuple[float, float]:
        return self.base.omega_range

    @property
    def speed_range(self) -> tuple[float, float]:
        return self.base.speed_range

    def frf(self, omega, speed) -> FRF:
        h = self.base.frf(omega, speed)
        if not self.filled:
            return h
        q = self.lateral.frf(omega, speed)
        return h._replace(**{n: getattr(q, n) for n in self.filled})
