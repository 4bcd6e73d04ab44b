"""Two-mode flutter by the determinant method (thesis sections 4.3, 4.4 and 5.4).

Onset of flutter: a real frequency w and wind speed V with det(A_s(w) - A_a(w, V)) = 0 (Eq 4.29), with
    A_s = diag(A_j),  A_j(w) = m_j (w_j^2 - w^2 + 2 i zeta_j w_j w)                       (Eq 4.27-4.28)
    A_a[i, j] = (1/2) rho V^2 L [h_pu uu_ij + B h_ptheta ut_ij + B h_mu ut_ji + B^2 h_mtheta tt_ij]
                                                                                (Eq 4.24, 4.37, 4.39)
Reduced form (derived here; the thesis's Eq 4.40/4.43 has the wrong sign, see docs/flutter.md):
substitute w = Omega V / B, w_j = Omega_j V / B (Eq 4.38, 4.41) and divide row i by V^2 m_i / B^2 (> 0,
so the determinant only changes by a positive factor):
    D_ij(Omega, V) = delta_ij (Omega_i^2 - Omega^2 + 2 i zeta_i Omega_i Omega)
                     - (rho B^2 L / (2 m_i)) [h_pu uu_ij + B h_ptheta ut_ij + B h_mu ut_ji + B^2 h_mtheta tt_ij]
which for a bending mode j (m_j = mu L a_jj) and a torsional mode k (m_k = J L a_kk) is exactly
a_s - a_a with a_a of Eq 4.44 and a_s = diag(Omega_j^2 - Omega^2 + 2 i zeta_j Omega_j Omega, ...).
det(D) = f1 + i f2 (Eq 5.15-5.16); (Omega_c, V_c) by Newton-Raphson with a numerical Jacobian
(Eq 5.19-5.21), started from a bracketing scan over V so that the LOWEST critical speed is found.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bridge.errors import InputError, check_range
from bridge.flutter.aerodynamics import AerodynamicModel
from bridge.flutter.modal import ModalModel

__all__ = ["reduced_matrix", "dimensional_matrix", "determinant", "FlutterResult", "DeterminantMap",
           "solve_pair", "solve_pairs", "governing", "STRUCTURAL_FORMS"]

# "derived": Eq 4.28 carried into reduced variables (correct).  "thesis_eq_4_43": the printed Eq 4.43,
# Omega^2 - Omega_j^2 + 2 i zeta_j Omega_j Omega; kept only to demonstrate the erratum in the tests.
STRUCTURAL_FORMS = ("derived", "thesis_eq_4_43")


def _aero_bracket(model: ModalModel, frf) -> np.ndarray:
    """Generalised aerodynamic stiffness per unit (1/2) rho V^2 L, shape (..., N, N):
    [h_pu uu + h_pr ur + B h_ptheta ut + h_qu ru + h_qr rr + B h_qtheta rt
     + B h_mu tu + B h_mr tr + B^2 h_mtheta tt]_ij
    with xy_ij = (1/L) int X_i Y_j (U vertical, R lateral downwind, Theta torsion; ru = ur^T, tu = ut^T,
    tr = rt^T): the strip loads p, q, m of bridge.flutter.derivatives integrated against mode i."""
    B = model.deck_width_m

    def e(h):
        return np.asarray(h)[..., None, None]

    out = (e(frf.h_pu) * model.uu + B * e(frf.h_ptheta) * model.ut + B * e(frf.h_mu) * model.ut.T
           + B**2 * e(frf.h_mtheta) * model.tt)
    if model.has_lateral:
        out = out + (e(frf.h_pr) * model.ur + e(frf.h_qu) * model.ur.T + e(frf.h_qr) * model.rr
                     + B * e(frf.h_qtheta) * model.rt + B * e(frf.h_mr) * model.rt.T)
    return out


def reduced_matrix(model: ModalModel, aero: AerodynamicModel, air_density: float, omega, speed,
                   structural_form: str = "derived") -> np.ndarray:
    """D(Omega, V) of the module docstring, shape broadcast(omega, speed).shape + (N, N)."""
    omega, speed = np.broadcast_arrays(np.asarray(omega, dtype=np.float64), np.asarray(speed, dtype=np.float64))
    B, L = model.deck_width_m, model.deck_length_m
    Om_i = model.angular_frequencies * B / speed[..., None]           # Eq 4.41, shape (..., N)
    Om = omega[..., None]
    zeta = model.damping_ratios
    if structural_form == "derived":
        diag = Om_i**2 - Om**2 + 2j * zeta * Om_i * Om                # Eq 4.28 / (V^2 / B^2)
    elif structural_form == "thesis_eq_4_43":
        diag = Om**2 - Om_i**2 + 2j * zeta * Om_i * Om                # as printed (wrong)
    else:
        raise InputError("flutter.structural_form", structural_form, f"one of {', '.join(STRUCTURAL_FORMS)}")
    scale = air_density * B**2 * L / (2.0 * model.modal_masses)      # rho B^2 L / (2 m_i), per row
    D = -scale[:, None] * _aero_bracket(model, aero.frf(omega, speed))
    idx = np.arange(model.n_modes)
    D[..., idx, idx] += diag
    return D


def dimensional_matrix(model: ModalModel, aero: AerodynamicModel, air_density: float, w, speed) -> np.ndarray:
    """A_s(w) - A_a(w, V) of Eq 4.26-4.28 and 4.39 in physical units, w in rad/s."""
    w, speed = np.broadcast_arrays(np.asarray(w, dtype=np.float64), np.asarray(speed, dtype=np.float64))
    B, L = model.deck_width_m, model.deck_length_m
    wj, zeta, m = model.angular_frequencies, model.damping_ratios, model.modal_masses
    A_s = m * (wj**2 - w[..., None] ** 2 + 2j * zeta * wj * w[..., None])   # Eq 4.28
    A_a = 0.5 * air_density * (speed**2)[..., None, None] * L * _aero_bracket(model, aero.frf(w * B / speed, speed))
    idx = np.arange(model.n_modes)
    out = -A_a
    out[..., idx, idx] += A_s
    return out


def determinant(D: np.ndarray) -> np.ndarray:
    """det of a stack of N x N matrices = f1 + i f2 (Eq 5.15-5.16; 2 x 2: A11 A22 - A12 A21)."""
    if D.shape[-1] == 2:
        return D[..., 0, 0] * D[..., 1, 1] - D[..., 0, 1] * D[..., 1, 0]
    return np.linalg.det(D)


@dataclass(frozen=True)
class DeterminantMap:
    """f1 = Re det, f2 = Im det (Eq 5.16) on the scan grid, for plots.  Shapes (n_omega, n_speed)."""

    reduced_frequency: np.ndarray   # Omega, (n_omega, n_speed)
    speed_m_s: np.ndarray           # (n_speed,)
    f1: np.ndarray
    f2: np.ndarray


@dataclass(frozen=True)
class FlutterResult:
    """Outcome of the two-mode determinant method for one (bending, torsion) pair.

    ``flutter`` False means no solution was found for V in [min_speed_searched_m_s,
    max_speed_searched_m_s]; the critical values are then NaN.  Where the aerodynamic model is a table:
    ``covered_omega_range`` is its Omega range ((0, inf) for a closed form), ``scan_covered`` False when
    part of the scan (w in [0.25 min w_i, 1.5 max w_i] at each V) lay outside it, and
    ``uncovered_speeds_m_s`` the intervals of searched speeds at which the data do not cover the pair's
    natural frequencies [min w_i, max w_i] (Omega = w B / V outside the range: no root searched there).
    ``no_root_in_covered_range``: no flutter found where the model has data - not "no flutter below
    max_speed_searched_m_s".
    """

    pair: tuple[str, ...]
    flutter: bool
    critical_speed_m_s: float
    frequency_hz: float
    reduced_frequency: float
    iterations: int
    residual: float
    min_speed_searched_m_s: float
    max_speed_searched_m_s: float
    scan: DeterminantMap | None = field(default=None, repr=False, compare=False)
    covered_omega_range: tuple[float, float] = (0.0, np.inf)
    scan_covered: bool = True
    uncovered_speeds_m_s: tuple[tuple[float, float], ...] = ()

    @property
    def no_root_in_covered_range(self) -> bool:
        """No flutter found, and the aerodynamic data did not cover the whole search."""
        return not self.flutter and not self.scan_covered


def _normalised_residual(D: np.ndarray) -> float:
    """|det| relative to the size of its terms: |A11 A22 - A12 A21| / (|A11 A22| + |A12 A21|) for two
    modes; for N modes |det D| / prod_i ||row_i|| (Hadamard's bound, 1 for orthogonal rows)."""
    if D.shape[-1] == 2:
        return float(abs(determinant(D)) / (abs(D[0, 0] * D[1, 1]) + abs(D[0, 1] * D[1, 0])))
    return float(abs(determinant(D)) / np.prod(np.linalg.norm(D, axis=1)))


def speed_window(aero, air_density: float, max_speed_m_s: float, min_speed_m_s: float | None) -> tuple[float, float]:
    """Checked (V_min, V_max) of a flutter search: positive density and speeds, inside the aerodynamic
    model's V range (a table is never extrapolated); V_min defaults to max(model's V_min, 1 % of V_max)."""
    check_range("flutter.air_density_kg_m3", air_density, low=0.0, low_open=True)
    v_hi = check_range("flutter.max_speed_m_s", max_speed_m_s, low=0.0, low_open=True)
    s_lo, s_hi = aero.speed_range
    if v_hi > s_hi * (1 + 1e-12):
        raise InputError("flutter.max_speed_m_s", v_hi,
                         f"the aerodynamic model covers V in [{s_lo:g}, {s_hi:g}]; no extrapolation")
    v_lo = max(s_lo, 0.01 * v_hi) if min_speed_m_s is None else check_range(
        "flutter.min_speed_m_s", min_speed_m_s, low=s_lo, high=v_hi, high_open=True)
    return v_lo, v_hi


def solve_pair(model: ModalModel, aero: AerodynamicModel, air_density: float, max_speed_m_s: float,
               min_speed_m_s: float | None = None, n_speed: int = 120, n_omega: int = 241,
               structural_form: str = "derived", tolerance: float = 1e-10,
               max_iterations: int = 50) -> FlutterResult:
    """Lowest critical speed of a two-mode ``model`` (mode 0 bending, mode 1 torsion, or any two modes);
    a model of more modes (a pair with a lateral mode) is solved the same way on det of its N x N D.

    Scan: on a grid of w in [0.25 min w_i, 1.5 max w_i] (Omega = w B / V) and V in [V_min, V_max], find
    the roots of f2 in Omega at each V and the first V step over which f1 at a root changes sign; then
    Newton-Raphson on (f1, f2) = 0 in (Omega, V) with central-difference Jacobian (Eq 5.19-5.21).
    A table-based aerodynamic model that does not cover the needed V range raises InputError.  Scan points
    outside the model's Omega range are NaN in both f1 and f2 (no sign change, so no root, across the
    border of the covered region); the result gives the table's range, the speeds at which it misses the
    pair's natural frequencies (``uncovered_speeds_m_s``) and, without a root, ``no_root_in_covered_range``.
    """
    if model.n_modes < 2:
        raise InputError("flutter.pair", model.labels, "the determinant method takes two or more modes")
    v_lo, v_hi = speed_window(aero, air_density, max_speed_m_s, min_speed_m_s)
    B = model.deck_width_m
    wi = model.angular_frequencies
    speeds = np.linspace(v_lo, v_hi, int(n_speed))
    w = np.linspace(0.25 * wi.min(), 1.5 * wi.max(), int(n_omega))
    Om = w[:, None] * B / speeds[None, :]
    o_lo, o_hi = aero.omega_range
    inside = (Om >= o_lo) & (Om <= o_hi)
    f = np.full(Om.shape, complex(np.nan, np.nan))   # outside the model: NaN in f1 AND f2 (nan + 0j had f2 = 0)
    if np.any(inside):
        Vg = np.broadcast_to(speeds, Om.shape)
        f[inside] = determinant(reduced_matrix(model, aero, air_density, Om[inside], Vg[inside], structural_form))
    f1, f2 = f.real, f.imag
    scan = DeterminantMap(reduced_frequency=Om, speed_m_s=speeds, f1=f1, f2=f2)

    def roots(col: int) -> list[tuple[float, float]]:
        """(w, f1) at the sign changes of f2 along w in column ``col`` (linear interpolation)."""
        a, b = f2[:-1, col], f2[1:, col]
        out = []
        for i in np.flatnonzero(np.isfinite(a) & np.isfinite(b) & (np.sign(a) != np.sign(b)) & (a != 0)):
            t = a[i] / (a[i] - b[i])
            out.append((w[i] + t * (w[i + 1] - w[i]), f1[i, col] + t * (f1[i + 1, col] - f1[i, col])))
        return out

    labels = tuple(model.labels)
    # the data cover the natural frequencies [min w_i, max w_i] for B max w_i / o_hi <= V <= B min w_i / o_lo
    v_a = B * wi.max() / o_hi if o_hi > 0 else np.inf
    v_b = B * wi.min() / o_lo if o_lo > 0 else np.inf
    gaps = [(v_lo, min(v_a, v_hi))] if v_a > v_lo else []
    gaps += [(max(v_b, v_lo), v_hi)] if v_b < v_hi else []
    if v_a > v_b:                                           # nowhere covered: one gap, the whole window
        gaps = [(v_lo, v_hi)]
    coverage = dict(covered_omega_range=(float(o_lo), float(o_hi)), scan_covered=bool(np.all(inside)),
                    uncovered_speeds_m_s=tuple((float(a), float(b)) for a, b in gaps))
    dw = w[1] - w[0]
    previous = roots(0)
    for col in range(1, speeds.size):
        current = roots(col)
        candidates = []
        for wa, f1a in previous:
            if not current:
                break
            wb, f1b = min(current, key=lambda r: abs(r[0] - wa))
            if abs(wb - wa) <= 3.0 * dw and np.sign(f1a) != np.sign(f1b):
                t = f1a / (f1a - f1b)
                candidates.append((wa + t * (wb - wa), speeds[col - 1] + t * (speeds[col] - speeds[col - 1])))
        for w0, V0 in sorted(candidates, key=lambda c: c[1]):
            res = _newton(model, aero, air_density, w0 * B / V0, V0, structural_form, tolerance, max_iterations,
                          (speeds[col - 1] - 2 * (speeds[1] - speeds[0]), speeds[col] + 2 * (speeds[1] - speeds[0])))
            if res is not None:
                Om_c, V_c, it, r = res
                return FlutterResult(pair=labels, flutter=True, critical_speed_m_s=V_c,
                                     frequency_hz=Om_c * V_c / B / (2 * np.pi), reduced_frequency=Om_c,
                                     iterations=it, residual=r, min_speed_searched_m_s=float(v_lo),
                                     max_speed_searched_m_s=float(v_hi), scan=scan, **coverage)
        previous = current
    # no root: "no flutter below v_hi" if the model covered the whole scan, else "no root in the covered
    # range" (FlutterResult.no_root_in_covered_range); never extrapolated, never an error for the stage
    return FlutterResult(pair=labels, flutter=False, critical_speed_m_s=np.nan, frequency_hz=np.nan,
                         reduced_frequency=np.nan, iterations=0, residual=np.nan,
                         min_speed_searched_m_s=float(v_lo), max_speed_searched_m_s=float(v_hi), scan=scan,
                         **coverage)


def _newton(model, aero, rho, Om0, V0, form, tol, max_iterations, v_window):
    """Newton-Raphson on (f1, f2) = 0 in x = (Omega, V), Eq 5.19-5.21.  Returns (Omega, V, iterations,
    normalised residual) or None if it does not converge inside ``v_window`` with Omega > 0."""
    o_lo, o_hi = aero.omega_range
    s_lo, s_hi = aero.speed_range

    def f(Om, V):
        d = determinant(reduced_matrix(model, aero, rho, Om, V, form))
        return np.array([d.real, d.imag])

    def clip_ok(Om, V):
        return o_lo <= Om <= o_hi and s_lo <= V <= s_hi and Om > 0 and v_window[0] <= V <= v_window[1]

    x = np.array([Om0, V0], dtype=np.float64)
    fx = f(*x)
    for it in range(1, max_iterations + 1):
        J = np.empty((2, 2))
        for c in range(2):
            h = 1e-7 * x[c]
            xp, xm = x.copy(), x.copy()
            xp[c] += h
            xm[c] -= h
            if not clip_ok(*xp):         # one-sided differences at the edge of a table
                xp = x.copy()
            if not clip_ok(*xm):
                xm = x.copy()
            J[:, c] = (f(*xp) - f(*xm)) / (xp[c] - xm[c])   # Eq 5.21, numerically
        try:
            dx = -np.linalg.solve(J, fx)
        except np.linalg.LinAlgError:
            return None
        step = 1.0
        while not clip_ok(*(x + step * dx)) and step > 1e-3:
            step *= 0.5
        if not clip_ok(*(x + step * dx)):
            return None
        x = x + step * dx
        fx = f(*x)
        if abs(step * dx[0]) <= tol * abs(x[0]) and abs(step * dx[1]) <= tol * abs(x[1]):
            D = reduced_matrix(model, aero, rho, x[0], x[1], form)
            return float(x[0]), float(x[1]), it, _normalised_residual(D)
    return None


def solve_pairs(model: ModalModel, aero: AerodynamicModel, air_density: float, max_speed_m_s: float,
                which: str = "thesis", **kwargs) -> list[FlutterResult]:
    """:func:`solve_pair` for every (bending, torsion) pair of ``model.pairs(which)``."""
    return [solve_pair(model.subset(p), aero, air_density, max_speed_m_s, **kwargs) for p in model.pairs(which)]


def governing(results: list[FlutterResult]) -> FlutterResult | None:
    """The pair with the lowest critical speed, or None if no pair flutters."""
    fl = [r for r in results if r.flutter]
    return min(fl, key=lambda r: r.critical_speed_m_s) if fl else None
