"""Static coefficients and the Strouhal number of a section held still in the wind (thesis 5.2).

A :class:`bridge.aero.forced_motion.StaticCase` holds the section at an angle of attack alpha (nose-up)
for the preset's ``static_duration`` convective times B / V from an impulsive start.  Over the second
half of that record the mean loads give

    C_D = q / ((1/2) rho V^2 B),   C_L = p / ((1/2) rho V^2 B),   C_M = m / ((1/2) rho V^2 B^2)

(all on the chord B, as :class:`bridge.flutter.aerodynamics.QuasiSteady` takes them; lift up, drag
downwind, moment nose-up about the section's reference point), and the lift's fluctuation gives the
shedding frequency f of the wake, reported as St = f D / V on the section's depth D (and f B / V).

Over several angles a straight line per coefficient (least squares in alpha, radians) gives its value
at alpha = 0 and its slope; these are the inputs of the quasi-steady model
(:meth:`StaticCoefficients.quasi_steady`), which completes the CFD's heave and pitch derivatives with
the lateral (drag, sway) terms.

Chordwise loading (a diagnostic of where a plate carries its lift, ``tools/plate_loading.py``): the pressure
difference between the lower and the upper surface, Delta C_p(x) = (p_lower - p_upper) / ((1/2) rho V^2), x
from the leading edge in chords.  For the thin plate in potential flow (Katz and Plotkin, Low-Speed
Aerodynamics, 2nd ed. 2001, section 5.3)

    Delta C_p(x) = 4 alpha sqrt((1 - x) / x),

whose integral over a strip is 4 alpha [F(x1) - F(x0)], F(x) = sqrt(x (1 - x)) + arcsin(sqrt(x)): over the
chord 2 pi alpha, with the centre of pressure at the quarter chord.  28 % of that lift lies on the first 5 %
of the chord (:func:`thin_plate_loading`).

Settling: an impulsively started section reaches its steady lift only as the starting vortex moves
away (for a thin plate Wagner's function, 1 - 0.165 exp(-0.091 t V/B) - 0.335 exp(-0.6 t V/B)), so a
finite run under-reads it; :attr:`StaticCoefficients.settling` reports the change of each mean between
the third and the last quarter of the record as the measure of what is left.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bridge.aero.forced_motion import ForceRecord

SHEDDING_THRESHOLD = 1e-4   # lift coefficient rms below which a wake counts as steady

__all__ = ["SHEDDING_THRESHOLD", "ChordwiseLoading", "StaticCoefficients", "chordwise_loading", "static_coefficients",
           "shedding_frequency", "thin_plate_loading", "window_mean"]


def window_mean(t: np.ndarray, x: np.ndarray, start: float, end: float | None = None) -> float:
    """Time-weighted mean of ``x`` over start < t <= end (trapezoidal rule, uneven steps allowed)."""
    end = float(t[-1]) if end is None else end
    sel = (t >= start) & (t <= end)
    if sel.sum() < 2:
        raise ValueError(f"window [{start}, {end}] holds fewer than 2 samples")
    ts, xs = t[sel], x[sel]
    return float(np.sum(0.5 * (xs[1:] + xs[:-1]) * np.diff(ts)) / (ts[-1] - ts[0]))


def shedding_frequency(t: np.ndarray, x: np.ndarray, threshold: float = SHEDDING_THRESHOLD,
                       min_cycles: float = 2.0) -> tuple[float, float]:
    """Dominant frequency (cycles per unit time) of the fluctuation of ``x`` and its rms.

    The record is resampled on an even grid, its mean and linear trend removed, and the peak of the
    Hann-windowed, 16-fold zero-padded spectrum refined by a parabola through the three bins around it.
    A record whose fluctuation rms is below ``threshold`` is steady, and a peak with fewer than
    ``min_cycles`` periods in the record is no frequency the record can resolve: both give NaN."""
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    n = max(64, t.size)
    te = np.linspace(t[0], t[-1], n)
    xe = np.interp(te, t, x)
    xe = xe - np.polyval(np.polyfit(te - te.mean(), xe, 1), te - te.mean())
    rms = float(np.sqrt(np.mean(xe ** 2)))
    if rms < threshold:
        return math.nan, rms
    nfft = 16 * n
    spec = np.abs(np.fft.rfft(xe * np.hanning(n), nfft))
    k = int(np.argmax(spec[1:])) + 1
    if 1 <= k < spec.size - 1:
        a, b, c = np.log(spec[k - 1:k + 2] + 1e-300)
        denom = a - 2 * b + c
        k = k + (0.5 * (a - c) / denom if denom != 0 else 0.0)
    dt = (te[-1] - te[0]) / (n - 1)
    f = float(k / (nfft * dt))
    return (f if f * (te[-1] - te[0]) >= min_cycles else math.nan), rms


@dataclass(frozen=True)
class StaticCoefficients:
    """Means over the second half of each static run, per angle (arrays over ``angles_deg``)."""

    angles_deg: np.ndarray
    drag: np.ndarray          # C_D on B
    lift: np.ndarray          # C_L (up)
    moment: np.ndarray        # C_M (nose-up, about the reference point)
    lift_rms: np.ndarray      # rms of the lift coefficient's fluctuation
    frequency: np.ndarray     # shedding frequency f B / V (NaN: steady wake, or < 2 periods in the window)
    settling: np.ndarray      # (angles, 3): change of C_D, C_L, C_M from the third to the last quarter
    depth_over_chord: float   # D / B of the section
    window: tuple[float, float]

    @property
    def strouhal(self) -> np.ndarray:
        """St = f D / V on the section's depth."""
        return self.frequency * self.depth_over_chord

    def fit(self, values: np.ndarray) -> tuple[float, float]:
        """(value at alpha = 0, slope per radian) of the least-squares line through ``values``."""
        a = np.radians(self.angles_deg)
        if a.size == 1:
            return float(values[0]), math.nan
        slope, at0 = np.polyfit(a, values, 1)
        return float(at0), float(slope)

    def fits(self) -> tuple[tuple[float, float], ...]:
        """:meth:`fit` of C_D, C_L and C_M, in that order."""
        return tuple(self.fit(v) for v in (self.drag, self.lift, self.moment))

    def quasi_steady(self):
        """The quasi-steady model of these coefficients (values at alpha = 0, slopes of the line fits; a
        negative drag, which only a run gone wrong gives, enters as 0 - the stage warns)."""
        from bridge.flutter.aerodynamics import QuasiSteady

        if self.angles_deg.size < 2:
            raise ValueError("the quasi-steady model needs the slopes: at least 2 angles")
        (cd, dcd), (cl, dcl), (cm, dcm) = self.fits()
        return QuasiSteady(lift_coefficient=cl, lift_slope_per_rad=dcl, drag_coefficient=max(cd, 0.0),
                           moment_coefficient=cm, moment_slope_per_rad=dcm, drag_slope_per_rad=dcd,
                           name="quasi_steady (CFD static coefficients)")


def static_coefficients(records: list[ForceRecord], angles_deg, depth_over_chord: float) -> StaticCoefficients:
    """Coefficients of the static runs ``records`` (CFD units: loads per rho V^2 B, moments per
    rho V^2 B^2, so a coefficient is twice the load) held at ``angles_deg``."""
    rows, settle, window = [], [], (0.0, 0.0)
    for rec in records:
        t, end = rec.t, float(rec.t[-1])
        half, q3 = 0.5 * end, 0.75 * end
        loads = (2.0 * rec.drag, 2.0 * rec.lift, 2.0 * rec.moment)
        means = [window_mean(t, x, half) for x in loads]
        settle.append([window_mean(t, x, q3) - window_mean(t, x, half, q3) for x in loads])
        sel = t >= half
        f, rms = shedding_frequency(t[sel], loads[1][sel])
        rows.append((*means, rms, f))
        window = (half, end)
    arr = np.array(rows, dtype=float).reshape(-1, 5)
    return StaticCoefficients(np.asarray(angles_deg, dtype=float), arr[:, 0], arr[:, 1], arr[:, 2], arr[:, 3],
                              arr[:, 4], np.array(settle, dtype=float).reshape(-1, 3), float(depth_over_chord),
                              window)


def thin_plate_loading(alpha: float, x0: float, x1: float) -> float:
    """The thin plate's potential-flow loading integrated over the strip x0 <= x <= x1 of the chord (module doc):
    its lift coefficient from that strip, 4 alpha [F(x1) - F(x0)]; ``alpha`` in radians, 0 <= x0 <= x1 <= 1."""
    if not 0.0 <= x0 <= x1 <= 1.0:
        raise ValueError(f"strip: need 0 <= x0 <= x1 <= 1, got {x0}, {x1}")

    def F(x):
        return math.sqrt(x * (1.0 - x)) + math.asin(math.sqrt(x))

    return 4.0 * alpha * (F(x1) - F(x0))


@dataclass(frozen=True)
class ChordwiseLoading:
    """Delta C_p summed over strips of the chord, with what the whole chord's loading gives."""

    edges: np.ndarray        # strip edges, chords from the leading edge
    strips: np.ndarray       # integral of Delta C_p over each strip (its share of C_L)
    potential: np.ndarray    # the same for the thin plate in potential flow (thin_plate_loading)
    lift: float              # C_L from the pressure alone (the chord's integral)
    moment: float            # C_M about the mid-chord, nose-up, from the pressure alone
    alpha: float             # radians

    @property
    def centre_of_pressure(self) -> float:
        """Chords from the leading edge (0.25 for the thin plate in potential flow)."""
        return 0.5 - self.moment / self.lift

    def as_dict(self) -> dict:
        return {"strip_edges": self.edges.tolist(), "strips": self.strips.tolist(),
                "potential_flow_strips": self.potential.tolist(), "lift_from_pressure": self.lift,
                "moment_from_pressure": self.moment, "centre_of_pressure": self.centre_of_pressure,
                "alpha_rad": self.alpha}


def chordwise_loading(x: np.ndarray, delta_cp: np.ndarray, width: np.ndarray, alpha: float,
                      edges=(0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0)) -> ChordwiseLoading:
    """Sum samples of Delta C_p (at ``x``, chords from the leading edge, each standing for a piece of chord
    ``width``: a cell or a face) over the strips between ``edges``, beside the thin plate's potential flow at
    ``alpha`` (radians); C_L and C_M (mid-chord, nose-up) of the whole chord from the same samples."""
    x, dcp, w = (np.asarray(a, dtype=float) for a in (x, delta_cp, width))
    if not x.shape == dcp.shape == w.shape or x.ndim != 1 or x.size == 0:
        raise ValueError(f"x, delta_cp, width: need equal 1-d shapes, got {x.shape}, {dcp.shape}, {w.shape}")
    e = np.asarray(edges, dtype=float)
    if e[0] != 0.0 or e[-1] != 1.0 or np.any(np.diff(e) <= 0):
        raise ValueError(f"edges: need 0 = e0 < e1 < ... = 1, got {e.tolist()}")
    load = dcp * w
    strip = np.clip(np.searchsorted(e, x, side="right") - 1, 0, e.size - 2)
    strips = np.bincount(strip, weights=load, minlength=e.size - 1)
    potential = np.array([thin_plate_loading(alpha, a, b) for a, b in zip(e[:-1], e[1:], strict=True)])
    return ChordwiseLoading(edges=e, strips=strips, potential=potential, lift=float(load.sum()),
                            moment=float(-(load * (x - 0.5)).sum()), alpha=float(alpha))
