"""Aerodynamic models read from tables: h_xy tabulated over (Omega, V) in HDF5 (:class:`FRFTable`, e.g.
written by the CFD stage) and flutter derivatives against a reduced frequency or velocity in CSV
(:class:`DerivativeTable`, e.g. a wind-tunnel report, in the convention the table states; see
:mod:`bridge.flutter.conventions`).  Both implement :class:`bridge.flutter.aerodynamics.AerodynamicModel`,
list in ``provides`` the FRFs they really give (the others are zero, for another model to fill), and are
never extrapolated: asking outside a table's range raises InputError.
"""

from __future__ import annotations

import csv
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from scipy.interpolate import CubicSpline, RegularGridInterpolator

from bridge.errors import InputError
from bridge.flutter.conventions import ARGUMENTS, FRF_OF, SCANLAN, TERMS, Convention, to_reduced_frequency
from bridge.flutter.derivatives import (
    DERIVATIVE_NAMES,
    FRF,
    FRF_NAMES,
    LATERAL,
    VERTICAL_TORSIONAL,
    FlutterDerivatives,
    frf_from_derivatives,
)

__all__ = ["FRFTable", "DerivativeTable", "check_within", "MISSING_DERIVATIVES", "DERIVATIVE_PAIRS"]

MISSING_DERIVATIVES = ("error", "zero")
# FRF -> (the derivative of its real part, of its imaginary part), e.g. h_pu = c K^2 (H4 + i H1)
DERIVATIVE_PAIRS: dict[str, tuple[str, str]] = {
    FRF_OF[load, motion]: tuple(sorted((n for n, t in TERMS.items() if t[:2] == (load, motion)),
                                       key=lambda n: TERMS[n][2] != "real"))
    for load, motion in FRF_OF}


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
    complex128, thesis sign conventions; at least 2 points on each axis.  Optional: any of the lateral
    ``h_pr``, ``h_qu``, ``h_qr``, ``h_qtheta``, ``h_mr`` (same shape, conventions of
    :mod:`bridge.flutter.derivatives`); those present are in ``provides``, the others are zero.
    """

    name = "table"

    def __init__(self, omega: np.ndarray, speed: np.ndarray, values: FRF, source: str = "table",
                 provides: tuple[str, ...] = VERTICAL_TORSIONAL):
        omega = np.asarray(omega, dtype=np.float64)
        speed = np.asarray(speed, dtype=np.float64)
        for key, axis in (("reduced_frequency", omega), ("speed_m_s", speed)):
            if axis.ndim != 1 or axis.size < 2 or not np.all(np.isfinite(axis)) or np.any(np.diff(axis) <= 0):
                raise InputError(f"{source}:{key}", axis.tolist() if axis.size < 8 else axis.shape,
                                 "needs >= 2 finite, strictly ascending values")
        if omega[0] < 0.0 or speed[0] <= 0.0:
            raise InputError(f"{source}:axes", (omega[0], speed[0]), "Omega >= 0 and V > 0")
        self.provides = _provides(provides, source)
        self.omega, self.speed, self.source = omega, speed, source
        self._interp = {}
        shape = (omega.size, speed.size)
        for name in self.provides:
            v = np.asarray(getattr(values, name), dtype=np.complex128)
            if v.ndim == 0:                  # a constant (e.g. a lateral term written as 0)
                v = np.full(shape, v[()])
            if v.shape != shape or not np.all(np.isfinite(v)):
                raise InputError(f"{source}:{name}", v.shape, f"needs finite shape {shape} (or one number)")
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
            missing = [k for k in ("reduced_frequency", "speed_m_s", *VERTICAL_TORSIONAL) if k not in g]
            if missing:
                raise InputError(f"{path}:{group}", missing, "datasets required: reduced_frequency, "
                                 "speed_m_s, h_pu, h_ptheta, h_mu, h_mtheta (optional: " + ", ".join(LATERAL) + ")")
            provides = VERTICAL_TORSIONAL + tuple(n for n in LATERAL if n in g)
            values = FRF(**{k: np.asarray(g[k][()], dtype=np.complex128) for k in provides})
            return cls(g["reduced_frequency"][()], g["speed_m_s"][()], values, source=str(path), provides=provides)

    def data_arguments(self) -> dict[str, Any]:
        """The constructor's arguments (the tabulated values read back from the interpolators) and the
        ``name`` when an instance has its own, for the stage cache (:mod:`bridge.datastore`)."""
        values = FRF(**{n: re.values + 1j * im.values for n, (re, im) in self._interp.items()})
        return {"omega": self.omega, "speed": self.speed, "values": values, "source": self.source,
                "provides": self.provides, **_own_name(self)}

    @classmethod
    def from_data_arguments(cls, arguments: dict[str, Any]) -> FRFTable:
        return _named(cls, arguments)

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
        return FRF(**{n: (re(pts) + 1j * im(pts)).reshape(omega.shape) for n, (re, im) in self._interp.items()})


def _provides(provides, source: str) -> tuple[str, ...]:
    """Checked ``provides``: known FRF names, the vertical-torsional four always among them, FRF order."""
    provides = tuple(provides)
    unknown = [n for n in provides if n not in FRF_NAMES]
    if unknown:
        raise InputError(f"{source}:provides", unknown, f"FRF names: {', '.join(FRF_NAMES)}")
    return tuple(n for n in FRF_NAMES if n in provides or n in VERTICAL_TORSIONAL)


def _own_name(table) -> dict[str, str]:
    """``{"name": ...}`` when the instance has a name of its own (not the class's), else nothing."""
    return {"name": vars(table)["name"]} if "name" in vars(table) else {}


def _named(cls, arguments: dict[str, Any]):
    """A table built from its constructor's ``arguments``, given the name among them as its own."""
    arguments = dict(arguments)
    name = arguments.pop("name", None)
    table = cls(**arguments)
    if name is not None:
        table.name = name
    return table


class _Linear:
    """Linear interpolation of complex values (used when a table has fewer than 4 rows); a class, not a
    closure, so that a table can be pickled (e.g. sent to a worker process)."""

    def __init__(self, x_table: np.ndarray, y_table: np.ndarray):
        self.x, self.y = np.asarray(x_table), np.asarray(y_table)

    def __call__(self, x):
        return np.interp(x, self.x, self.y.real) + 1j * np.interp(x, self.x, self.y.imag)


class DerivativeTable:
    """Flutter derivatives against a reduced frequency or velocity (V-independent), e.g. from a wind tunnel.

    Held in the Scanlan form of :mod:`bridge.flutter.derivatives` (``derivatives``, against K = B w / U),
    converted to h_xy = c K^2 (...) (smooth in K, whereas H* ~ 1/K^2) and interpolated in K with a cubic
    spline (linear with fewer than 4 rows).  ``provides``: the FRFs the table determines (the
    vertical-torsional four always; a lateral one when the table has one of its two derivatives); the
    others are zero, for :class:`bridge.flutter.aerodynamics.WithLateral` to fill.  ``convention``: the
    convention the table was given in (None when built from Scanlan-form arrays).  Outside the table's K
    range: InputError.

    CSV (:meth:`from_csv`): ``#`` comment lines, of which ``# convention: ...`` state the convention
    (:mod:`bridge.flutter.conventions`); one header row; exactly one argument column, ``K`` (= B w/U),
    ``k`` (= b w/U, b = B/2), ``reduced_velocity`` (= U/(fB)) or ``reduced_velocity_omega`` (= U/(wB));
    derivative columns among H1-H6, A1-A6, P1-P6 (a trailing ``*`` accepted).  Every column is read;
    other columns are ignored with a warning naming them.  H1-H4 and A1-A4 are required, and a lateral
    FRF given by one of its two derivatives needs the other (H5/H6, A5/A6, P1/P4, P2/P3, P5/P6), unless
    ``missing = "zero"`` says the missing ones are zero.  A lateral FRF with neither column is not
    provided (not "zero": another model may fill it); to state that it is zero, give its columns as 0.
    """

    name = "derivatives"

    def __init__(self, K: np.ndarray, derivatives: FlutterDerivatives, source: str = "derivatives",
                 provides: tuple[str, ...] = VERTICAL_TORSIONAL, convention: Convention | None = None):
        K = np.asarray(K, dtype=np.float64)
        if K.ndim != 1 or K.size < 2 or not np.all(np.isfinite(K)) or np.any(K <= 0.0):
            raise InputError(f"{source}:K", K.tolist()[:8], "needs >= 2 finite K > 0")
        order = np.argsort(K)
        K = K[order]
        if np.any(np.diff(K) <= 0):
            raise InputError(f"{source}:K", K.tolist()[:8], "needs >= 2 distinct finite K > 0")
        d = FlutterDerivatives(*(np.broadcast_to(np.asarray(v, dtype=np.float64), K.shape)[order]
                                 for v in derivatives))
        self.provides = _provides(provides, source)
        stray = [n for f in FRF_NAMES if f not in self.provides for n in DERIVATIVE_PAIRS[f]
                 if np.any(getattr(d, n) != 0.0)]
        if stray:
            raise InputError(f"{source}:provides", self.provides,
                             f"derivatives {', '.join(stray)} are not zero: name their FRFs in provides")
        if not all(np.all(np.isfinite(v)) for v in d):
            raise InputError(source, "non-finite derivative", "finite numbers in every cell")
        h = frf_from_derivatives(K, d)
        self.K, self.derivatives, self.source, self.convention = K, d, source, convention
        interp = CubicSpline if K.size >= 4 else _Linear
        self._spline = {n: interp(K, getattr(h, n)) for n in self.provides}

    @classmethod
    def from_csv(cls, path: str | Path, convention: Convention | None = None,
                 missing: str = "error") -> DerivativeTable:
        """Read a CSV table (class docstring).  ``convention``: keys stated in the scenario
        ([flutter.derivatives_convention]); merged with the file's ``# convention:`` lines, a key stated
        differently by the two is an InputError.  ``missing``: "error" | "zero" (missing derivatives)."""
        if missing not in MISSING_DERIVATIVES:
            raise InputError("flutter.missing_derivatives", missing, f"one of {', '.join(MISSING_DERIVATIVES)}")
        path = Path(path)
        if not path.is_file():
            raise InputError("flutter.derivatives_path", str(path), "an existing CSV file")
        source = str(path)
        stated = Convention()
        numbered = []   # (line number in the file, cells) of the header and data rows
        for n, line in enumerate(path.read_text().splitlines(), start=1):
            text = line.strip()
            if text.startswith("#"):
                body = text.lstrip("#").strip()
                if body.lower().startswith("convention:"):
                    stated = stated.merged(Convention.parse(body.split(":", 1)[1], f"{source}: convention"),
                                           "an earlier convention line", "a later one")
            elif text:
                cells = next(csv.reader([line]))
                if any(c.strip() for c in cells):
                    numbered.append((n, cells))
        rows = [cells for _, cells in numbered]
        if len(rows) < 3:
            raise InputError(source, len(rows), "a header row and at least 2 data rows")
        header = [c.strip().rstrip("*").strip() for c in rows[0]]
        seen = [h for i, h in enumerate(header) if h in header[:i]]
        if seen:
            raise InputError(f"{source}:header", seen, "each column once")
        arguments = [h for h in header if h in ARGUMENTS]
        if len(arguments) != 1:
            raise InputError(f"{source}:header", rows[0],
                             f"exactly one argument column, one of {', '.join(ARGUMENTS)} "
                             "(K = B w/U, k = b w/U with b = B/2, U/(fB), U/(wB))")
        given = [h for h in header if h in DERIVATIVE_NAMES]
        unknown = [h for h in header if h not in ARGUMENTS and h not in DERIVATIVE_NAMES]
        if unknown:
            warnings.warn(f"{source}: columns ignored (neither an argument nor a flutter derivative): "
                          f"{', '.join(unknown)}", UserWarning, stacklevel=2)
        # the derivatives a table must have: H1-H4, A1-A4, and the partner of each lateral one it has
        needed = [n for f in FRF_NAMES for n in DERIVATIVE_PAIRS[f]
                  if f in VERTICAL_TORSIONAL or any(m in given for m in DERIVATIVE_PAIRS[f])]
        absent = [n for n in needed if n not in given]
        if absent and missing == "error":
            raise InputError(f"{source}:header", ", ".join(absent),
                             "these derivative columns are missing; add them, or set [flutter] "
                             "missing_derivatives = \"zero\" to take them as zero")
        if convention is not None:
            stated = stated.merged(convention, f"{source}", "[flutter.derivatives_convention]")
        if not stated.stated:
            raise InputError(f"{source}: convention", "none stated",
                             "a derivative table must state its convention; " + _HOW_TO)
        stated.require(given, source)
        width = len(header)
        uneven = [n for n, r in numbered[1:] if len(r) != width]
        if uneven:
            raise InputError(source, f"lines {uneven[:5]}", f"{width} cells in every row, as in the header")
        data = np.empty((len(rows) - 1, width), dtype=np.float64)
        for i, (n, r) in enumerate(numbered[1:]):
            for j, cell in enumerate(r):
                try:
                    data[i, j] = float(cell)
                except ValueError:
                    raise InputError(f"{source}: line {n}, column {header[j] or j + 1}", cell.strip(),
                                     "must be a number") from None
                if not np.isfinite(data[i, j]):
                    raise InputError(f"{source}: line {n}, column {header[j] or j + 1}", cell.strip(),
                                     "must be a finite number")
        col = {h: data[:, i] for i, h in enumerate(header)}
        x = col[arguments[0]]
        if np.any(x <= 0.0):
            raise InputError(f"{source}:{arguments[0]}", float(x.min()), "> 0")
        K = to_reduced_frequency(arguments[0], x)
        scanlan = stated.converted({n: col[n] for n in given}, SCANLAN)
        provides = VERTICAL_TORSIONAL + tuple(f for f in LATERAL if any(n in given for n in DERIVATIVE_PAIRS[f]))
        d = FlutterDerivatives(**{n: scanlan.get(n, np.zeros_like(K)) for n in DERIVATIVE_NAMES})
        return cls(K, d, source=source, provides=provides, convention=stated)

    def data_arguments(self) -> dict[str, Any]:
        """The constructor's arguments and the ``name`` when an instance has its own (the aero stage names
        its table), for the stage cache (:mod:`bridge.datastore`)."""
        return {"K": self.K, "derivatives": self.derivatives, "source": self.source, "provides": self.provides,
                "convention": self.convention, **_own_name(self)}

    @classmethod
    def from_data_arguments(cls, arguments: dict[str, Any]) -> DerivativeTable:
        return _named(cls, arguments)

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
        return FRF(**{n: np.asarray(s(x), dtype=np.complex128) for n, s in self._spline.items()})


_HOW_TO = ("add a comment line such as '# convention: vertical=down lift=down lateral=downwind drag=downwind "
           "pitch=nose_up reference_length=B' with the directions and reference length of YOUR source "
           "(vertical, lift: up|down; lateral, drag: downwind|upwind; pitch, moment: nose_up|nose_down; "
           "reference_length: B|b), or the same keys in a [flutter.derivatives_convention] table; see "
           "docs/flutter.md, 'Derivative tables: conventions'")
