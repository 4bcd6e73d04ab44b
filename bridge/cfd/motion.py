"""Prescribed rigid-body motion of an immersed body: position (x, y, theta) and velocity in time.

A motion maps time t to the pose of the body frame (reference point x, y and rotation theta,
counter-clockwise) and its velocity (u, v, omega). Later issues drive these from a structural model
(fluid-structure coupling): anything with ``pose(t)`` and ``velocity(t)`` plugs in.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

__all__ = ["RigidMotion", "Stationary", "UniformTranslation", "HarmonicMotion", "PrescribedMotion"]


class RigidMotion(Protocol):
    def pose(self, t: float) -> tuple[float, float, float]: ...

    def velocity(self, t: float) -> tuple[float, float, float]: ...


@dataclass(frozen=True)
class Stationary:
    """Body fixed at (x, y) with angle theta (radians)."""

    x: float = 0.0
    y: float = 0.0
    theta: float = 0.0

    def pose(self, t):
        return (self.x, self.y, self.theta)

    def velocity(self, t):
        return (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class UniformTranslation:
    """x(t) = x0 + u t, y(t) = y0 + v t, no rotation."""

    x0: float
    y0: float
    u: float
    v: float

    def pose(self, t):
        return (self.x0 + self.u * t, self.y0 + self.v * t, 0.0)

    def velocity(self, t):
        return (self.u, self.v, 0.0)


@dataclass(frozen=True)
class HarmonicMotion:
    """Heave/sway/pitch about a mean pose: q(t) = q0 + amp sin(omega t + phase) per component.

    amplitude = (ax, ay, a_theta) in length, length, radians; omega in rad/s.
    """

    x0: float
    y0: float
    amplitude: tuple[float, float, float]
    omega: float
    theta0: float = 0.0
    phase: float = 0.0

    def __post_init__(self):
        if self.omega < 0:
            raise ValueError(f"omega: must be >= 0, got {self.omega}")
        if len(self.amplitude) != 3:
            raise ValueError(f"amplitude: need 3 components (x, y, theta), got {self.amplitude}")

    def pose(self, t):
        s = math.sin(self.omega * t + self.phase)
        ax, ay, at = self.amplitude
        return (self.x0 + ax * s, self.y0 + ay * s, self.theta0 + at * s)

    def velocity(self, t):
        c = self.omega * math.cos(self.omega * t + self.phase)
        ax, ay, at = self.amplitude
        return (ax * c, ay * c, at * c)


@dataclass(frozen=True)
class PrescribedMotion:
    """General motion from callables: pose(t) -> (x, y, theta), velocity(t) -> (u, v, omega).

    If ``velocity_fn`` is None the velocity is the central difference of the pose (step ``dt_fd``).
    """

    pose_fn: Callable[[float], tuple[float, float, float]]
    velocity_fn: Callable[[float], tuple[float, float, float]] | None = None
    dt_fd: float = 1e-6

    def pose(self, t):
        return tuple(float(q) for q in self.pose_fn(t))

    def velocity(self, t):
        if self.velocity_fn is not None:
            return tuple(float(q) for q in self.velocity_fn(t))
        a, b = self.pose_fn(t - self.dt_fd), self.pose_fn(t + self.dt_fd)
        return tuple((qb - qa) / (2 * self.dt_fd) for qa, qb in zip(a, b, strict=True))
