"""Frequency response functions of a deck section from the force time series of forced-motion runs.

A forced-motion run (thesis 5.2-5.3) moves the section harmonically in one degree of freedom and
records the loads per unit length.  This module turns those records into

* complex amplitudes, by a least-squares harmonic fit over whole periods with an uncertainty from the
  period-to-period scatter (:func:`harmonic_fit`), or as the thesis does, Eq 5.9-5.14
  (:func:`thesis_extraction`, with the sign of the phase kept);
* the dimensional FRFs of Eq 5.1-5.8 (:func:`rate_frf` H_xdot = x_0 / xdot_0, :func:`displacement_frf`
  H_x = i w H_xdot, the corrected Eq 5.4), the normalised h_xy of Eq 4.37 (:func:`normalised_frf`) and
  Scanlan's derivatives (:func:`bridge.flutter.derivatives.derivatives_from_frf`), per run
  (:func:`forced_motion_response` -> :class:`FrequencyResponse`);
* the table the flutter stage reads (:func:`frf_table`, :func:`speed_independent_table` ->
  :class:`bridge.flutter.tables.FRFTable`).

Conventions (those of :mod:`bridge.flutter.derivatives`): harmonic quantities x(t) = Re(X e^{i w t})
in the caller's time t; degrees of freedom ``heave`` (u, up), ``pitch`` (theta, nose-up), ``sway``
(r, downwind); loads per unit length ``lift`` (p, up), ``drag`` (q, downwind), ``moment`` (m,
nose-up).  Eq 4.37: p = (1/2) rho V^2 [h_pu u + B h_ptheta theta], m = (1/2) rho V^2 B [h_mu u +
B h_mtheta theta], q = (1/2) rho V^2 [h_qu u + h_qr r + B h_qtheta theta], Omega = w B / V.  Any
consistent units (the CFD's B = V = rho = 1 included).

Assumptions: the loads are linear in the motion (small amplitudes, thesis 5.3) and the record handed
in is past the transient; only whole periods of it are used.  Sources: the thesis, sections 5.2-5.3
and its errata (docs/thesis_errata.md); docs/aero.md derives the formulas and the uncertainty.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from bridge.errors import InputError, check_range
from bridge.flutter.derivatives import (
    FRF,
    FRF_NAMES,
    LATERAL,
    VERTICAL_TORSIONAL,
    FlutterDerivatives,
    derivatives_from_frf,
)
from bridge.flutter.tables import FRFTable

__all__ = ["HarmonicFit", "harmonic_fit", "ThesisExtraction", "thesis_extraction", "rate_frf",
           "displacement_frf", "normalised_frf", "FRF_OF_RUN", "DOFS", "LOADS", "FrequencyResponse",
           "forced_motion_response", "distortion", "FRFGrid", "tabulate", "frf_table", "speed_independent_table"]

DOFS = ("heave", "pitch", "sway")
LOADS = ("lift", "drag", "moment")
# (load, forced degree of freedom) -> the h_xy it measures
FRF_OF_RUN: dict[tuple[str, str], str] = {
    ("lift", "heave"): "h_pu", ("lift", "pitch"): "h_ptheta", ("lift", "sway"): "h_pr",
    ("drag", "heave"): "h_qu", ("drag", "pitch"): "h_qtheta", ("drag", "sway"): "h_qr",
    ("moment", "heave"): "h_mu", ("moment", "pitch"): "h_mtheta", ("moment", "sway"): "h_mr"}
# Eq 4.37: the load is normalised by (1/2) rho V^2 B^n, n = [load is a moment] + [motion is a rotation]
_B_POWER_LOAD = {"lift": 0, "drag": 0, "moment": 1}
_B_POWER_DOF = {"heave": 0, "pitch": 1, "sway": 0}
_INTEGER_RTOL = 1e-6      # how close w_k / w_0 must be to an integer


# ---------------------------------------------------------------------------------------------------
# Windows and quadrature over whole periods


def _series(t, signal, key: str) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(signal, dtype=np.float64)
    if t.ndim != 1 or t.shape != y.shape or t.size < 4:
        raise InputError(key, (t.shape, y.shape), "t and the signal: 1-D, the same length, >= 4 samples")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
        raise InputError(key, "non-finite sample", "finite t and signal")
    if np.any(np.diff(t) <= 0.0):
        raise InputError(f"{key}.t", "not strictly increasing", "strictly increasing sample times")
    return t, y


def _whole_periods(t: np.ndarray, period: float, periods: int | None, key: str) -> tuple[float, float, int]:
    """(t_start, t_end, n): the last n whole periods ending at the last sample (all of them by default);
    the partial period at the start of the record is discarded."""
    available = int(math.floor((t[-1] - t[0]) / period + 1e-9))
    if available < 1:
        raise InputError(f"{key}.t", float(t[-1] - t[0]), f"a window of at least one period ({period:g})")
    if periods is None:
        n = available
    elif isinstance(periods, bool) or not isinstance(periods, (int, np.integer)) or not 1 <= periods <= available:
        raise InputError(f"{key}.periods", periods, f"a whole number from 1 to {available} (periods in the window)")
    else:
        n = int(periods)
    t_end = float(t[-1])
    return max(t_end - n * period, float(t[0])), t_end, n


def _quadrature_weights(t: np.ndarray, a: float, b: float) -> np.ndarray:
    """Weight of each sample in int_a^b f dt: the length of its cell (bounded by the midpoints to its
    neighbours) inside [a, b].  Constants are integrated exactly, whatever the time steps."""
    mid = 0.5 * (t[1:] + t[:-1])
    lo = np.concatenate(([-np.inf], mid))
    hi = np.concatenate((mid, [np.inf]))
    return np.clip(np.minimum(hi, b) - np.maximum(lo, a), 0.0, None)


def _integral(t: np.ndarray, f: np.ndarray, a: float, b: float) -> float:
    """Trapezoidal int_a^b f dt over the samples, f linearly interpolated at a and b."""
    inside = (t > a) & (t < b)
    tt = np.concatenate(([a], t[inside], [b]))
    ff = np.concatenate(([np.interp(a, t, f)], f[inside], [np.interp(b, t, f)]))
    return float(np.sum(0.5 * (ff[1:] + ff[:-1]) * np.diff(tt)))


def _weighted_lstsq(design: np.ndarray, y: np.ndarray, w: np.ndarray, key: str) -> np.ndarray:
    use = w > 0.0
    sw = np.sqrt(w[use])
    coef, _, rank, _ = np.linalg.lstsq(design[use] * sw[:, None], y[use] * sw, rcond=None)
    if rank < design.shape[1] or use.sum() <= design.shape[1]:
        raise InputError(key, int(use.sum()), f"more than {design.shape[1]} samples per period to fit "
                         f"{design.shape[1]} coefficients")
    return coef


def _harmonics(t: np.ndarray, omegas: np.ndarray) -> np.ndarray:
    wt = np.outer(t, omegas)
    return np.concatenate((np.cos(wt), np.sin(wt)), axis=1)


def _complex(coef: np.ndarray, k: int) -> np.ndarray:
    """a cos(wt) + b sin(wt) = Re((a - i b) e^{i w t})."""
    return coef[..., :k] - 1j * coef[..., k:2 * k]


def _standard_error(samples: np.ndarray) -> np.ndarray:
    """Standard error of the mean over axis 0, real and imaginary parts separately (complex result);
    NaN with a single sample."""
    n = samples.shape[0]
    if n < 2:
        return np.full(samples.shape[1:], np.nan + 1j * np.nan)
    return (np.std(samples.real, axis=0, ddof=1) + 1j * np.std(samples.imag, axis=0, ddof=1)) / np.sqrt(n)


# ---------------------------------------------------------------------------------------------------
# Harmonic fit


@dataclass(frozen=True, eq=False)
class HarmonicFit:
    """Result of :func:`harmonic_fit`.

    ``amplitudes`` (K,) complex X_k, signal ~ mean + drift + sum_k Re(X_k e^{i w_k t});
    ``stderr`` (K,) complex: its real (imaginary) part is the standard error of Re X_k (Im X_k), from
    the scatter of ``per_period`` (n, K), the fits of each whole period (NaN when n = 1);
    ``periods`` n, ``period`` T_0 = 2 pi / w_0, ``window`` (t_start, t_end) = n whole periods;
    ``mean`` c_0 and ``drift_rate`` c_1 (signal units per time unit; 0 without ``drift`` or with one period);
    ``residual_rms`` of the signal about the fitted model over the window.
    """

    omegas: np.ndarray
    amplitudes: np.ndarray
    stderr: np.ndarray
    per_period: np.ndarray
    periods: int
    period: float
    window: tuple[float, float]
    mean: float
    drift_rate: float
    residual_rms: float


def harmonic_fit(t: np.ndarray, signal: np.ndarray, omegas: float | Iterable[float], periods: int | None = None,
                 fundamental: float | None = None, drift: bool = True) -> HarmonicFit:
    """Least-squares fit of signal(t) - c_1 (t - t_mid) = c_0 + sum_k (a_k cos w_k t + b_k sin w_k t).

    ``t``: sample times, strictly increasing, any spacing (the CFD's time step varies); ``omegas``:
    angular frequencies w_k > 0, each a whole multiple of ``fundamental`` w_0 (default the lowest w_k);
    the window is cut into whole periods T_0 = 2 pi / w_0 ending at the last sample, and the last
    ``periods`` of them are used (default all; the partial period at the start is discarded: hand in the
    record after the transient).  ``drift``: remove a linear drift c_1 first, the line through the means
    of the whole periods (a slow drift of the mean biases the fit over whole periods by c_1 T / pi in the
    sine part; see docs/aero.md); it needs two periods, with one none is removed.  (The drift is not a
    column of the least-squares fit: over few periods t - t_mid is strongly correlated with sin w_0 t -
    0.78 over one period - and a drift column turned the step-to-step noise of a CFD record into a bias of
    17 % on one period and 1 % on three.)

    Samples are weighted by their share of the window's length (:func:`_quadrature_weights`), so the fit
    approximates the continuous least-squares projection over whole periods, on which the model's terms
    are orthogonal to every other harmonic of w_0: unmodelled content (higher harmonics, vortex
    shedding at a multiple of w_0) does not leak into X_k because the time steps are uneven.

    Uncertainty: each whole period j is fitted on its own (constant and harmonics, after removing the
    drift of the whole-window fit), giving X_k^(j); the standard error of X_k is that of their mean,
    std(X^(j)) / sqrt(n), for the real and the imaginary part (the fit of the window is the mean of
    the period fits up to the drift term and the quadrature).  Periods are taken as independent: a
    disturbance correlated over several periods is under-reported.
    """
    key = "harmonic_fit"
    t, y = _series(t, signal, key)
    w = np.atleast_1d(np.asarray(omegas, dtype=np.float64))
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0.0) or np.unique(w).size != w.size:
        raise InputError(f"{key}.omegas", w.tolist(), "distinct finite angular frequencies > 0")
    w0 = float(np.min(w)) if fundamental is None else check_range(f"{key}.fundamental", fundamental, 0.0,
                                                                   low_open=True)
    ratio = w / w0
    if np.any(np.abs(ratio - np.round(ratio)) > _INTEGER_RTOL * ratio) or np.any(np.round(ratio) < 1):
        raise InputError(f"{key}.omegas", w.tolist(), f"whole multiples of the fundamental {w0:g} (pass "
                         "fundamental= the common angular frequency), so that its periods hold whole periods of all")
    T0 = 2.0 * math.pi / w0
    t_start, t_end, n = _whole_periods(t, T0, periods, key)
    K = w.size

    # the drift: a line through the means of the whole periods, each the constant of a fit of that period
    # alone (every harmonic of w_0 averages out over a period, so a linear drift is found whatever else the
    # signal holds, and a signal without drift gets none); with one period, none
    weights = _quadrature_weights(t, t_start, t_end)
    t_mid = 0.5 * (t_start + t_end)
    design_p = np.concatenate((np.ones((t.size, 1)), _harmonics(t, w)), axis=1)
    period_weights = [_quadrature_weights(t, a, min(a + T0, t_end)) for a in t_start + np.arange(n) * T0]
    drift_rate = 0.0
    if drift and n >= 2:
        centres = t_start + (np.arange(n) + 0.5) * T0
        means = [_weighted_lstsq(design_p, y, wj, key)[0] for wj in period_weights]
        drift_rate = float(np.polyfit(centres - t_mid, means, 1)[0])
    y_d = y - drift_rate * (t - t_mid)

    # whole window, the drift removed
    coef = _weighted_lstsq(design_p, y_d, weights, key)
    amplitudes = _complex(coef[1:], K)
    residual = y_d - design_p @ coef
    residual_rms = float(np.sqrt(np.sum(weights * residual**2) / np.sum(weights)))

    # each whole period on its own, the window's drift removed
    per_period = np.empty((n, K), dtype=np.complex128)
    for j, wj in enumerate(period_weights):
        per_period[j] = _complex(_weighted_lstsq(design_p, y_d, wj, key)[1:], K)

    return HarmonicFit(omegas=w, amplitudes=amplitudes, stderr=_standard_error(per_period),
                       per_period=per_period, periods=n, period=T0, window=(t_start, t_end),
                       mean=float(coef[0]), drift_rate=drift_rate, residual_rms=residual_rms)


def distortion(t: np.ndarray, signal: np.ndarray, omegas: Iterable[float], fundamental: float) -> float:
    """How far a multi-frequency run's load is from a linear response: the rms amplitude of ``signal`` at the
    multiples of ``fundamental`` up to twice the highest of ``omegas`` that the motion does not contain, over
    the rms amplitude at ``omegas`` (the same window and fit as :func:`harmonic_fit`).

    A linear section answers only at the frequencies it is moved at (ratio ~ 0, the noise).  Products of the
    motion's sines (a quadratic or cubic response, or shedding locked to the motion) land on sums and
    differences of them: on the lines counted here and, since the set is made of whole multiples of one
    frequency, also on the moved lines themselves, where they bias the FRFs by about as much."""
    w = np.sort(np.asarray(list(omegas), dtype=np.float64))
    m = np.round(w / fundamental).astype(int)
    lines = np.arange(1, 2 * int(m.max()) + 1)
    fit = harmonic_fit(t, signal, fundamental * lines, fundamental=fundamental)
    moved = np.isin(lines, m)
    a = np.abs(fit.amplitudes)
    return float(np.sqrt(np.mean(a[~moved] ** 2)) / max(np.sqrt(np.mean(a[moved] ** 2)), 1e-300))


# ---------------------------------------------------------------------------------------------------
# The thesis's extraction, Eq 5.9-5.14


@dataclass(frozen=True)
class ThesisExtraction:
    """Result of :func:`thesis_extraction`: the rate FRF H_xdot of Eq 5.14 for one load.

    ``amplitude`` |H| = sqrt(2) rms of the normalised, mean-free load (Eq 5.13); ``phase_thesis`` the
    thesis's arccos value (Eq 5.12), in [0, pi]: UNSIGNED; ``phase`` the signed phase lag in (-pi, pi],
    from the cosine and the sine integrals; ``frf_thesis`` and ``frf`` = |H| (cos phi - i sin phi)
    with each (Eq 5.14); ``mean`` the removed mean load (Eq 5.10); ``rate_amplitude`` the normalising
    xdot_0 (Eq 5.9); ``periods`` the whole periods integrated over.
    """

    amplitude: float
    phase_thesis: float
    phase: float
    frf_thesis: complex
    frf: complex
    mean: float
    rate_amplitude: float
    periods: int


def thesis_extraction(t: np.ndarray, load: np.ndarray, motion_rate: np.ndarray, omega: float,
                      norm: float | None = None, periods: int | None = None) -> ThesisExtraction:
    """The rate FRF H_xdot = |H| e^{-i phi} of one load as the thesis extracts it (Eq 5.9-5.14),
    with the sign of the phase kept.

    Over the last ``periods`` whole periods T = 2 pi / ``omega`` of the record (default all; trapezoidal
    integrals, any time steps):
        Pi(t) = (load - mean) / xdot_0                         (Eq 5.9-5.10; ``norm`` = xdot_0)
        |H| = sqrt(2) sqrt(<Pi^2>)                             (Eq 5.13)
        cos phi = (2/T) int Pi cos(w t - psi) dt / |H|         (Eq 5.11-5.12)
        H = |H| (cos phi - i sin phi)                          (Eq 5.14)
    ``motion_rate`` is the rate xdot(t) of the forced motion: its phase psi is the reference (the thesis
    starts the motion as xdot_0 cos w t, psi = 0, and integrates against cos w t); ``norm`` defaults to
    its amplitude.

    The sign: cos phi does not tell phi from -phi, so the thesis's arccos (``phase_thesis``, in [0, pi])
    loses the sign of the phase and, for a load that LEADS the motion (phi < 0), gives the complex
    conjugate of H.  The sine integral (2/T) int Pi sin(w t - psi) dt = |H| sin phi is computed as well
    and ``phase`` = atan2 of the two (``frf`` uses it).  Both are returned.  Noise and harmonics other
    than w inflate |H| (the rms holds their power; :func:`harmonic_fit` does not), and with it bias
    the arccos value towards pi/2; the atan2 phase is not biased so.
    """
    key = "thesis_extraction"
    t, p = _series(t, load, key)
    _, rate = _series(t, motion_rate, f"{key}.motion_rate")
    omega = check_range(f"{key}.omega", omega, 0.0, low_open=True)
    T = 2.0 * math.pi / omega
    a, b, n = _whole_periods(t, T, periods, key)
    length = b - a
    c, s = np.cos(omega * t), np.sin(omega * t)

    def mean(f):
        return _integral(t, f, a, b) / length

    # the motion rate: xdot = A cos(w t - psi), A cos psi = 2 <xdot cos>, A sin psi = 2 <xdot sin>
    rc, rs = 2.0 * mean(rate * c), 2.0 * mean(rate * s)
    psi = math.atan2(rs, rc)
    x0 = math.hypot(rc, rs) if norm is None else check_range(f"{key}.norm", norm, 0.0, low_open=True)
    if x0 == 0.0:
        raise InputError(f"{key}.motion_rate", 0.0, f"a motion with a component at omega = {omega:g}")

    p_mean = mean(p)
    Pi = (p - p_mean) / x0                                          # Eq 5.9
    amplitude = math.sqrt(2.0 * mean(Pi**2))                        # Eq 5.13
    cos_int = 2.0 * mean(Pi * np.cos(omega * t - psi))              # Eq 5.11-5.12: |H| cos phi
    sin_int = 2.0 * mean(Pi * np.sin(omega * t - psi))              # the sine part: |H| sin phi
    phase_thesis = math.acos(min(1.0, max(-1.0, cos_int / amplitude))) if amplitude > 0.0 else 0.0
    phase = math.atan2(sin_int, cos_int)
    return ThesisExtraction(amplitude=amplitude, phase_thesis=phase_thesis, phase=phase,
                            frf_thesis=complex(amplitude * np.exp(-1j * phase_thesis)),     # Eq 5.14
                            frf=complex(amplitude * np.exp(-1j * phase)), mean=p_mean,
                            rate_amplitude=x0, periods=n)


# ---------------------------------------------------------------------------------------------------
# Conversions, Eq 5.3-5.8 and 4.37


def rate_frf(load_amplitude, motion_amplitude, omega):
    """Eq 5.3: H_xdot = p_0 / xdot_0 with xdot_0 = i w x_0, from the complex amplitudes of the load
    p_0 and of the motion's displacement x_0 (u_0 or theta_0) at angular frequency w."""
    return np.asarray(load_amplitude) / (1j * np.asarray(omega) * np.asarray(motion_amplitude))


def displacement_frf(rate, omega):
    """Eq 5.4 as corrected (docs/thesis_errata.md): H_x = i w H_xdot; the thesis prints H_pu = i w H_pu.
    Hence |H_x| = w |H_xdot| and phi_x = phi_xdot - pi/2 (Eq 5.6-5.8)."""
    return 1j * np.asarray(omega) * np.asarray(rate)


def normalised_frf(dimensional, load: str, dof: str, speed_m_s, deck_width_m: float,
                   air_density_kg_m3: float = 1.225):
    """Eq 4.37: h_xy = H_xy / ((1/2) rho V^2 B^n), n = 1 for a moment plus 1 for a rotation (h_pu =
    H_pu / q, h_ptheta = h_mu = H / (q B), h_mtheta = H / (q B^2), q = rho V^2 / 2); the lateral ones
    (drag, sway) likewise."""
    if load not in _B_POWER_LOAD:
        raise InputError("frequency_response.load", load, f"one of {', '.join(LOADS)}")
    if dof not in _B_POWER_DOF:
        raise InputError("frequency_response.dof", dof, f"one of {', '.join(DOFS)}")
    n = _B_POWER_LOAD[load] + _B_POWER_DOF[dof]
    q = 0.5 * air_density_kg_m3 * np.asarray(speed_m_s, dtype=np.float64) ** 2
    return np.asarray(dimensional) / (q * deck_width_m**n)


# ---------------------------------------------------------------------------------------------------
# One run -> FrequencyResponse


@dataclass(frozen=True)
class FrequencyResponse:
    """The normalised FRFs one forced-motion run measured at one reduced frequency.

    ``frf``: h_xy (Eq 4.37) in ``provides`` (the loads recorded times the forced ``dof``: a heave run
    with lift and moment gives h_pu, h_mu), zero elsewhere; ``stderr``: their standard errors, real
    and imaginary parts separately (:func:`harmonic_fit`), zero elsewhere; ``periods``: the whole
    periods used.  ``deck_width_m`` B and ``air_density_kg_m3`` rho are those of the normalisation.
    """

    reduced_frequency: float
    speed_m_s: float
    dof: str
    frf: FRF
    stderr: FRF
    provides: tuple[str, ...]
    periods: int
    deck_width_m: float
    air_density_kg_m3: float = 1.225

    def __post_init__(self) -> None:
        key = "frequency_response"
        for name in ("reduced_frequency", "speed_m_s", "deck_width_m", "air_density_kg_m3"):
            object.__setattr__(self, name, check_range(f"{key}.{name}", getattr(self, name), 0.0, low_open=True))
        if self.dof not in DOFS:
            raise InputError(f"{key}.dof", self.dof, f"one of {', '.join(DOFS)}")
        measurable = {FRF_OF_RUN[load, self.dof] for load in LOADS}
        provides = tuple(self.provides)
        if not provides or any(n not in measurable for n in provides):
            raise InputError(f"{key}.provides", provides, f"some of {', '.join(sorted(measurable))} "
                             f"(what a {self.dof} run measures)")
        object.__setattr__(self, "provides", tuple(n for n in FRF_NAMES if n in provides))
        if isinstance(self.periods, bool) or not isinstance(self.periods, (int, np.integer)) or self.periods < 1:
            raise InputError(f"{key}.periods", self.periods, "a whole number >= 1")

    @property
    def angular_frequency(self) -> float:
        """w = Omega V / B (Eq 4.38)."""
        return self.reduced_frequency * self.speed_m_s / self.deck_width_m

    @property
    def derivatives(self) -> FlutterDerivatives:
        """Scanlan's derivatives at K = Omega (those of FRFs not in ``provides`` are zero, not measured)."""
        return derivatives_from_frf(self.reduced_frequency, self.frf)

    @property
    def derivative_stderr(self) -> FlutterDerivatives:
        """Standard errors of :attr:`derivatives`: each derivative is +-Re h / K^2 or +-Im h / K^2."""
        return FlutterDerivatives(*(np.abs(v) for v in derivatives_from_frf(self.reduced_frequency, self.stderr)))

    def dimensional(self) -> dict[str, complex]:
        """H_xy = p_0 / x_0 of Eq 5.3 (units of the inputs), for each FRF in ``provides``."""
        q = 0.5 * self.air_density_kg_m3 * self.speed_m_s**2
        load_of = {v: load for (load, dof), v in FRF_OF_RUN.items() if dof == self.dof}
        return {n: complex(getattr(self.frf, n)) * q
                * self.deck_width_m ** (_B_POWER_LOAD[load_of[n]] + _B_POWER_DOF[self.dof]) for n in self.provides}

    def rate(self) -> dict[str, complex]:
        """H_xdot = p_0 / xdot_0 of Eq 5.3 (the thesis's CFD output, Tables 5.2-5.3): H_xy / (i w)."""
        return {n: H / (1j * self.angular_frequency) for n, H in self.dimensional().items()}


def forced_motion_response(t: np.ndarray, motion: np.ndarray, omegas: float | Iterable[float], *, dof: str,
                           speed_m_s: float, deck_width_m: float, lift: np.ndarray | None = None,
                           moment: np.ndarray | None = None, drag: np.ndarray | None = None,
                           air_density_kg_m3: float = 1.225, periods: int | None = None,
                           fundamental: float | None = None, drift: bool = True) -> tuple[FrequencyResponse, ...]:
    """The FRFs of one forced-motion run, one :class:`FrequencyResponse` per angular frequency in
    ``omegas`` (several for a multi-frequency excitation).

    ``motion``: the forced displacement (u up or r downwind, or theta nose-up) at the times ``t``;
    ``lift``, ``moment``, ``drag``: the loads per unit length recorded (at least one).  Each series is
    fitted by :func:`harmonic_fit` (same window, ``periods``, ``fundamental``, ``drift``); then at each
    w_k: H_xdot = p_0 / (i w x_0) (Eq 5.3), H_x = i w H_xdot (Eq 5.4 corrected), h = H_x / ((1/2) rho
    V^2 B^n) (Eq 4.37), Omega = w B / V.  The standard error of h comes from the same conversion of
    each period's load amplitude (the motion, prescribed, is taken from the whole window).
    """
    key = "forced_motion_response"
    if dof not in DOFS:
        raise InputError(f"{key}.dof", dof, f"one of {', '.join(DOFS)}")
    speed_m_s = check_range(f"{key}.speed_m_s", speed_m_s, 0.0, low_open=True)
    deck_width_m = check_range(f"{key}.deck_width_m", deck_width_m, 0.0, low_open=True)
    air_density_kg_m3 = check_range(f"{key}.air_density_kg_m3", air_density_kg_m3, 0.0, low_open=True)
    loads = {name: series for name, series in (("lift", lift), ("drag", drag), ("moment", moment))
             if series is not None}
    if not loads:
        raise InputError(key, "no load", "at least one of lift, moment, drag")

    def fit(series):
        return harmonic_fit(t, series, omegas, periods=periods, fundamental=fundamental, drift=drift)

    x = fit(motion)
    scale = np.max(np.abs(np.asarray(motion, dtype=np.float64) - x.mean))
    if np.any(np.abs(x.amplitudes) <= 1e-9 * scale) or scale == 0.0:
        raise InputError(f"{key}.motion", np.abs(x.amplitudes).tolist(), "a component at every omega")
    w = x.omegas
    values: dict[str, np.ndarray] = {}
    errors: dict[str, np.ndarray] = {}
    for load, series in loads.items():
        f = fit(series)
        name = FRF_OF_RUN[load, dof]

        def to_h(p0, load=load):
            H = displacement_frf(rate_frf(p0, x.amplitudes, w), w)           # Eq 5.3, 5.4 (corrected)
            return normalised_frf(H, load, dof, speed_m_s, deck_width_m, air_density_kg_m3)  # Eq 4.37

        values[name] = to_h(f.amplitudes)
        errors[name] = _standard_error(to_h(f.per_period))
    zero = FRF(*(0j for _ in FRF_NAMES))
    return tuple(FrequencyResponse(
        reduced_frequency=float(w[k] * deck_width_m / speed_m_s), speed_m_s=speed_m_s, dof=dof,
        frf=zero._replace(**{n: complex(v[k]) for n, v in values.items()}),
        stderr=zero._replace(**{n: complex(e[k]) for n, e in errors.items()}),
        provides=tuple(values), periods=x.periods, deck_width_m=deck_width_m,
        air_density_kg_m3=air_density_kg_m3) for k in range(w.size))


# ---------------------------------------------------------------------------------------------------
# Many runs -> the table of the flutter stage


class FRFGrid(NamedTuple):
    """h_xy on a grid: ``omega`` (n_Omega,) ascending, ``speed`` (n_V,) ascending, ``values`` and
    ``stderr`` FRFs of (n_Omega, n_V) complex arrays, ``provides`` the FRFs measured in every cell."""

    omega: np.ndarray
    speed: np.ndarray
    values: FRF
    stderr: FRF
    provides: tuple[str, ...]


def _axis(values: Iterable[float], rtol: float = 1e-9) -> np.ndarray:
    """The distinct values, ascending; values within ``rtol`` of each other are one."""
    out: list[float] = []
    for v in sorted(values):
        if not out or v - out[-1] > rtol * abs(v):
            out.append(v)
    return np.asarray(out)


def _index(axis: np.ndarray, v: float, rtol: float = 1e-9) -> int:
    return int(np.flatnonzero(np.abs(axis - v) <= rtol * abs(v))[0])


def tabulate(responses: Iterable[FrequencyResponse]) -> FRFGrid:
    """Arrange responses (a heave run and a pitch run at each (Omega, V), typically) on the grid of their
    reduced frequencies and speeds (values within a relative 1e-9 are one).  Each of h_pu, h_ptheta,
    h_mu, h_mtheta must be measured by exactly one response in every cell; a lateral FRF is in the grid
    when every cell has it (measured in some cells only: InputError).  Values at the same Omega and V
    measured twice: InputError (average them first, if that is what is meant)."""
    responses = list(responses)
    if not responses:
        raise InputError("frf_table.responses", 0, "at least one FrequencyResponse")
    omega = _axis(r.reduced_frequency for r in responses)
    speed = _axis(r.speed_m_s for r in responses)
    shape = (omega.size, speed.size)
    values = {n: np.zeros(shape, dtype=np.complex128) for n in FRF_NAMES}
    errors = {n: np.zeros(shape, dtype=np.complex128) for n in FRF_NAMES}
    filled = {n: np.zeros(shape, dtype=bool) for n in FRF_NAMES}
    for r in responses:
        i, j = _index(omega, r.reduced_frequency), _index(speed, r.speed_m_s)
        for n in r.provides:
            if filled[n][i, j]:
                raise InputError(f"frf_table.{n}", (r.reduced_frequency, r.speed_m_s),
                                 "one response per FRF, reduced frequency and speed (it was given twice)")
            values[n][i, j], errors[n][i, j], filled[n][i, j] = getattr(r.frf, n), getattr(r.stderr, n), True
    for n in VERTICAL_TORSIONAL:
        if not filled[n].all():
            i, j = np.argwhere(~filled[n])[0]
            raise InputError(f"frf_table.{n}", (float(omega[i]), float(speed[j])),
                             "measured at every reduced frequency and speed (a heave and a pitch run each)")
    partial = [n for n in LATERAL if filled[n].any() and not filled[n].all()]
    if partial:
        raise InputError("frf_table.lateral", partial, "lateral FRFs measured in every cell or in none")
    provides = VERTICAL_TORSIONAL + tuple(n for n in LATERAL if filled[n].all())
    return FRFGrid(omega, speed, FRF(**values), FRF(**errors), provides)


def frf_table(responses: Iterable[FrequencyResponse], source: str = "cfd") -> FRFTable:
    """The :class:`bridge.flutter.tables.FRFTable` of the responses (:func:`tabulate`): >= 2 reduced
    frequencies and >= 2 speeds.  For runs at one speed, see :func:`speed_independent_table`."""
    grid = tabulate(responses)
    if grid.speed.size < 2:
        raise InputError("frf_table.speed_m_s", grid.speed.tolist(), "runs at >= 2 speeds (for data at one speed "
                         "taken as independent of V, use speed_independent_table)")
    return FRFTable(grid.omega, grid.speed, grid.values, source=source, provides=grid.provides)


def speed_independent_table(responses: Iterable[FrequencyResponse], speed_range_m_s: tuple[float, float],
                            source: str = "cfd") -> FRFTable:
    """An :class:`bridge.flutter.tables.FRFTable` from runs at ONE speed, stated to hold for every V in
    ``speed_range_m_s`` = (V_min, V_max): the column is duplicated at V_min and V_max, so the table is
    constant in V there (and refuses any V outside, as every table does).

    This is an assumption the caller makes, not a result: h_xy are taken to depend on Omega alone
    (Reynolds-number independence, true of potential flow and of sharp-edged sections to first order;
    the thesis's Table 5.3 claims a V dependence, docs/thesis_errata.md).  Runs at several speeds:
    InputError (use :func:`frf_table`)."""
    grid = tabulate(responses)
    if grid.speed.size != 1:
        raise InputError("speed_independent_table.speed_m_s", grid.speed.tolist(),
                         "runs at one speed (with several, use frf_table)")
    lo = check_range("speed_independent_table.speed_range_m_s[0]", speed_range_m_s[0], 0.0, low_open=True)
    hi = check_range("speed_independent_table.speed_range_m_s[1]", speed_range_m_s[1], lo, low_open=True)
    values = FRF(*(np.repeat(v, 2, axis=1) for v in grid.values))
    return FRFTable(grid.omega, np.array([lo, hi]), values, source=source, provides=grid.provides)
