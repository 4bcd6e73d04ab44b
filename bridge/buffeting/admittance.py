"""Aerodynamic admittance: how much of the quasi-steady buffeting load a gust of a given frequency delivers.

One function |chi(f)|^2 for all three loads (lift, drag, moment) and both turbulence components multiplies the
quasi-steady load spectra (bridge.buffeting.loads); ``ADMITTANCES``:

* ``"sears"`` (default): Sears's function (Sears 1941, J. Aeronaut. Sci. 8: 104-108) of the thin aerofoil
  in a sinusoidal vertical gust, phi(k) = [J0(k) - i J1(k)] C(k) + i J1(k) with Theodorsen's C(k) and
  k = omega b / V = pi f B / V; |phi|^2 = 1 at k = 0 and about 1 / (2 pi k) at large k;
* ``"liepmann"``: Liepmann's approximation of it (Liepmann 1952, J. Aeronaut. Sci. 19: 793-800),
  |chi|^2 = 1 / (1 + 2 pi^2 f B / V), at most 0.09 below the exact one (near f B / V = 0.03);
* ``"none"``: 1, the quasi-steady loads as they are;
* ``"table"``: a measured |chi|^2 against f B / V, interpolated linearly, the end values held outside.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import j0, j1

from bridge.errors import InputError
from bridge.flutter.aerodynamics import theodorsen_function

__all__ = ["ADMITTANCES", "Admittance", "sears_function"]

ADMITTANCES = ("sears", "liepmann", "none", "table")


def sears_function(k: np.ndarray | float) -> np.ndarray:
    """Sears's function phi(k) = [J0(k) - i J1(k)] C(k) + i J1(k), k = omega b / V (b = B / 2); phi(0) = 1."""
    k = np.asarray(k, dtype=np.float64)
    return (j0(k) - 1j * j1(k)) * theodorsen_function(k) + 1j * j1(k)


@dataclass(frozen=True)
class Admittance:
    """The aerodynamic admittance |chi|^2 of the loads (module docstring); ``reduced_frequency`` (f B / V,
    ascending, >= 0) and ``squared`` (|chi|^2 >= 0) only with ``kind = "table"``."""

    kind: str = "sears"
    reduced_frequency: tuple[float, ...] = ()
    squared: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in ADMITTANCES:
            raise InputError("buffeting.admittance", self.kind, f"one of {', '.join(ADMITTANCES)}")
        x = np.asarray(self.reduced_frequency, dtype=np.float64)
        y = np.asarray(self.squared, dtype=np.float64)
        if self.kind != "table":
            if x.size or y.size:
                raise InputError("buffeting.admittance_reduced_frequency", list(self.reduced_frequency),
                                 "only with admittance = \"table\"")
            return
        if x.ndim != 1 or x.size < 2 or not np.all(np.isfinite(x)) or x[0] < 0.0 or np.any(np.diff(x) <= 0.0):
            raise InputError("buffeting.admittance_reduced_frequency", list(self.reduced_frequency),
                             ">= 2 finite values f B / V >= 0, strictly ascending")
        if y.shape != x.shape or not np.all(np.isfinite(y)) or np.any(y < 0.0):
            raise InputError("buffeting.admittance_squared", list(self.squared),
                             f"{x.size} finite values |chi|^2 >= 0, one per admittance_reduced_frequency")

    def squared_at(self, reduced_frequency: np.ndarray) -> np.ndarray:
        """|chi|^2 at f B / V."""
        x = np.asarray(reduced_frequency, dtype=np.float64)
        if self.kind == "sears":
            return np.abs(sears_function(np.pi * x)) ** 2
        if self.kind == "liepmann":
            return 1.0 / (1.0 + 2.0 * np.pi**2 * x)
        if self.kind == "none":
            return np.ones_like(x)
        if self.kind == "table":
            return np.interp(x, self.reduced_frequency, self.squared)
        raise InputError("buffeting.admittance", self.kind, f"one of {', '.join(ADMITTANCES)}")
