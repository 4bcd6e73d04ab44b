"""Aerodynamic models of the deck: the four non-dimensional FRFs h_pu, h_ptheta, h_mu, h_mtheta (Eq 4.37)
as functions of the reduced frequency Omega = w B / V (Eq 4.38) and the mean wind speed V.

One interface, :class:`AerodynamicModel`: ``frf(omega, speed) -> FRF`` (complex arrays broadcast over
``omega`` and ``speed``) and the ranges of Omega and V where the model may be used.  Sign conventions are
the thesis's (u, p positive up; theta, m nose-up; moment about mid-chord), see
:mod:`bridge.flutter.derivatives`.  Models:

* :class:`Theodorsen` - thin flat plate in potential flow, closed form (Theodorsen 1935, NACA Report 496).
* :class:`QuasiSteady` - from static coefficients and their slopes (no memory effects).
* :class:`FRFTable` - h_xy tabulated over (Omega, V) in HDF5 (written by the CFD stage), linear
  interpolation of real and imaginary parts; asking outside the table raises InputError.
* :class:`DerivativeTable` - Scanlan's H1*..A4* against reduced velocity or K from a CSV file; assumed
  independent of V (Reynolds number), interpolated in K; outside the table's K raises InputError.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np
from scipy.interpolate import CubicSpline, RegularGridInterpolator
from scipy.special import hankel2

from bridge.errors import InputError, check_range
from bridge.flutter.derivatives import FRF, FlutterDerivatives, frf_from_derivatives

__all__ = ["AerodynamicModel", "Theodorsen", "QuasiSteady", "FRFTable", "DerivativeTable",
           "theodorsen_function", "FRF_NAMES"]

FRF_NAMES = ("h_pu", "h_ptheta", "h_mu", "h_mtheta")
_RANGE_RTOL = 1e-12  # round-off allowance at the ends of a table (never more)


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


def _check_within(key: str, values: np.ndarray, low: float, high: float, what: str) -> None:
    v = np.asarray(values, dtype=np.float64)
    if v.size == 0:
        return
    tol = _RANGE_RTOL * max(abs(low), abs(high), 1.0)
    vmin, vmax = float(np.min(v)), float(np.max(v))
    if not (vmin >= low - tol and vmax <= high + tol) or np.isnan(vmin) or np.isnan(vmax):
        bad = vmin if vmin < low - tol else vmax
        raise InputError(key, bad, f"{what} covers [{low:g}, {high:g}]; no extrapolation")


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
    """Quasi-steady FRFs from static coefficients (reference length B for all of them).

    Effective angle of attack alpha_e = theta - udot/V; the drag, tilted by -udot/V, adds to the lift:
        p = (1/2) rho V^2 B [C_L' theta - (C_L' + C_D) udot / V],  m = (1/2) rho V^2 B^2 C_M' (theta - udot/V)
    hence h_pu = -i Omega (C_L' + C_D), h_ptheta = C_L', h_mu = -i Omega C_M', h_mtheta = C_M'.
    The mean coefficients C_L and C_M set the static load only; they do not enter the linearised FRFs
    (kept so the model states the full static polar it came from).  No pitch-rate term.
    """

    lift_coefficient: float
    lift_slope_per_rad: float
    drag_coefficient: float
    moment_coefficient: float
    moment_slope_per_rad: float
    name: str = "quasi_steady"

    def __post_init__(self) -> None:
        for key in ("lift_coefficient", "lift_slope_per_rad", "moment_coefficient", "moment_slope_per_rad"):
            object.__setattr__(self, key, check_range(f"flutter.quasi_steady.{key}", getattr(self, key)))
        object.__setattr__(self, "drag_coefficient",
                           check_range("flutter.quasi_steady.drag_coefficient", self.drag_coefficient, low=0.0))

    def frf(self, omega, speed) -> FRF:
        omega, _ = np.broadcast_arrays(np.asarray(omega, dtype=np.float64), np.asarray(speed, dtype=np.float64))
        one = np.ones_like(omega, dtype=np.complex128)
        return FRF(h_pu=-1j * omega * (self.lift_slope_per_rad + self.drag_coefficient),
                   h_ptheta=self.lift_slope_per_rad * one,
                   h_mu=-1j * omega * self.moment_slope_per_rad,
                   h_mtheta=self.moment_slope_per_rad * one)


class FRFTable:
    """h_xy tabulated on a regular grid of Omega (ascending) and V (ascending), interpolated linearly in
    real and imaginary parts.  Asking outside [Omega_min, Omega_max] x [V_min, V_max] raises InputError.

    HDF5 schema read by :meth:`from_hdf5` (documented in docs/results.md, "Aerodynamic table (input)"):
    in group ``group`` (default ``/``): ``reduced_frequency`` (n_Omega,) float64 Omega = w B / V,
    ``speed_m_s`` (n_V,) float64, and ``h_pu``, ``h_ptheta``, ``h_mu``, ``h_mtheta`` (n_Omega, n_V)
    complex128, thesis sign conventions; at least 2 points on each axis.
    """

    name = "table"

    def __init__(self, omega: np.ndarray, speed: np.ndarray, values: FRF, source: str = "table"):
        omega = np.asarray(omega, dtype=np.float64)
        speed = np.asarray(speed, dtype=np.float64)
        for key, axis in (("reduced_frequency", omega), ("speed_m_s", speed)):
            if axis.ndim != 1 or axis.size < 2 or not np.all(np.isfinite(axis)) or np.any(np.diff(axis) <= 0):
                raise InputError(f"{source}:{key}", axis.tolist() if axis.size < 8 else axis.shape,
                                 "needs >= 2 finite, strictly ascending values")
        if omega[0] < 0.0 or speed[0] <= 0.0:
            raise InputError(f"{source}:axes", (omega[0], speed[0]), "Omega >= 0 and V > 0")
        self.omega, self.speed, self.source = omega, speed, source
        self._interp = {}
        for name in FRF_NAMES:
            v = np.asarray(getattr(values, name), dtype=np.complex128)
            if v.shape != (omega.size, speed.size) or not np.all(np.isfinite(v)):
                raise InputError(f"{source}:{name}", v.shape, f"needs finite shape ({omega.size}, {speed.size})")
            self._interp[name] = (
                RegularGridInterpolator((omega, speed), v.real, bounds_error=True),
                RegularGridInterpolator((omega, speed), v.imag, bounds_error=True))

    @classmethod
    def from_hdf5(cls, path: str | Path, group: str = "/") -> FRFTable:
        import h5py

        path = Path(path)
        if not path.is_file():
            raise InputError("flutter.table_path", str(path), "an existing HDF5 file")
        with h5py.File(path, "r") as f:
            if group not in f:
                raise InputError("flutter.table_group", group, f"a group in {path}")
            g = f[group]
            missing = [k for k in ("reduced_frequency", "speed_m_s", *FRF_NAMES) if k not in g]
            if missing:
                raise InputError(f"{path}:{group}", missing, "datasets required: reduced_frequency, "
                                 "speed_m_s, h_pu, h_ptheta, h_mu, h_mtheta")
            values = FRF(*(np.asarray(g[k][()], dtype=np.complex128) for k in FRF_NAMES))
            return cls(g["reduced_frequency"][()], g["speed_m_s"][()], values, source=str(path))

    @property
    def omega_range(self) -> tuple[float, float]:
        return (float(self.omega[0]), float(self.omega[-1]))

    @property
    def speed_range(self) -> tuple[float, float]:
        return (float(self.speed[0]), float(self.speed[-1]))

    def frf(self, omega, speed) -> FRF:
        omega, speed = np.broadcast_arrays(np.asarray(omega, dtype=np.float64), np.asarray(speed, dtype=np.float64))
        _check_within("flutter.reduced_frequency", omega, *self.omega_range, f"the table {self.source}")
        _check_within("flutter.speed_m_s", speed, *self.speed_range, f"the table {self.source}")
        pts = np.stack([np.clip(omega, *self.omega_range), np.clip(speed, *self.speed_range)], axis=-1)
        pts = pts.reshape(-1, 2)
        return FRF(*((re(pts) + 1j * im(pts)).reshape(omega.shape)
                     for re, im in (self._interp[n] for n in FRF_NAMES)))


def _linear(x_table: np.ndarray, y_table: np.ndarray):
    """Linear interpolation of complex values (used when a table has fewer than 4 rows)."""
    def f(x):
        return np.interp(x, x_table, y_table.real) + 1j * np.interp(x, x_table, y_table.imag)
    return f


class DerivativeTable:
    """Scanlan's flutter derivatives against K (or reduced velocity U/(fB) = 2 pi / K) from a CSV file.

    CSV: one header row, ``#`` comment lines allowed; a column ``K`` (= B w / U) or ``reduced_velocity``
    (= U / (f B)), and columns ``H1 H2 H3 H4 A1 A2 A3 A4`` (a trailing ``*`` in a name is accepted);
    Scanlan's convention (h, L positive down; alpha, M nose-up; mid-chord).  The table is converted to
    h_xy = K^2 (...) (smooth in K, whereas H* ~ 1/K^2) and interpolated in K with a cubic spline (linear
    with fewer than 4 rows).  Independent of V.  Outside the table's K range: InputError.
    """

    name = "derivatives"

    def __init__(self, K: np.ndarray, derivatives: FlutterDerivatives, source: str = "derivatives"):
        K = np.asarray(K, dtype=np.float64)
        order = np.argsort(K)
        K = K[order]
        if K.size < 2 or K[0] <= 0.0 or np.any(np.diff(K) <= 0) or not np.all(np.isfinite(K)):
            raise InputError(f"{source}:K", K.tolist()[:8], "needs >= 2 distinct finite K > 0")
        d = FlutterDerivatives(*(np.asarray(v, dtype=np.float64)[order] for v in derivatives))
        h = frf_from_derivatives(K, d)
        self.K, self.derivatives, self.source = K, d, source
        if K.size >= 4:
            self._spline = {n: CubicSpline(K, getattr(h, n)) for n in FRF_NAMES}
        else:
            self._spline = {n: _linear(K, getattr(h, n)) for n in FRF_NAMES}

    @classmethod
    def from_csv(cls, path: str | Path) -> DerivativeTable:
        path = Path(path)
        if not path.is_file():
            raise InputError("flutter.derivatives_path", str(path), "an existing CSV file")
        with path.open(newline="") as fh:
            rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
        if len(rows) < 3:
            raise InputError(str(path), len(rows), "a header row and at least 2 data rows")
        header = [c.strip().rstrip("*").strip() for c in rows[0]]
        names = ("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4")
        missing = [n for n in names if n not in header]
        if missing or not ({"K", "reduced_velocity"} & set(header)):
            raise InputError(f"{path}:header", rows[0], "columns K or reduced_velocity, and " + " ".join(names))
        try:
            data = np.array([[float(c) for c in r] for r in rows[1:]], dtype=np.float64)
        except ValueError as exc:
            raise InputError(str(path), str(exc), "numbers in every data cell") from None
        col = {n: data[:, header.index(n)] for n in header if n in names or n in ("K", "reduced_velocity")}
        K = col["K"] if "K" in col else 2.0 * np.pi / col["reduced_velocity"]
        return cls(K, FlutterDerivatives(*(col[n] for n in names)), source=str(path))

    @property
    def omega_range(self) -> tuple[float, float]:
        return (float(self.K[0]), float(self.K[-1]))

    @property
    def speed_range(self) -> tuple[float, float]:
        return (0.0, np.inf)

    def frf(self, omega, speed) -> FRF:
        omega, _ = np.broadcast_arrays(np.asarray(omega, dtype=np.float64), np.asarray(speed, dtype=np.float64))
        _check_within("flutter.reduced_frequency", omega, *self.omega_range, f"the derivative table {self.source}")
        x = np.clip(omega, *self.omega_range)
        return FRF(*(np.asarray(self._spline[n](x), dtype=np.complex128) for n in FRF_NAMES))
