"""Rigid bodies as closed polygons in their own frame (counter-clockwise vertices).

Geometry only: area, centroid and polar second moment (needed by the internal-fluid correction of the
immersed-boundary force), and factories for the shapes of the project: circle, thin plate, and a
streamlined box-girder deck (a parametric hexagon: the thesis's drawings are not available, so the
shape is defined by width B, depth D and the fairing nose/tail lengths; docs/thesis_errata.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Polygon", "circle", "flat_plate", "box_deck"]


@dataclass(frozen=True, eq=False)
class Polygon:
    """Closed polygon, vertices (n, 2) counter-clockwise in the body frame (reference point 0, 0)."""

    vertices: np.ndarray

    def __post_init__(self):
        v = np.asarray(self.vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
            raise ValueError(f"vertices: need shape (n >= 3, 2), got {v.shape}")
        object.__setattr__(self, "vertices", v)
        if self.area <= 0:
            raise ValueError("vertices: must be counter-clockwise (positive signed area)")

    def _cross_terms(self):
        x, y = self.vertices[:, 0], self.vertices[:, 1]
        xn, yn = np.roll(x, -1), np.roll(y, -1)
        return x, y, xn, yn, x * yn - xn * y

    @property
    def area(self) -> float:
        return float(0.5 * self._cross_terms()[4].sum())

    @property
    def centroid(self) -> np.ndarray:
        x, y, xn, yn, c = self._cross_terms()
        return np.array([((x + xn) * c).sum(), ((y + yn) * c).sum()]) / (6.0 * self.area)

    @property
    def polar_moment_centroid(self) -> float:
        """Integral of |r - r_c|^2 over the area (per unit density)."""
        x, y, xn, yn, c = self._cross_terms()
        ixx = ((y * y + y * yn + yn * yn) * c).sum() / 12.0
        iyy = ((x * x + x * xn + xn * xn) * c).sum() / 12.0
        cx, cy = self.centroid
        return float(ixx + iyy - self.area * (cx * cx + cy * cy))

    @property
    def radius(self) -> float:
        """Largest distance of a vertex from the reference point (bounds the body under rotation)."""
        return float(np.hypot(self.vertices[:, 0], self.vertices[:, 1]).max())


def circle(diameter: float, n: int = 256) -> Polygon:
    """Regular n-gon inscribed... with equal area to the circle of the given diameter."""
    if diameter <= 0 or n < 8:
        raise ValueError(f"diameter > 0 and n >= 8 required, got {diameter}, {n}")
    t = 2 * np.pi * np.arange(n) / n
    # radius of the n-gon with the circle's area: (n/2) r^2 sin(2 pi/n) = pi R^2
    r = 0.5 * diameter * np.sqrt(2 * np.pi / (n * np.sin(2 * np.pi / n)))
    return Polygon(np.column_stack([r * np.cos(t), r * np.sin(t)]))


def flat_plate(chord: float, thickness: float) -> Polygon:
    """Rectangle chord x thickness centred at the origin (resolve the thickness by >= 2 cells)."""
    if chord <= 0 or thickness <= 0 or thickness > chord:
        raise ValueError(f"need 0 < thickness <= chord, got chord={chord}, thickness={thickness}")
    a, b = chord / 2, thickness / 2
    return Polygon(np.array([[-a, -b], [a, -b], [a, b], [-a, b]]))


def box_deck(width: float, depth: float, nose: float | None = None, bottom_ratio: float = 0.6) -> Polygon:
    """Streamlined box girder: hexagon with pointed fairings at mid-depth, centred at the origin.

    width B (total), depth D, nose = horizontal length of each fairing (default D), bottom flange
    width = bottom_ratio * (B - 2 nose) ... the deck top is flat between the fairings.
    """
    nose = depth if nose is None else nose
    if not (0 < depth < width and 0 < nose < width / 2 and 0 < bottom_ratio <= 1):
        raise ValueError(f"box_deck: need 0 < depth < width, 0 < nose < width/2, 0 < bottom_ratio <= 1; "
                         f"got {width}, {depth}, {nose}, {bottom_ratio}")
    a = width / 2
    top = a - nose
    bot = bottom_ratio * top
    h = depth / 2
    return Polygon(np.array([[-a, 0.0], [-bot, -h], [bot, -h], [a, 0.0], [top, h], [-top, h]]))
