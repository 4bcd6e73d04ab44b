"""Multimode flutter by the p-k method (N modes coupled by the aerodynamic matrix).

Modal equations (Eq 4.9) for all N modes with the aeroelastic modal load of Eq 4.23-4.24:
    M q'' + C q' + K q = A_a(w, V) q,  M = diag(m_i), C = diag(2 m_i zeta_i w_i), K = diag(m_i w_i^2),
    A_a[i, j] = (1/2) rho V^2 L [h_pu uu_ij + B h_ptheta ut_ij + B h_mu ut_ji + B^2 h_mtheta tt_ij
                                 + lateral terms, see bridge.flutter.determinant._aero_bracket].
p-k: for q = Q e^{s t}, A_a is evaluated at the trial frequency w (Omega = w B / V) and split as
A_a = A_R + i A_I ~ A_R + (A_I / w) s, which is exact on the imaginary axis (s = i w).  Then
    [s^2 M + s (C - A_I / w) + (K - A_R)] Q = 0
is a real quadratic eigenvalue problem (state-space form, 2N eigenvalues); for each mode the trial w is
replaced by Im(s) of the tracked eigenvalue until it no longer changes.  Damping ratio
zeta = -Re(s) / |s|, frequency Im(s) / 2 pi.  Flutter: the first V where a damping ratio crosses zero
(refined by Brent's method on zeta(V)); a crossing at zero frequency is static divergence, reported
apart.  At a flutter point s = i w exactly, so with two modes the p-k
critical speed is the determinant method's (Eq 4.29) to the iteration tolerance.
Lateral modes carry no aerodynamic FRF in the thesis's model and are left out, unless asked for
(``lateral=True``, with an aerodynamic model that gives the lateral FRFs).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from bridge.errors import ConvergenceError, InputError
from bridge.flutter.aerodynamics import AerodynamicModel
from bridge.flutter.determinant import _aero_bracket, speed_window
from bridge.flutter.modal import ModalModel

_ROUND_OFF_FREQUENCY = 1e-6   # a p-k frequency below this fraction of the sweep's highest is a real root

__all__ = ["MultimodeResult", "pk_sweep", "aeroelastic_eigenvalues", "static_divergence_speed"]


@dataclass(frozen=True)
class MultimodeResult:
    """Frequencies and damping ratios of every mode against V, and the flutter onset.

    ``speed_m_s`` (n_V,), ``frequency_hz`` and ``damping_ratio`` (n_V, N) in the order of ``labels``.
    ``flutter`` False: no damping ratio of an oscillating mode crossed zero up to ``max_speed_searched_m_s``.
    A crossing where the mode's frequency has gone to zero is static (torsional) divergence, reported in
    ``divergence_speed_m_s`` and not as flutter (the moment about mid-chord of a plate diverges at
    (1/2) rho V^2 B^2 (pi/2) = J w_T^2, Eq 4.37 with h_mtheta(0) = pi/2).
    """

    labels: tuple[str, ...]
    speed_m_s: np.ndarray
    frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    flutter: bool
    critical_speed_m_s: float
    frequency_hz_at_flutter: float
    reduced_frequency: float
    unstable_mode: str
    max_speed_searched_m_s: float
    divergence_speed_m_s: float = np.nan   # lowest V (up to the flutter speed's interval) where a mode's
                                           # frequency went to zero (static divergence), or NaN
    unresolved: tuple[tuple[str, float], ...] = ()  # (mode, V) where the p-k iteration found no root on the
                                                    # tracked branch (branch jumps); NaN there, listed in reports

    @property
    def oscillatory(self) -> np.ndarray:
        """(n_V, N) bool: False where the tracked p-k eigenvalue is real (frequency 0, below 1e-6 of the
        highest frequency of the sweep) or NaN.  On such a non-oscillatory branch zeta = -Re(s)/|s| is
        exactly +1 (a decaying real root: aerodynamic damping above critical) or -1 (a growing real
        root: static divergence), not a damping ratio of an oscillation."""
        f = np.nan_to_num(self.frequency_hz, nan=0.0)
        return f > _ROUND_OFF_FREQUENCY * f.max(initial=0.0)


def _state_matrix(model: ModalModel, aero: AerodynamicModel, rho: float, w: float, V: float) -> np.ndarray:
    B, L = model.deck_width_m, model.deck_length_m
    m, wi, zi = model.modal_masses, model.angular_frequencies, model.damping_ratios
    A = 0.5 * rho * V**2 * L * _aero_bracket(model, aero.frf(w * B / V, V))    # Eq 4.24, 4.37
    K = np.diag(m * wi**2) - A.real
    C = np.diag(2.0 * m * zi * wi) - A.imag / w
    n = model.n_modes
    S = np.zeros((2 * n, 2 * n))
    S[:n, n:] = np.eye(n)
    S[n:, :n] = -K / m[:, None]
    S[n:, n:] = -C / m[:, None]
    return S


def aeroelastic_eigenvalues(model: ModalModel, aero: AerodynamicModel, air_density: float, speed: float,
                            guesses: np.ndarray, shapes: np.ndarray | None = None, tolerance: float = 1e-10,
                            max_iterations: int = 200, strict: bool = True,
                            modes: Sequence[int] | None = None
                            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """p-k eigenvalue s_r and modal shape (complex N-vector of modal amplitudes) of each mode at wind
    speed V, iterating on frequency from ``guesses`` (one per mode: the previous speed's eigenvalues, or
    i w_r at the first speed).

    Mode tracking: at each trial frequency the eigenvalue whose shape correlates best with the previous
    speed's shape of the same mode (modal assurance criterion in mass-normalised coordinates
    sqrt(m_i) q_i, columns of ``shapes``; identity at the start) is taken; nearest eigenvalue breaks
    ties.  Tracking by eigenvalue distance alone lets modes with close frequencies (S-V5, S-T1, SS-V5
    of the Great Belt) collapse onto one branch and miss the flutter branch.

    The trial frequency is kept inside the aerodynamic model's Omega range (a table is never
    extrapolated); the third return value flags the modes whose iteration wanted to leave it (their
    eigenvalue is then not a p-k solution and the caller discards it).  With ``strict=False`` a mode whose
    iteration does not converge (the tracked eigenvalue jumps between branches, so Im s(w) = w has no
    root on it) is flagged the same way instead of raising ConvergenceError.
    ``modes``: iterate only these mode indices; the others come back as NaN and flagged, never as a
    solution (refining one mode's damping crossing must not depend on, or fail for, another mode's
    iteration).
    """
    n = model.n_modes
    shapes = np.eye(n, dtype=np.complex128) if shapes is None else np.asarray(shapes, dtype=np.complex128)
    out, out_shapes = np.empty(n, dtype=np.complex128), np.empty((n, n), dtype=np.complex128)
    w_floor = 1e-6 * model.angular_frequencies.min()
    o_lo, o_hi = aero.omega_range
    w_lo = max(w_floor, o_lo * speed / model.deck_width_m)      # Omega range of the model, as w at this V
    w_hi = o_hi * speed / model.deck_width_m
    outside = np.zeros(n, dtype=bool)
    unresolved = np.zeros(n, dtype=bool)
    scale = np.sqrt(model.modal_masses)[:, None]   # shapes compared in mass-normalised coordinates
    for r, s_prev in enumerate(np.asarray(guesses, dtype=np.complex128)):
        if modes is not None and r not in modes:
            out[r], out_shapes[:, r], outside[r] = np.nan, np.nan, True
            continue
        ref = shapes[:, r] / np.linalg.norm(shapes[:, r])

        def track(w: float, ref=ref, s_prev=s_prev) -> tuple[complex, np.ndarray, float]:
            """Eigenvalue of this mode at trial frequency w, and g(w) = Im s - w (clipped to the range)."""
            lam, vec = np.linalg.eig(_state_matrix(model, aero, air_density, w, speed))
            keep = lam.imag >= 0.0
            lam, X = lam[keep], scale * vec[:n, keep]
            X = X / np.linalg.norm(X, axis=0)
            mac = np.abs(ref.conj() @ X) ** 2
            score = mac - 1e-6 * np.abs(lam - s_prev) / max(abs(s_prev), w_floor)
            i = int(np.argmax(score))
            return lam[i], X[:, i], min(max(lam[i].imag, w_lo), w_hi) - w

        # p-k condition Im s(w) = w: secant iteration on g(w), which converges where the plain fixed point
        # w <- Im s(w) crawls or oscillates; a step that leaves the range falls back to a damped fixed point.
        w_a = min(max(abs(s_prev.imag), w_lo), w_hi)
        s, phi, g_a = track(w_a)
        w_b = w_a + g_a
        change = abs(g_a) / w_a
        if change > tolerance:
            for _ in range(max_iterations):
                s, phi, g_b = track(w_b)
                change = abs(g_b) / w_b
                if change <= tolerance:
                    break
                w_c = w_b - g_b * (w_b - w_a) / (g_b - g_a) if g_b != g_a else w_b + g_b
                if not (np.isfinite(w_c) and w_lo <= w_c <= w_hi and w_c > 0.0):
                    w_c = w_b + 0.5 * g_b
                w_a, g_a, w_b = w_b, g_b, w_c
            else:
                if strict:
                    raise ConvergenceError(f"p-k frequency iteration, mode {model.labels[r]} at V = {speed:g} m/s",
                                           max_iterations, change, tolerance)
                unresolved[r] = True
        out[r], out_shapes[:, r] = s, phi
        outside[r] = (s.imag < w_lo and w_lo > w_floor) or s.imag > w_hi or unresolved[r]
    return out, out_shapes, outside


def _is_unresolved(model: ModalModel, aero: AerodynamicModel, V: float, s: complex) -> bool:
    """True when a flagged mode's eigenvalue lies inside the aerodynamic model's range: it was flagged for
    a failed iteration, not for leaving the range."""
    o_lo, o_hi = aero.omega_range
    omega = s.imag * model.deck_width_m / V
    return o_lo <= omega <= o_hi


def _collapsed(s: np.ndarray, off: np.ndarray) -> np.ndarray:
    """Flag modes whose tracked eigenvalue is (to 1e-8) another mode's: two rows may not follow one branch;
    the later mode is the one that lost its own (e.g. after restarting past a gap)."""
    flag = np.zeros(s.size, dtype=bool)
    for r in range(s.size):
        for q in range(r):
            if not off[q] and not flag[q] and abs(s[r] - s[q]) <= 1e-8 * max(abs(s[q]), 1e-12):
                flag[r] = True
    return flag


def static_divergence_speed(model: ModalModel, aero: AerodynamicModel, air_density: float,
                            max_speed_m_s: float) -> float:
    """Lowest V at which the structure's modal stiffness is cancelled by the steady aerodynamic stiffness:
    det(diag(m_i w_i^2) - (1/2) rho V^2 L Re[A(Omega -> 0)]) = 0 (Eq 4.24, 4.37 at zero frequency), solved
    as a generalised eigenproblem for q = (1/2) rho V^2.  NaN if none below ``max_speed_m_s`` or if the
    aerodynamic model does not reach Omega = 0 (a table starting above it: no extrapolation).
    Independent of the p-k branch tracking, which loses an overdamped torsional branch near divergence."""
    from scipy.linalg import eigvals

    o_lo, _ = aero.omega_range
    s_lo, s_hi = aero.speed_range
    if o_lo > 1e-3:
        return float("nan")
    omega0 = max(o_lo, 1e-6)
    speed = min(max_speed_m_s, s_hi)
    K = np.diag(model.modal_masses * model.angular_frequencies**2)
    A0 = model.deck_length_m * _aero_bracket(model, aero.frf(omega0, speed)).real   # per unit q
    q = eigvals(K, A0)
    q = q[np.isfinite(q) & (np.abs(q.imag) <= 1e-9 * np.abs(q)) & (q.real > 0.0)].real
    if q.size == 0:
        return float("nan")
    v = float(np.sqrt(2.0 * q.min() / air_density))
    return v if s_lo <= v <= max_speed_m_s else float("nan")


def _damping(s: np.ndarray) -> np.ndarray:
    return -s.real / np.abs(s)


def pk_sweep(model: ModalModel, aero: AerodynamicModel, air_density: float, max_speed_m_s: float,
             min_speed_m_s: float | None = None, n_speed: int = 120, tolerance: float = 1e-10,
             lateral: bool = False) -> MultimodeResult:
    """Damping and frequency of every vertical and torsional mode (and, with ``lateral``, every lateral
    mode that moves the deck, rr[i, i] > 0) for V in [V_min, V_max], and the lowest V where a damping
    ratio crosses zero from above."""
    keep = [i for i in range(model.n_modes) if model.kinds[i] != "lateral"
            or (lateral and model.rr[i, i] > 0.0)]
    if len(keep) < 2:
        raise InputError("flutter.modes", model.labels, "multimode flutter needs >= 2 vertical/torsional modes")
    model = model.subset(keep)
    v_lo, v_hi = speed_window(aero, air_density, max_speed_m_s, min_speed_m_s)
    speeds = np.linspace(v_lo, v_hi, int(n_speed))
    s, phi = 1j * model.angular_frequencies, np.eye(model.n_modes, dtype=np.complex128)
    eig = np.empty((speeds.size, model.n_modes), dtype=np.complex128)
    shapes = np.empty((speeds.size, model.n_modes, model.n_modes), dtype=np.complex128)
    outside = np.zeros((speeds.size, model.n_modes), dtype=bool)
    unresolved = []
    for n, V in enumerate(speeds):
        s_new, phi_new, off = aeroelastic_eigenvalues(model, aero, air_density, V, s, phi, tolerance, strict=False)
        off = off | _collapsed(s_new, off)
        in_range = (s_new.imag >= 0.0) & ~off
        unresolved += [(model.labels[r], float(V)) for r in np.flatnonzero(off & (s_new.imag > 0.0))
                       if _is_unresolved(model, aero, V, s_new[r])]
        # a mode with no solution here keeps its last good eigenvalue and shape as the next start value
        s = np.where(in_range, s_new, s)
        phi = np.where(in_range[None, :], phi_new, phi)
        eig[n], shapes[n], outside[n] = s_new, phi_new, off
    zeta = np.where(outside, np.nan, _damping(eig))        # NaN: outside the aerodynamic model's range
    freq = np.where(outside, np.nan, eig.imag / (2 * np.pi))
    # a root whose frequency is round-off (below 1e-6 of the sweep's highest, MultimodeResult.oscillatory) is
    # real: frequency exactly 0 and zeta exactly +-1, whatever the last bits of its imaginary part
    real = np.isfinite(freq) & (np.abs(freq) <= _ROUND_OFF_FREQUENCY * np.nanmax(np.abs(freq), initial=0.0))
    zeta = np.where(real, np.sign(zeta), zeta)
    freq = np.where(real, 0.0, freq)
    result = dict(labels=model.labels, speed_m_s=speeds, frequency_hz=freq, damping_ratio=zeta,
                  max_speed_searched_m_s=float(v_hi), unresolved=tuple(unresolved))
    crossing = np.flatnonzero((zeta[:-1] > 0.0) & (zeta[1:] <= 0.0))  # flat index over (n_V-1, N)
    w_floor = 1e-3 * model.angular_frequencies.min()   # below this an unstable root is static: divergence
    divergence, flutter_at = np.nan, None
    for c in np.sort(crossing):                          # ascending V, then mode
        n0, r = np.unravel_index(c, (speeds.size - 1, model.n_modes))
        if flutter_at is not None and not np.isnan(divergence):
            break
        if flutter_at is not None and speeds[n0] > flutter_at[0]:
            break                                        # any later divergence is beyond flutter anyway

        def zeta_r(V: float, n0=n0, r=r) -> float:
            s_all, _, off = aeroelastic_eigenvalues(model, aero, air_density, V, eig[n0], shapes[n0], tolerance,
                                                    modes=(r,))
            if off[r]:
                raise InputError("flutter.reduced_frequency", float(s_all[r].imag * model.deck_width_m / V),
                                 "outside the aerodynamic model's range while refining the p-k crossing")
            return float(_damping(s_all[r:r + 1])[0])

        V_c = brentq(zeta_r, speeds[n0], speeds[n0 + 1], xtol=1e-12 * speeds[n0 + 1], rtol=1e-12)
        s_c = aeroelastic_eigenvalues(model, aero, air_density, V_c, eig[n0], shapes[n0], tolerance, modes=(r,))[0][r]
        if s_c.imag < w_floor:                             # zero frequency: static divergence, not flutter
            divergence = float(V_c) if np.isnan(divergence) else divergence
        elif flutter_at is None:
            flutter_at = (float(V_c), s_c, r)
    static = static_divergence_speed(model, aero, air_density, v_hi)
    if not np.isnan(static) and (np.isnan(divergence) or static < divergence):
        divergence = static
    if flutter_at is not None:
        V_c, s_c, r = flutter_at
        return MultimodeResult(flutter=True, critical_speed_m_s=V_c,
                               frequency_hz_at_flutter=float(s_c.imag / (2 * np.pi)),
                               reduced_frequency=float(s_c.imag * model.deck_width_m / V_c),
                               unstable_mode=model.labels[r], divergence_speed_m_s=divergence, **result)
    return MultimodeResult(flutter=False, critical_speed_m_s=np.nan, frequency_hz_at_flutter=np.nan,
                           reduced_frequency=np.nan, unstable_mode="", divergence_speed_m_s=divergence, **result)
