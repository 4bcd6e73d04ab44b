"""Aerodynamic models read from tables: h_xy tabulated over (Omega, V) in HDF5 (:class:`FRFTable`, e.g.
written by the CFD stage) and Scanlan's flutter derivatives against reduced velocity or K in CSV
(:class:`DerivativeTable`, e.g. a wind-tunnel report).  Both implement
:class:`bridge.flutter.aerodynamics.AerodynamicModel` and are never extrapolated: asking outside a
table's range raises InputError.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline, RegularGridInterpolator

from bridge.errors import InputError
from bridge.flutter.derivatives import FRF, VERTICAL_TORSIONAL, FlutterDerivatives, frf_from_derivatives

__all__ = ["FRFTable", "DerivativeTable", "check_within"]

FRF_NAMES = VERTICAL_TORSIONAL  # the four h_xy a table carries today


_RANGE_RTOL = 1e-12  # round-off allowance at the ends of a table (never more)


def check_within(key: str, values: np.ndarray, low: float, high: float, what: str) -> None:
    v = np.asarray(values, dtype=np.float64)
    if v.size == 0:
        return
    tol = _RANGE_RTOL * max(abs(low), abs(high), 1.0)
    vmin, vmax = float(np.min(v)), float(np.max(v))
    if not (vmin >= low - tol and vmax <= high + tol) or np.isnan(vmin) or np.isnan(vmax):
        bad = vmin if vmin < low - tol else vmax
        raise InputError(key, bad, f"{what} covers [{low:g}, {high:g}]; no extrapolation")


class FRFTable:
    """h_xy tabulated on a regular grid of Omega (ascending) and V (ascending), interpolated linearly in
    real and imaginary parts.  Asking outside [Omega_min, Omega_max] x [V_min, V_max] raises InputError.

    HDF5 schema read by :meth:`from_hdf5` (documented in docs/results.md, "Aerodynamic table (input)"):
    in group ``group`` (default ``/``): ``reduced_frequency`` (n_Omega,) float64 Omega = w B / V,
    ``speed_m_s`` (n_V,) float64, and ``h_pu``, ``h_ptheta``, ``h_mu``, ``h_mtheta`` (n_Omega, n_V)
    complex128, thesis sign conventions; at least 2 points on each axis.
    """

    name = "table"
    provides = FRF_NAMES

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
        check_within("flutter.reduced_frequency", omega, *self.omega_range, f"the table {self.source}")
        check_within("flutter.speed_m_s", speed, *self.speed_range, f"the table {self.source}")
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
    provides = FRF_NAMES

    def __init__(self, K: np.ndarray, derivatives: FlutterDerivatives, source: str = "derivatives"):
        K = np.asarray(K, dtype=np.float64)
        order = np.argsort(K)
        K = K[order]
        if K.size < 2 or K[0] <= 0.0 or np.any(np.diff(K) <= 0) or not np.all(np.isfinite(K)):
            raise InputError(f"{source}:K", K.tolist()[:8], "needs >= 2 distinct finite K > 0")
        d = FlutterDerivatives(*(np.broadcast_to(np.asarray(v, dtype=np.float64), K.shape)[order]
                                 for v in derivatives))
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
        check_within("flutter.reduced_frequency", omega, *self.omega_range, f"the derivative table {self.source}")
        x = np.clip(omega, *self.omega_range)
        return FRF(*(np.asarray(self._spline[n](x), dtype=np.complex128) for n in FRF_NAMES))
