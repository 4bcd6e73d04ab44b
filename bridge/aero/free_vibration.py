"""Free vibration of a section on springs in the CFD: the flow's own flutter speed, without derivatives.

The flutter stage finds V_c from forced-motion derivatives, which assumes the forces are linear in the
motion and that a few forced frequencies describe them.  Here the CFD checks that route by itself: the
section (heave and pitch about its reference point) sits on linear springs with viscous damping, is held
at a small twist while the flow settles, then released; its motion and the flow advance together.  Below
the flutter speed the motion decays, above it grows; the speed where the growth rate of the least damped
mode changes sign is the CFD's own flutter speed (the classical free-vibration section-model test, e.g.
Scanlan and Tomko 1971, J. Eng. Mech. Div. 97(6), and its CFD form in Larsen and Walther 1997, JWEIA
67-68).

Units are the CFD's: chord B = 1, wind V = 1, air density 1, time in B/V.  For a section of mass m and
inertia I per unit length, natural circular frequencies omega and damping ratios zeta, at wind speed V:

    y'' + 2 zeta_h w_h y' + w_h^2 y = F_y / mu          mu   = m / (rho B^2),  w_h = omega_h B / V
    th'' + 2 zeta_a w_a th' + w_a^2 th = M_z / iota     iota = I / (rho B^4),  w_a = omega_a B / V

with y up, theta and M_z counter-clockwise (the CFD's frame: with the wind from the left that is nose
down), so the loads the flow reports go in as they are.  The wind speed enters only through w_h and w_a:
the Reynolds number is the preset's, as for the forced-motion runs of the derivative route.

Coupling (conventional serial staggered, second order): over each flow step the structure advances by the
trapezoidal rule (Newmark's average acceleration: no numerical damping, which would bias the growth rate)
under the loads extrapolated linearly from the last two steps; the body follows the cubic Hermite curve
between the step's end states, so its position and velocity are continuous.  The fit of the growth rate
is the matrix pencil method (Hua and Sarkar 1990, IEEE Trans. ASSP 38(5)) on both coordinates together.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from bridge.errors import InputError, check_range

__all__ = ["SpringSection", "FreeMotion", "AeroelasticFlow", "DampedMode", "damped_modes", "ReleaseCase",
           "least_damped", "onset"]


@dataclass(frozen=True)
class SpringSection:
    """The section's structure in the CFD's units (module doc): mass and inertia ratios, circular frequencies
    per B/V, damping ratios."""

    mass_ratio: float          # mu = m / (rho B^2)
    inertia_ratio: float       # iota = I / (rho B^4)
    heave_omega: float         # omega_h B / V
    pitch_omega: float         # omega_a B / V
    heave_damping: float = 0.0
    pitch_damping: float = 0.0

    @classmethod
    def at_speed(cls, section, speed_m_s: float, air_density_kg_m3: float) -> SpringSection:
        """``section``: a :class:`bridge.flutter.section.SectionModel` (SI units) at the wind speed ``speed_m_s``."""
        V = check_range("free_vibration.speed_m_s", speed_m_s, low=0.0, low_open=True)
        B, rho = section.deck_width_m, air_density_kg_m3
        return cls(mass_ratio=section.mass_per_length_kg_m / (rho * B ** 2),
                   inertia_ratio=section.inertia_per_length_kg_m2_m / (rho * B ** 4),
                   heave_omega=2 * math.pi * section.heave_frequency_hz * B / V,
                   pitch_omega=2 * math.pi * section.pitch_frequency_hz * B / V,
                   heave_damping=section.heave_damping_ratio, pitch_damping=section.pitch_damping_ratio)

    def coefficients(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per coordinate (x, y, theta): mass, damping, stiffness (x is held: infinite stiffness, no motion)."""
        m = np.array([1.0, self.mass_ratio, self.inertia_ratio])
        w = np.array([0.0, self.heave_omega, self.pitch_omega])
        z = np.array([0.0, self.heave_damping, self.pitch_damping])
        return m, 2 * z * w * m, w ** 2 * m


def _hermite(s: float, h: float, q0, v0, q1, v1):
    """Cubic Hermite position and velocity at the fraction ``s`` of a step of length ``h``."""
    s2, s3 = s * s, s * s * s
    p = (2 * s3 - 3 * s2 + 1) * q0 + (s3 - 2 * s2 + s) * h * v0 + (-2 * s3 + 3 * s2) * q1 + (s3 - s2) * h * v1
    d = ((6 * s2 - 6 * s) * q0 + (3 * s2 - 4 * s + 1) * h * v0 + (-6 * s2 + 6 * s) * q1 + (3 * s2 - 2 * s) * h * v1)
    return p, d / h


@dataclass
class FreeMotion:
    """A rigid motion (bridge.cfd.motion.RigidMotion) whose pose comes from the structure: held at ``held``
    (x, y, theta) until ``release``, then the Hermite curve of the step under way (and of the step before,
    for a query that looks back)."""

    held: tuple[float, float, float]
    release: float
    segments: list = field(default_factory=list)   # up to two (t0, t1, q0, v0, q1, v1), the newest last
    # counts the pushes: the pose and velocity at a time already asked for can change with a push, and a flow
    # that keeps them per time (bridge.cfd.curvilinear) keys them on this too
    revision: int = 0

    def _segment(self, t: float):
        if len(self.segments) == 2 and t < self.segments[1][0]:
            return self.segments[0]
        return self.segments[-1]

    def pose(self, t):
        if not self.segments or t <= self.release:
            return self.held
        t0, t1, q0, v0, q1, v1 = self._segment(t)
        p, _ = _hermite((t - t0) / (t1 - t0), t1 - t0, q0, v0, q1, v1)
        return tuple(float(c) for c in p)

    def velocity(self, t):
        if not self.segments or t <= self.release:
            return (0.0, 0.0, 0.0)
        t0, t1, q0, v0, q1, v1 = self._segment(t)
        _, d = _hermite((t - t0) / (t1 - t0), t1 - t0, q0, v0, q1, v1)
        return tuple(float(c) for c in d)

    def push(self, segment) -> None:
        self.segments = [*self.segments[-1:], segment]
        self.revision += 1


class AeroelasticFlow:
    """A flow (bridge.cfd.flow.Flow) whose body is the section on springs (module doc).  ``flow`` must have
    been built with ``motion`` as its body's motion.  Before ``motion.release`` the section is held; after it
    each :meth:`step` moves the structure over the step, then the flow.  ``kick``: the velocity (x, y, theta)
    given at the release.  ``preload``: the springs hold the mean loads of the hold's second half, so that the
    structure feels only their change (it oscillates about the held pose, as the derivative route linearises
    about it); else it settles where the springs balance the wind.  ``history``: time, y, theta, their rates
    and the loads, one row per step after the release."""

    def __init__(self, flow, motion: FreeMotion, structure: SpringSection, kick=(0.0, 0.0, 0.0),
                 preload: bool = False):
        self.flow, self.motion, self.structure = flow, motion, structure
        self.m, self.c, self.k = structure.coefficients()
        self.q = np.array(motion.held, dtype=np.float64)
        self.v = np.zeros(3)
        self.kick, self.preload = np.asarray(kick, dtype=np.float64), preload
        self.offset = np.zeros(3)
        self._held = [0.0, np.zeros(3)]   # time and load integral over the hold's second half
        self._started = False
        self.loads: list[tuple[float, np.ndarray]] = []   # the last two (t, (F_x, F_y, M_z)) after steps
        self.history: list[tuple[float, ...]] = []

    # the Flow contract, passed through
    def __getattr__(self, name):
        return getattr(self.flow, name)

    @property
    def total_force(self):
        return self.flow.total_force

    def stable_dt(self) -> float:
        return self.flow.stable_dt()

    def _predicted_load(self, t_new: float) -> np.ndarray:
        (t1, f1) = self.loads[-1]
        if len(self.loads) < 2:
            return f1
        (t0, f0) = self.loads[-2]
        return f1 + (f1 - f0) * (t_new - t1) / (t1 - t0)

    def _start(self) -> None:
        self._started = True
        self.v = self.kick.copy()
        if self.preload:
            if self._held[0] <= 0.0:
                raise ValueError("preload: the hold is too short to have a second half")
            self.offset = self._held[1] / self._held[0]

    def step(self, dt: float) -> float:
        t = self.flow.t
        released = t >= self.motion.release - 1e-12 and self.loads
        if released:
            if not self._started:
                self._start()
            m, c, k = self.m, self.c, self.k
            f_old = self.loads[-1][1] - self.offset
            f_new = self._predicted_load(t + dt) - self.offset
            free = k > 0
            a_old = np.where(free, (f_old - c * self.v - k * self.q) / m, 0.0)
            rhs = f_new - c * (self.v + 0.5 * dt * a_old) - k * (self.q + dt * self.v + 0.25 * dt * dt * a_old)
            a_new = np.where(free, rhs / (m + 0.5 * dt * c + 0.25 * dt * dt * k), 0.0)
            q_new = self.q + dt * self.v + 0.25 * dt * dt * (a_old + a_new)
            v_new = self.v + 0.5 * dt * (a_old + a_new)
            self.motion.push((t, t + dt, self.q.copy(), self.v.copy(), q_new, v_new))
            self.q, self.v = q_new, v_new
        taken = self.flow.step(dt)
        load = np.asarray(self.flow.total_force, dtype=np.float64).copy()
        if not np.all(np.isfinite(load)):
            from bridge.cfd import FlowDiverged

            raise FlowDiverged(f"non-finite loads at t = {self.flow.t:.6g}")
        self.loads = [*self.loads[-1:], (self.flow.t, load)]
        if released:
            self.history.append((self.flow.t, self.q[1], self.q[2], self.v[1], self.v[2], *load))
        elif t >= 0.5 * self.motion.release:
            self._held[0] += dt
            self._held[1] = self._held[1] + dt * load
        return taken


@dataclass(frozen=True)
class ReleaseCase:
    """What bridge.aero.presets.build_flow needs of a case: the motion, and how far the body may travel (for
    the grids' size).  ``twist_rad``: the initial twist (counter-clockwise); ``hold``: time held (B/V);
    ``kick_rate``: the pitch rate given at the release (per B/V); ``preload``: see :class:`AeroelasticFlow`;
    ``reach``: the largest heave the grids make room for (chords); ``max_twist_rad``: the largest twist."""

    twist_rad: float
    hold: float
    kick_rate: float = 0.0
    preload: bool = False
    reach: float = 0.1
    max_twist_rad: float = math.radians(6.0)
    _motion: FreeMotion | None = field(default=None, init=False, repr=False, compare=False)

    def motion(self) -> FreeMotion:
        """The one motion of this case: the flow that build_flow makes and the AeroelasticFlow share it."""
        if self._motion is None:
            object.__setattr__(self, "_motion", FreeMotion((0.0, 0.0, self.twist_rad), self.hold))
        return self._motion

    def key(self) -> dict:
        return {"twist_rad": self.twist_rad, "hold": self.hold, "kick_rate": self.kick_rate, "preload": self.preload,
                "reach": self.reach, "max_twist_rad": self.max_twist_rad}

    def flow(self, flow, structure: SpringSection) -> AeroelasticFlow:
        """``flow`` (built by build_flow with this case) with the section on springs."""
        return AeroelasticFlow(flow, self.motion(), structure, kick=(0.0, 0.0, self.kick_rate), preload=self.preload)

    def excursion(self, radius: float) -> float:
        return self.reach + math.sin(self.max_twist_rad) * radius


@dataclass(frozen=True)
class DampedMode:
    """One mode of a fitted free response: s = sigma + i omega (per unit time of the record), its damping
    ratio -sigma/|s|, and its amplitude in each channel (the channels' units)."""

    sigma: float
    omega: float
    amplitudes: tuple[float, ...]

    @property
    def damping_ratio(self) -> float:
        return -self.sigma / math.hypot(self.sigma, self.omega)


def damped_modes(t: np.ndarray, channels: np.ndarray, n_modes: int = 2, samples: int = 600) -> list[DampedMode]:
    """The ``n_modes`` oscillating modes (and a constant offset) that best fit the records ``channels``
    (shape (n_channels, len(t))) together, by the matrix pencil method: the records resampled uniformly,
    each scaled by its RMS, their Hankel matrices stacked, the signal space of rank 2 n_modes + 1 from the
    SVD, the poles from its shift invariance, then the amplitudes per channel by least squares.  Sorted by
    frequency; modes found as real poles are dropped."""
    t = np.asarray(t, dtype=np.float64)
    y = np.atleast_2d(np.asarray(channels, dtype=np.float64))
    if t.size < 20 or y.shape[1] != t.size:
        raise ValueError(f"damped_modes: need at least 20 samples per channel, got {t.size} times and {y.shape}")
    tu = np.linspace(t[0], t[-1], samples)
    h = tu[1] - tu[0]
    yu = np.array([np.interp(tu, t, c) for c in y])
    scale = np.sqrt(np.mean((yu - yu.mean(axis=1, keepdims=True)) ** 2, axis=1))
    scale[scale == 0] = 1.0
    yn = yu / scale[:, None]
    order = 2 * n_modes + 1
    L = samples // 3
    hankel = np.vstack([np.lib.stride_tricks.sliding_window_view(c, L + 1) for c in yn])
    _, _, vh = np.linalg.svd(hankel, full_matrices=False)
    V = vh[:order].T
    z = np.linalg.eigvals(np.linalg.pinv(V[:-1]) @ V[1:])
    s = np.log(z.astype(complex)) / h
    basis = np.exp(np.outer(tu - tu[0], s))
    amp, *_ = np.linalg.lstsq(basis, yu.T, rcond=None)
    modes = []
    for j in np.nonzero(s.imag > 1e-9)[0]:
        modes.append(DampedMode(float(s[j].real), float(s[j].imag), tuple(float(2 * abs(x)) for x in amp[j])))
    return sorted(modes, key=lambda md: md.omega)


def least_damped(modes: list[DampedMode], significant: float = 0.05) -> DampedMode:
    """The mode that decides stability: the largest growth rate among modes whose amplitude reaches
    ``significant`` of the largest in some channel (a fit's spurious weak pole does not count)."""
    if not modes:
        raise ValueError("least_damped: no oscillating mode was found in the record")
    a = np.array([md.amplitudes for md in modes])
    keep = np.any(a >= significant * a.max(axis=0, keepdims=True), axis=1)
    return max((md for md, k in zip(modes, keep, strict=True) if k), key=lambda md: md.sigma)


def onset(speeds, sigmas) -> float | None:
    """The speed where the growth rate first changes sign from negative to positive, linear between the
    bracketing speeds; None if it does not change sign."""
    v = np.asarray(speeds, dtype=np.float64)
    s = np.asarray(sigmas, dtype=np.float64)
    order = np.argsort(v)
    v, s = v[order], s[order]
    for i in range(len(v) - 1):
        if s[i] < 0 <= s[i + 1]:
            return float(v[i] - s[i] * (v[i + 1] - v[i]) / (s[i + 1] - s[i]))
    return None


def check_speeds(speeds) -> tuple[float, ...]:
    """``--speeds``: positive speeds (two or more to bracket the onset; one runs and records that speed)."""
    out = tuple(float(v) for v in speeds)
    if not out:
        raise InputError("--speeds", "", "at least one wind speed (m/s); two or more to bracket the onset")
    for v in out:
        check_range("--speeds", v, low=0.0, low_open=True, high=1000.0)
    return out
