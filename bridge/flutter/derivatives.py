"""Conversion between the thesis's frequency response functions h_xy and Scanlan's flutter derivatives.

Thesis (Eq 4.19-4.21, 4.37, 4.38), harmonic motion ``x(t) = X e^{i w t}``:
    u, p      vertical displacement and lift per unit length, positive UP (the y axis);
    theta, m  rotation and moment per unit length, positive nose-up (leading edge, facing the wind, up);
    p = (1/2) rho V^2 [h_pu u + B h_ptheta theta],  m = (1/2) rho V^2 B [h_mu u + B h_mtheta theta],
    with Omega = w B / V.
Scanlan and Tomko (1971), with K = B w / U (= Omega), h and L positive DOWN, alpha and M nose-up:
    L = (1/2) rho U^2 B [K H1* hdot/U + K H2* B alphadot/U + K^2 H3* alpha + K^2 H4* h/B]
    M = (1/2) rho U^2 B^2 [K A1* hdot/U + K A2* B alphadot/U + K^2 A3* alpha + K^2 A4* h/B]
The moment is taken about the mid-chord (the deck's centre line) in both.

Substituting hdot = i w h = i (K U / B) h and u = -h, p = -L, theta = alpha, m = M:
    h_pu     =  K^2 (H4* + i H1*)        h_ptheta = -K^2 (H3* + i H2*)
    h_mu     = -K^2 (A4* + i A1*)        h_mtheta =  K^2 (A3* + i A2*)
(so with h and L positive UP, H2*, H3*, A1*, A4* change sign; Scanlan and Tomko 1971, docs/reference_cases.md).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["FRF", "FlutterDerivatives", "frf_from_derivatives", "derivatives_from_frf"]


class FRF(NamedTuple):
    """The four non-dimensional aeroelastic frequency response functions of Eq 4.37 (complex arrays)."""

    h_pu: np.ndarray
    h_ptheta: np.ndarray
    h_mu: np.ndarray
    h_mtheta: np.ndarray


class FlutterDerivatives(NamedTuple):
    """Scanlan's H1*..H4*, A1*..A4* (h, L positive down; alpha, M nose-up; mid-chord axis)."""

    H1: np.ndarray
    H2: np.ndarray
    H3: np.ndarray
    H4: np.ndarray
    A1: np.ndarray
    A2: np.ndarray
    A3: np.ndarray
    A4: np.ndarray


def frf_from_derivatives(K: np.ndarray, d: FlutterDerivatives) -> FRF:
    """h_xy(Omega = K) from Scanlan's derivatives at reduced frequency K = B w / U (see module docstring)."""
    K2 = np.asarray(K, dtype=np.float64) ** 2
    return FRF(h_pu=K2 * (d.H4 + 1j * d.H1), h_ptheta=-K2 * (d.H3 + 1j * d.H2),
               h_mu=-K2 * (d.A4 + 1j * d.A1), h_mtheta=K2 * (d.A3 + 1j * d.A2))


def derivatives_from_frf(K: np.ndarray, h: FRF) -> FlutterDerivatives:
    """Scanlan's derivatives from h_xy at Omega = K > 0 (inverse of :func:`frf_from_derivatives`)."""
    K2 = np.asarray(K, dtype=np.float64) ** 2
    return FlutterDerivatives(
        H1=np.imag(h.h_pu) / K2, H2=-np.imag(h.h_ptheta) / K2, H3=-np.real(h.h_ptheta) / K2,
        H4=np.real(h.h_pu) / K2, A1=-np.imag(h.h_mu) / K2, A2=np.imag(h.h_mtheta) / K2,
        A3=np.real(h.h_mtheta) / K2, A4=-np.real(h.h_mu) / K2)
