"""Turbulent wind along the deck: one-point spectra of the along-wind (u) and vertical (w) components and
their spanwise coherence.

The mean wind V blows across the deck, horizontally and normal to the span; u(x, t) (positive downwind) and
w(x, t) (positive up) are stationary Gaussian fluctuations, uncorrelated with each other (the u-w co-spectrum
is left out, as is usual for bridge decks: Strommen 2010, sec. 3.3), with standard deviations
sigma_u = I_u V and sigma_w = I_w V.  Spectra are ONE-SIDED and per HERTZ: the variance is
int_0^inf S(f) df.  With the reduced frequency fhat = f L / V (L the component's integral length scale):

* Kaimal type (Kaimal, Wyngaard, Izumi and Cote 1972, QJRMS 98: 563-589, in the normalised form of
  EN 1991-1-4 Annex B.1 and of Strommen, *Theory of Bridge Aerodynamics*, 2nd ed. 2010, sec. 3.2):
      f S(f) / sigma^2 = A fhat / (1 + 1.5 A fhat)^(5/3),   A_u = 6.8, A_w = 9.4,
  which integrates to sigma^2 exactly and gives S(0) = sigma^2 A L / V.
* von Karman (von Karman 1948, PNAS 34: 530-539; ESDU 85020; Simiu and Scanlan 1996, sec. 2.3):
      f S_u / sigma_u^2 = 4 fhat / (1 + 70.8 fhat^2)^(5/6)
      f S_w / sigma_w^2 = 4 fhat (1 + 755.2 fhat^2) / (1 + 283.2 fhat^2)^(11/6)
  (S(0) = 4 sigma^2 L / V: L is the integral length scale; the integrals are sigma^2 to 1e-4).

Spanwise coherence (Davenport 1961, QJRMS 87: 194-211; Davenport 1962, Proc. ICE 23: 389-408): the
cross-spectrum of a component at two deck points a distance dx apart is

      S(dx, f) = S(f) exp(-C f |dx| / V)

with a decay coefficient C per component (the root-coherence, real: no phase).

Defaults (``Turbulence``) for a deck some 70 m above open water: I_u = 0.11 (EN 1991-1-4 Eq 4.7,
I_v = 1 / ln(z / z_0) = 0.113 at z = 70 m, z_0 = 0.01 m), I_w = I_u / 2, L_u = 180 m (EN 1991-1-4
Annex B.1, L(z) = 300 (z / 200)^0.44 = 189 m; N400 (Statens vegvesen Handbook N400 Bruprosjektering,
2015) 100 (z / 10)^0.3 = 179 m), L_w = L_u / 12 (N400; Strommen 2010, sec. 3.2), C_u = 10, C_w = 6.5 (N400;
as in the examples of the wawi package).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bridge.errors import InputError, check_range

__all__ = ["SPECTRA", "Turbulence", "kaimal_spectrum", "von_karman_spectrum", "davenport_coherence",
           "KAIMAL_A_U", "KAIMAL_A_W"]

SPECTRA = ("kaimal", "von_karman")
KAIMAL_A_U, KAIMAL_A_W = 6.8, 9.4


def kaimal_spectrum(f: np.ndarray, sigma: float, length_scale_m: float, speed_m_s: float, A: float) -> np.ndarray:
    """One-sided Kaimal-type spectrum per Hz, S(f) = sigma^2 (A L / V) / (1 + 1.5 A f L / V)^(5/3)."""
    fhat = np.asarray(f, dtype=np.float64) * length_scale_m / speed_m_s
    return sigma**2 * (A * length_scale_m / speed_m_s) / (1.0 + 1.5 * A * fhat) ** (5.0 / 3.0)


def von_karman_spectrum(f: np.ndarray, sigma: float, length_scale_m: float, speed_m_s: float,
                        component: str) -> np.ndarray:
    """One-sided von Karman spectrum per Hz of ``component`` "u" or "w" (module docstring)."""
    fhat = np.asarray(f, dtype=np.float64) * length_scale_m / speed_m_s
    scale = sigma**2 * 4.0 * length_scale_m / speed_m_s
    if component == "u":
        return scale / (1.0 + 70.8 * fhat**2) ** (5.0 / 6.0)
    if component == "w":
        return scale * (1.0 + 755.2 * fhat**2) / (1.0 + 283.2 * fhat**2) ** (11.0 / 6.0)
    raise ValueError(f"component must be 'u' or 'w', not {component!r}")


def davenport_coherence(separation_m: np.ndarray, f: np.ndarray, speed_m_s: float, decay: float) -> np.ndarray:
    """Davenport's root-coherence exp(-C f |dx| / V) (broadcast over ``separation_m`` and ``f``)."""
    return np.exp(-decay * np.abs(separation_m) * np.asarray(f, dtype=np.float64) / speed_m_s)


@dataclass(frozen=True)
class Turbulence:
    """The turbulence of the ``[buffeting]`` table: spectrum type, intensities, integral length scales and
    Davenport decay coefficients of u and w (defaults and sources in the module docstring; the w values
    default to I_u / 2 and L_u / 12 when not given)."""

    spectrum: str = "kaimal"
    intensity_u: float = 0.11
    intensity_w: float | None = None
    length_scale_u_m: float = 180.0
    length_scale_w_m: float | None = None
    decay_u: float = 10.0
    decay_w: float = 6.5

    def __post_init__(self) -> None:
        if self.spectrum not in SPECTRA:
            raise InputError("buffeting.spectrum", self.spectrum, f"one of {', '.join(SPECTRA)}")
        check_range("buffeting.turbulence_intensity_u", self.intensity_u, low=0.0, high=1.0, low_open=True)
        check_range("buffeting.length_scale_u_m", self.length_scale_u_m, low=0.0, low_open=True)
        if self.intensity_w is not None:
            check_range("buffeting.turbulence_intensity_w", self.intensity_w, low=0.0, high=1.0)
        if self.length_scale_w_m is not None:
            check_range("buffeting.length_scale_w_m", self.length_scale_w_m, low=0.0, low_open=True)
        check_range("buffeting.coherence_decay_u", self.decay_u, low=0.0)
        check_range("buffeting.coherence_decay_w", self.decay_w, low=0.0)

    @property
    def iw(self) -> float:
        """I_w: as given, else I_u / 2."""
        return 0.5 * self.intensity_u if self.intensity_w is None else float(self.intensity_w)

    @property
    def lw(self) -> float:
        """L_w [m]: as given, else L_u / 12."""
        return self.length_scale_u_m / 12.0 if self.length_scale_w_m is None else float(self.length_scale_w_m)

    def spectra(self, f: np.ndarray, speed_m_s: float) -> tuple[np.ndarray, np.ndarray]:
        """(S_u, S_w) at frequencies ``f`` [Hz] and mean speed V: one-sided, per Hz, in (m/s)^2/Hz."""
        su, sw = self.intensity_u * speed_m_s, self.iw * speed_m_s
        if self.spectrum == "kaimal":
            return (kaimal_spectrum(f, su, self.length_scale_u_m, speed_m_s, KAIMAL_A_U),
                    kaimal_spectrum(f, sw, self.lw, speed_m_s, KAIMAL_A_W))
        if self.spectrum == "von_karman":
            return (von_karman_spectrum(f, su, self.length_scale_u_m, speed_m_s, "u"),
                    von_karman_spectrum(f, sw, self.lw, speed_m_s, "w"))
        raise InputError("buffeting.spectrum", self.spectrum, f"one of {', '.join(SPECTRA)}")
