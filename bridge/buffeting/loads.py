"""Buffeting loads on the deck and their cross-spectra in modal coordinates.

Quasi-steady strip loads (Davenport 1962, Proc. ICE 23: 389-408; Scanlan 1978, J. Sound Vib. 60: 201-211;
Strommen, *Theory of Bridge Aerodynamics*, 2nd ed. 2010, sec. 5.2).  The deck at rest in the wind
(V + u, w) sees the relative wind at the inclination w / V (positive from below: the angle of attack
grows by w / V) with the speed^2 V^2 (1 + 2 u / V); drag acts along that wind and lift across it, so that to
first order in u / V and w / V the loads per unit length (lift p up, drag q downwind, moment m nose-up,
the sign conventions of bridge.flutter.derivatives) are

    p_b = (1/2) rho V B   [2 C_L u + (C_L' + C_D) w]
    q_b = (1/2) rho V B   [2 C_D u + (C_D' - C_L) w]
    m_b = (1/2) rho V B^2 [2 C_M u + C_M' w]

with the static coefficients of bridge.flutter.aerodynamics.QuasiSteady (all on B, slopes per radian).
The self-excited quasi-steady model of that class is the same expansion with (u, w) -> (-rdot, -udot).

The aerodynamic admittance |chi(f)|^2 (bridge.buffeting.admittance) multiplies the load spectra.

Modal loads: with the deck's mode shapes U_i (vertical), R_i (lateral, downwind), Theta_i (torsion) along x,
the modal load Q_i = int (U_i p + R_i q + Theta_i m) dx = (1/2) rho V B int (psi_u,i u + psi_w,i w) dx with
the load shapes (:func:`load_shapes`)

    psi_u,i = 2 C_L U_i + 2 C_D R_i + 2 B C_M Theta_i,   psi_w,i = (C_L' + C_D) U_i + (C_D' - C_L) R_i + B C_M' Theta_i.

With u and w uncorrelated and Davenport's coherence, the one-sided modal load cross-spectral matrix is

    S_Q,ij(f) = ((1/2) rho V B)^2 |chi(f)|^2 [S_u(f) J_u,ij(C_u f / V) + S_w(f) J_w,ij(C_w f / V)],
    J_ij(a) = int int psi_i(x1) psi_j(x2) exp(-a |x1 - x2|) dx1 dx2,

the double integral over the trapezoidal cells of the deck nodes (the rule of the modal integrals of Eq 4.34,
bridge.structure.modes) with the coherence integrated exactly over each cell (:func:`span_integral`).  J
depends on the frequency and the speed only through a = C f / V, so :class:`SpanIntegrals` tabulates it once
on a grid of a and interpolates (cubic spline in log(1 + a L)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from bridge.errors import InputError, check_range
from bridge.flutter.aerodynamics import QuasiSteady
from bridge.structure.modes import trapezoid_weights

__all__ = ["DeckModes", "load_shapes", "span_integral",
           "SpanIntegrals", "modal_load_spectra"]

@dataclass(frozen=True)
class DeckModes:
    """Mode shapes along the deck, one row per mode in the order of ``labels`` (those of the ModalModel they
    belong to), at the deck nodes ``z_m`` (ascending): ``vertical`` U (up), ``torsional`` Theta (nose-up),
    ``lateral`` R (downwind), each (N, n_z), normalised as the ModalModel's integrals are."""

    labels: tuple[str, ...]
    z_m: np.ndarray
    vertical: np.ndarray
    torsional: np.ndarray
    lateral: np.ndarray
    mid_span_z_m: float

    def __post_init__(self) -> None:
        z = np.asarray(self.z_m, dtype=np.float64)
        n = len(self.labels)
        if z.ndim != 1 or z.size < 2 or np.any(np.diff(z) <= 0.0):
            raise InputError("buffeting.z_m", z.shape, ">= 2 strictly ascending deck stations")
        for name in ("vertical", "torsional", "lateral"):
            a = np.asarray(getattr(self, name), dtype=np.float64)
            if a.shape != (n, z.size) or not np.all(np.isfinite(a)):
                raise InputError(f"buffeting.{name}", a.shape, f"finite shapes of shape ({n}, {z.size})")
        check_range("buffeting.mid_span_z_m", self.mid_span_z_m, low=float(z[0]), high=float(z[-1]))

    @classmethod
    def from_mode_set(cls, mode_set, labels: tuple[str, ...]) -> DeckModes:
        """The shapes of the fem stage's modes (:class:`bridge.structure.modes.ModeSet`) named ``labels``:
        U = u_y, Theta = theta_z and R = -u_x (the wind blows towards -x: bridge.structure.analysis,
        FemResult.modal_model)."""
        ix = [mode_set.index(label) for label in labels]
        return cls(tuple(labels), np.asarray(mode_set.z_m, dtype=np.float64), mode_set.U[ix], mode_set.Theta[ix],
                   -mode_set.V[ix], float(mode_set.mid_span_z_m))

    @property
    def weights(self) -> np.ndarray:
        """Trapezoidal weights of the stations [m]."""
        return trapezoid_weights(self.z_m)

    def at(self, z_m: float) -> np.ndarray:
        """(3, N) shapes at the station z (linear between nodes): rows vertical, torsional, lateral."""
        return np.array([[np.interp(z_m, self.z_m, row) for row in field]
                         for field in (self.vertical, self.torsional, self.lateral)])

    def stacked(self) -> np.ndarray:
        """(3, N, n_z): vertical, torsional, lateral."""
        return np.stack([self.vertical, self.torsional, self.lateral])

    def integrals(self, deck_length_m: float) -> dict[str, np.ndarray]:
        """The modal integrals of a :class:`bridge.flutter.modal.ModalModel` of these shapes (Eq 4.34 and
        its lateral terms, by the trapezoidal rule): uu, ut, tt, rr, ur, rt, each (N, N), (1/L) int X_i Y_j."""
        w = self.weights / deck_length_m
        U, T, R = self.vertical, self.torsional, self.lateral
        return {name: (a * w) @ b.T for name, (a, b) in
                {"uu": (U, U), "ut": (U, T), "tt": (T, T), "rr": (R, R), "ur": (U, R), "rt": (R, T)}.items()}


def load_shapes(modes: DeckModes, coefficients: QuasiSteady, deck_width_m: float) -> tuple[np.ndarray, np.ndarray]:
    """(psi_u, psi_w), each (N, n_z): the modal load per (1/2) rho V B per unit u and w (module docstring)."""
    c, B = coefficients, deck_width_m
    psi_u = 2.0 * (c.lift_coefficient * modes.vertical + c.drag_coefficient * modes.lateral
                   + B * c.moment_coefficient * modes.torsional)
    psi_w = ((c.lift_slope_per_rad + c.drag_coefficient) * modes.vertical
             + (c.drag_slope_per_rad - c.lift_coefficient) * modes.lateral
             + B * c.moment_slope_per_rad * modes.torsional)
    return psi_u, psi_w


def _edge_weight(x: np.ndarray) -> np.ndarray:
    """(1 - e^-x) / x (1 at x = 0): the weight of a cell of width w against a point outside it, per w (x = a w)."""
    small = x < 1e-8
    xs = np.where(small, 1.0, x)
    return np.where(small, 1.0 - 0.5 * x, -np.expm1(-xs) / xs)


def _self_kernel(x: np.ndarray) -> np.ndarray:
    """2 (x - 1 + e^-x) / x^2: the double integral of exp(-a |s - t|) over one cell of width w, per w^2 (x = a w)."""
    small = x < 1e-3
    xs = np.where(small, 1.0, x)
    return np.where(small, 1.0 - x / 3.0 + x * x / 12.0, 2.0 * (xs + np.expm1(-xs)) / (xs * xs))


def span_integral(z_m: np.ndarray, psi: np.ndarray, a: np.ndarray) -> np.ndarray:
    """J(a)_ij = int int psi_i(x) psi_j(y) exp(-a |x - y|) dx dy, shape (len(a), N, N), with psi constant on
    the trapezoidal cells of the stations (cell k: width w_k, the trapezoidal weight; the cells tile the deck)
    and the kernel integrated exactly over them.  Two cells k < l, a gap d_kl = w_k+1 + ... + w_l-1 apart,
    contribute psi_k psi_l^T q_k q_l exp(-a d_kl) with q = (1 - e^(-a w)) / a, and a cell with itself
    psi_k psi_k^T w_k^2 s(a w_k), s(x) = 2 (x - 1 + e^-x) / x^2.  At a = 0 this is the trapezoidal rule
    ((sum_k w_k psi_k)^2); for a psi constant along the deck it is the exact integral at any a (lumping the
    kernel on the nodes instead over-counts each node's own cell by a factor of about a w / 2 once a w > 1).
    The sums over the cells before k, F_k = exp(-a w_k-1) F_k-1 + q_k-1 psi_k-1, and after it, G_k, make
    J = sum_k q_k psi_k (F_k + G_k)^T + the cells' own terms: O(n_z N^2) per a, every term bounded (no
    overflow, no cancellation)."""
    z = np.asarray(z_m, dtype=np.float64)
    psi = np.asarray(psi, dtype=np.float64).T                                  # (n_z, N)
    w = trapezoid_weights(z)
    a = np.atleast_1d(np.asarray(a, dtype=np.float64))
    x = a[None, :] * w[:, None]                                                # (n_z, n_a)
    g = (w[:, None] * _edge_weight(x))[:, :, None] * psi[:, None, :]           # q_k psi_k, (n_z, n_a, N)
    decay = np.exp(-x)[:, :, None]                                             # across cell k
    before, after = np.zeros_like(g), np.zeros_like(g)
    for k in range(1, z.size):
        before[k] = decay[k - 1] * before[k - 1] + g[k - 1]
        after[-1 - k] = decay[-k] * after[-k] + g[-k]
    own = w[:, None] ** 2 * _self_kernel(x)                                    # (n_z, n_a)
    J = (np.einsum("kai,kaj->aij", g, before + after, optimize=True)
         + np.einsum("ka,ki,kj->aij", own, psi, psi, optimize=True))
    return 0.5 * (J + np.swapaxes(J, 1, 2))


class SpanIntegrals:
    """J(a) of :func:`span_integral` tabulated for a in [0, a_max] and interpolated: a cubic spline in
    t = log(1 + a L) (L the deck length) through ``points`` values of t evenly spaced; beyond a_max the
    last value times a_max / a (J ~ 1 / a once exp(-a |dx|) is much narrower than the shapes)."""

    def __init__(self, z_m: np.ndarray, psi: np.ndarray, a_max: float, points: int = 161):
        z = np.asarray(z_m, dtype=np.float64)
        self.length_m = float(z[-1] - z[0])
        self.a_max = float(a_max)
        t = np.linspace(0.0, np.log1p(max(self.a_max, 0.0) * self.length_m), int(points))
        a = np.expm1(t) / self.length_m
        values = span_integral(z, psi, a)
        self.at_zero = values[0]
        self.last = values[-1]
        self.spline = CubicSpline(t, values, axis=0) if self.a_max > 0.0 else None

    def __call__(self, a: np.ndarray) -> np.ndarray:
        a = np.asarray(a, dtype=np.float64)
        if self.spline is None:
            return np.broadcast_to(self.at_zero, a.shape + self.at_zero.shape).copy()
        inside = np.minimum(a, self.a_max)
        out = self.spline(np.log1p(inside * self.length_m))
        beyond = a > self.a_max
        if np.any(beyond):
            out[beyond] = self.last * (self.a_max / a[beyond])[:, None, None]
        return out


def modal_load_spectra(f: np.ndarray, speed_m_s: float, air_density: float, deck_width_m: float,
                       spectra: tuple[np.ndarray, np.ndarray], admittance_squared: np.ndarray,
                       integrals: tuple[SpanIntegrals, SpanIntegrals], decays: tuple[float, float]) -> np.ndarray:
    """S_Q(f) (len(f), N, N), one-sided per Hz, real symmetric (module docstring).  ``spectra`` = (S_u, S_w)
    and ``admittance_squared`` at ``f``; ``integrals`` = (J_u, J_w); ``decays`` = (C_u, C_w)."""
    f = np.asarray(f, dtype=np.float64)
    (su, sw), (ju, jw), (cu, cw) = spectra, integrals, decays
    scale = (0.5 * air_density * speed_m_s * deck_width_m) ** 2 * np.asarray(admittance_squared)
    S = su[:, None, None] * ju(cu * f / speed_m_s) + sw[:, None, None] * jw(cw * f / speed_m_s)
    return scale[:, None, None] * S
