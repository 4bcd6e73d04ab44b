"""Multimode buffeting response in the frequency domain (Davenport 1962; Scanlan 1978, J. Sound Vib. 60:
201-211; Jain, Jones and Scanlan 1996, J. Struct. Eng. 122(7): 716-725; Strommen, *Theory of Bridge
Aerodynamics*, 2nd ed. 2010, ch. 5).

Modal equations of the N modes of a :class:`bridge.flutter.modal.ModalModel` (the flutter stage's), with
the self-excited forces of the flutter stage's aerodynamic model and the buffeting loads Q_b
(bridge.buffeting.loads), for motion e^{i w t}:

    Z(w, V) eta = Q_b,   Z = A_s(w) - A_a(w, V)                          (thesis Eq 4.26-4.28, 4.39)
    A_s = diag(m_i (w_i^2 - w^2 + 2 i zeta_i w_i w)),
    A_a = (1/2) rho V^2 L [h_pu uu + B h_ptheta ut + B h_mu tu + B^2 h_mtheta tt + lateral terms](Omega = w B / V)

i.e. H(w) = Z^-1 = [-w^2 M + i w (C - C_ae) + K - K_ae]^-1 with K_ae = Re A_a and C_ae = Im A_a / w: this is
:func:`bridge.flutter.determinant.dimensional_matrix`, which this module calls (with rho = 0 in A_a when
the self-excited forces are left out).  The modal response cross-spectra and the covariance are

    S_eta(f) = H S_Q(f) H^*,   Cov(eta) = int_0^inf Re S_eta(f) df            (one-sided, per Hz)

and a deck displacement r(x) = sum_i phi_i(x) eta_i (phi = U, Theta or R) has the spectrum
phi(x) S_eta phi(x)^T and the variance phi(x) Cov phi(x)^T.  The integral is the trapezoidal rule on an
even grid f = 0 ... f_max (:func:`frequency_grid`); on a resonance peak of half-width zeta f the error of
that rule falls like exp(-2 pi zeta f / df), so a grid much finer than the narrowest peak is exact to
round-off.  ``resolution_change`` is the check: the change of the span-integrated variances when every
other point is dropped.

Where the aerodynamic model is a table (the CFD's derivatives), a reduced frequency Omega = w B / V outside
its range takes the FRFs at the nearest end of the table (:class:`HeldAerodynamics`): held, not
extrapolated (quasi-steady lateral terms that complete a table are closed forms, taken as they are).  For a
streamlined deck this underestimates the aerodynamic damping at Omega above the table (it grows about like
Omega), so the response there errs on the large side; the stage reports at which speeds a mode's natural
frequency lies outside.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from bridge.buffeting.admittance import Admittance
from bridge.buffeting.loads import DeckModes, SpanIntegrals, load_shapes, modal_load_spectra
from bridge.buffeting.wind import Turbulence
from bridge.errors import InputError, check_range
from bridge.flutter.aerodynamics import QuasiSteady, WithLateral
from bridge.flutter.determinant import dimensional_matrix
from bridge.flutter.modal import ModalModel

__all__ = ["HeldAerodynamics", "BuffetingResponse", "frequency_grid", "buffeting_response", "DOFS"]

DOFS = ("vertical", "torsional", "lateral")


class HeldAerodynamics:
    """An aerodynamic model (bridge.flutter.aerodynamics.AerodynamicModel) used at every reduced frequency:
    inside its Omega range as it is, outside at the nearest end of it (the FRFs held)."""

    def __init__(self, base):
        self.base = base
        self.name = base.name
        self.provides = getattr(base, "provides", ())
        self.covered = tuple(float(v) for v in base.omega_range)

    @property
    def omega_range(self) -> tuple[float, float]:
        return (0.0, np.inf)

    @property
    def speed_range(self) -> tuple[float, float]:
        return self.base.speed_range

    def frf(self, omega, speed):
        return self.base.frf(np.clip(np.asarray(omega, dtype=np.float64), *self.covered), speed)

    @classmethod
    def around(cls, aero):
        """``aero`` held outside its range; a table completed by quasi-steady lateral terms (WithLateral) has
        only the table held, the closed-form lateral terms taken at every Omega."""
        if isinstance(aero, WithLateral):
            return WithLateral(cls(aero.base), aero.lateral)
        return cls(aero)


def frequency_grid(max_frequency_hz: float, steps: int) -> np.ndarray:
    """f = 0, df, ..., max_frequency_hz: ``steps`` points, one more if ``steps`` is even (an odd count lets
    every other point make a grid with the same ends: the resolution check)."""
    check_range("buffeting.max_frequency_hz", max_frequency_hz, low=0.0, low_open=True)
    n = int(steps) + (1 - int(steps) % 2)
    return np.linspace(0.0, float(max_frequency_hz), n)


@dataclass(frozen=True)
class BuffetingResponse:
    """The response at each mean wind speed.  ``modal_covariance`` (n_V, N, N) Cov(eta) in the modal
    coordinates of ``labels``; ``midspan_spectra`` (n_V, 3, n_f) one-sided PSD per Hz at mid-span of the
    vertical [m^2/Hz], torsional [rad^2/Hz] and lateral [m^2/Hz] displacement (``DOFS``); ``rms_along_span``
    (n_V, 3, n_z) RMS at the deck nodes ``z_m``; ``rms_midspan`` (n_V, 3); ``resolution_change`` (n_V,)
    the largest relative change of a span-integrated variance on the grid of every other frequency."""

    labels: tuple[str, ...]
    speeds_m_s: np.ndarray
    frequencies_hz: np.ndarray
    z_m: np.ndarray
    mid_span_z_m: float
    modal_covariance: np.ndarray
    midspan_spectra: np.ndarray
    rms_along_span: np.ndarray
    rms_midspan: np.ndarray
    resolution_change: np.ndarray


def _trapezoid(n: int, step: float) -> np.ndarray:
    w = np.full(n, step)
    w[[0, -1]] *= 0.5
    return w


def buffeting_response(model: ModalModel, modes: DeckModes, aero, air_density: float, coefficients: QuasiSteady,
                       turbulence: Turbulence, admittance: Admittance, speeds_m_s, frequencies_hz: np.ndarray,
                       self_excited: bool = True, say: Callable[[str], None] | None = None,
                       chunk: int = 1024) -> BuffetingResponse:
    """The buffeting response of ``model`` (shapes ``modes``, same labels) at each speed (module docstring).
    ``aero`` gives the self-excited forces (through :meth:`HeldAerodynamics.around`); ``frequencies_hz`` an
    even grid from 0 (:func:`frequency_grid`)."""
    if tuple(modes.labels) != tuple(model.labels):
        raise InputError("buffeting.modes", modes.labels, f"shapes of the modal model's modes {model.labels}")
    f = np.asarray(frequencies_hz, dtype=np.float64)
    df = f[1] - f[0]
    if f[0] != 0.0 or f.size < 3 or f.size % 2 == 0 or not np.allclose(np.diff(f), df, rtol=1e-9, atol=0.0):
        raise InputError("buffeting.frequencies_hz", f.size, "an even grid from 0 with an odd number (>= 3) of points")
    speeds = np.asarray(speeds_m_s, dtype=np.float64)
    for v in speeds:
        check_range("buffeting.speed_m_s", float(v), low=0.0, low_open=True)
    B = model.deck_width_m
    held = HeldAerodynamics.around(aero)
    rho_se = air_density if self_excited else 0.0        # A_a = 0: the structure alone
    psi_u, psi_w = load_shapes(modes, coefficients, B)
    integrals = (SpanIntegrals(modes.z_m, psi_u, turbulence.decay_u * f[-1] / speeds.min()),
                 SpanIntegrals(modes.z_m, psi_w, turbulence.decay_w * f[-1] / speeds.min()))
    decays = (turbulence.decay_u, turbulence.decay_w)
    shapes = modes.stacked()                                               # (3, N, n_z)
    mid = modes.at(modes.mid_span_z_m)                                     # (3, N)
    span = np.einsum("kin,n,kjn->kij", shapes, modes.weights, shapes)      # int phi_i phi_j dx per DOF
    weights, half = _trapezoid(f.size, df), np.zeros(f.size)
    half[::2] = _trapezoid((f.size + 1) // 2, 2.0 * df)
    n, nv = model.n_modes, speeds.size
    cov = np.zeros((nv, n, n))
    spectra = np.zeros((nv, 3, f.size))
    change = np.zeros(nv)
    for iv, V in enumerate(speeds):
        if say is not None:
            say(f"buffeting: V = {V:.1f} m/s ({iv + 1}/{nv}), {n} modes, {f.size} frequencies")
        su, sw = turbulence.spectra(f, V)
        chi2 = admittance.squared_at(f * B / V)
        coarse = np.zeros((n, n))
        for s in range(0, f.size, chunk):
            sl = slice(s, s + chunk)
            SQ = modal_load_spectra(f[sl], V, air_density, B, (su[sl], sw[sl]), chi2[sl], integrals, decays)
            H = np.linalg.inv(dimensional_matrix(model, held, rho_se, 2.0 * np.pi * f[sl], V))
            S = np.ascontiguousarray((H @ SQ @ np.conj(np.swapaxes(H, -1, -2))).real)   # Re S_eta
            cov[iv] += (weights[sl] @ S.reshape(S.shape[0], -1)).reshape(n, n)
            coarse += (half[sl] @ S.reshape(S.shape[0], -1)).reshape(n, n)
            spectra[iv, :, sl] = np.einsum("ki,fik->kf", mid, S @ mid.T)
        total, rough = np.einsum("kij,ij->k", span, cov[iv]), np.einsum("kij,ij->k", span, coarse)
        ok = total > 0.0
        change[iv] = float(np.max(np.abs(rough[ok] - total[ok]) / total[ok])) if ok.any() else 0.0
    var_span = np.einsum("kin,vij,kjn->vkn", shapes, cov, shapes)
    var_mid = np.einsum("ki,vij,kj->vk", mid, cov, mid)
    return BuffetingResponse(labels=tuple(model.labels), speeds_m_s=speeds, frequencies_hz=f, z_m=modes.z_m,
                             mid_span_z_m=modes.mid_span_z_m, modal_covariance=cov, midspan_spectra=spectra,
                             rms_along_span=np.sqrt(np.maximum(var_span, 0.0)),
                             rms_midspan=np.sqrt(np.maximum(var_mid, 0.0)), resolution_change=change)
