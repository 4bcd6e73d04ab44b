"""The aeroelastic frequency response functions h_xy and Scanlan's 18 flutter derivatives, both ways.

Internal convention (the thesis's, Eq 4.19-4.21, 4.37, 4.38, extended to lateral motion), harmonic
motion ``x(t) = X e^{i w t}``, Omega = w B / V:
    u, p      vertical displacement and lift per unit length, positive UP (the y axis);
    r, q      lateral displacement and drag per unit length, positive DOWNWIND;
    theta, m  rotation and moment per unit length about the deck axis, positive nose-up (the upwind
              edge up);
    p = (1/2) rho V^2 [h_pu u + h_pr r + B h_ptheta theta]
    q = (1/2) rho V^2 [h_qu u + h_qr r + B h_qtheta theta]
    m = (1/2) rho V^2 B [h_mu u + h_mr r + B h_mtheta theta]
The thesis's four (h_pu, h_ptheta, h_mu, h_mtheta) are the vertical-torsional block; the five lateral
terms default to zero (the thesis has no lateral aerodynamics).

Scanlan's 18 derivatives (Scanlan and Tomko 1971 for H1*-H4*, A1*-A4*; the lateral set as in Simiu and
Scanlan, *Wind effects on structures*, 3rd ed. 1996, sec. 12.3), K = B w / U, axis at mid-chord,
h and L positive DOWN, p and D positive DOWNWIND, alpha and M nose-up:
    L = (1/2) rho U^2 B   [K H1 hdot/U + K H2 B alphadot/U + K^2 H3 alpha + K^2 H4 h/B + K H5 pdot/U + K^2 H6 p/B]
    D = (1/2) rho U^2 B   [K P1 pdot/U + K P2 B alphadot/U + K^2 P3 alpha + K^2 P4 p/B + K P5 hdot/U + K^2 P6 h/B]
    M = (1/2) rho U^2 B^2 [K A1 hdot/U + K A2 B alphadot/U + K^2 A3 alpha + K^2 A4 h/B + K A5 pdot/U + K^2 A6 p/B]
Substituting xdot = i (K U / B) x and u = -h, p_internal = -L, r = p, q = D, theta = alpha, m = M:
    h_pu =  K^2 (H4 + i H1)    h_pr = -K^2 (H6 + i H5)    h_ptheta = -K^2 (H3 + i H2)
    h_qu = -K^2 (P6 + i P5)    h_qr =  K^2 (P4 + i P1)    h_qtheta =  K^2 (P3 + i P2)
    h_mu = -K^2 (A4 + i A1)    h_mr =  K^2 (A6 + i A5)    h_mtheta =  K^2 (A3 + i A2)
(a term changes sign with each of its two motions/loads whose positive direction differs between the
conventions: vertical motion and lift are reversed, lateral and rotation are not).  Tables in other
conventions are converted by :mod:`bridge.flutter.conventions`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["FRF", "FlutterDerivatives", "frf_from_derivatives", "derivatives_from_frf", "scale_derivative", "FRF_NAMES",
           "DERIVATIVE_NAMES", "VERTICAL_TORSIONAL", "LATERAL"]


class FRF(NamedTuple):
    """The nine non-dimensional aeroelastic frequency response functions (complex arrays or scalars);
    the first four are Eq 4.37's, the lateral five default to zero."""

    h_pu: np.ndarray
    h_ptheta: np.ndarray
    h_mu: np.ndarray
    h_mtheta: np.ndarray
    h_pr: np.ndarray = 0.0
    h_qu: np.ndarray = 0.0
    h_qr: np.ndarray = 0.0
    h_qtheta: np.ndarray = 0.0
    h_mr: np.ndarray = 0.0


FRF_NAMES = FRF._fields
VERTICAL_TORSIONAL = ("h_pu", "h_ptheta", "h_mu", "h_mtheta")
LATERAL = ("h_pr", "h_qu", "h_qr", "h_qtheta", "h_mr")


class FlutterDerivatives(NamedTuple):
    """Scanlan's derivatives (module docstring: h, L down; p, D downwind; alpha, M nose-up; mid-chord).
    H1*-H4*, A1*-A4* first (the thesis's vertical-torsional set); the lateral ten default to zero."""

    H1: np.ndarray
    H2: np.ndarray
    H3: np.ndarray
    H4: np.ndarray
    A1: np.ndarray
    A2: np.ndarray
    A3: np.ndarray
    A4: np.ndarray
    H5: np.ndarray = 0.0
    H6: np.ndarray = 0.0
    A5: np.ndarray = 0.0
    A6: np.ndarray = 0.0
    P1: np.ndarray = 0.0
    P2: np.ndarray = 0.0
    P3: np.ndarray = 0.0
    P4: np.ndarray = 0.0
    P5: np.ndarray = 0.0
    P6: np.ndarray = 0.0


DERIVATIVE_NAMES = FlutterDerivatives._fields

# h_xy = sign K^2 (real + i imag) for each FRF (the table of the module docstring)
_MAP = {"h_pu": (1.0, "H4", "H1"), "h_pr": (-1.0, "H6", "H5"), "h_ptheta": (-1.0, "H3", "H2"),
        "h_qu": (-1.0, "P6", "P5"), "h_qr": (1.0, "P4", "P1"), "h_qtheta": (1.0, "P3", "P2"),
        "h_mu": (-1.0, "A4", "A1"), "h_mr": (1.0, "A6", "A5"), "h_mtheta": (1.0, "A3", "A2")}


def frf_from_derivatives(K: np.ndarray, d: FlutterDerivatives) -> FRF:
    """h_xy(Omega = K) from Scanlan's derivatives at reduced frequency K = B w / U (module docstring)."""
    K2 = np.asarray(K, dtype=np.float64) ** 2
    return FRF(**{name: sign * K2 * (np.asarray(getattr(d, re)) + 1j * np.asarray(getattr(d, im)))
                  for name, (sign, re, im) in _MAP.items()})


def derivatives_from_frf(K: np.ndarray, h: FRF) -> FlutterDerivatives:
    """Scanlan's derivatives from h_xy at Omega = K > 0 (inverse of :func:`frf_from_derivatives`)."""
    K2 = np.asarray(K, dtype=np.float64) ** 2
    out = {}
    for name, (sign, re, im) in _MAP.items():
        v = sign * np.asarray(getattr(h, name), dtype=np.complex128) / K2
        out[re], out[im] = v.real, v.imag
    return FlutterDerivatives(**out)


def scale_derivative(h: FRF, name: str, factor: float) -> FRF:
    """``h`` with Scanlan's derivative ``name`` (e.g. "A2") times ``factor`` and every other derivative as it
    was: the one part (real or imaginary) of the one h_xy that carries it, scaled (the module docstring's
    table; exact at every Omega, 0 included)."""
    for frf_name, (_, re, im) in _MAP.items():
        if name in (re, im):
            v = np.asarray(getattr(h, frf_name), dtype=np.complex128)
            v = (factor * v.real + 1j * v.imag) if name == re else (v.real + 1j * factor * v.imag)
            return h._replace(**{frf_name: v})
    raise ValueError(f"{name!r} is not one of Scanlan's derivatives ({', '.join(DERIVATIVE_NAMES)})")
