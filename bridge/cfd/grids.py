"""Cartesian staggered (MAC) grids: uniform in x, uniform or stretched in y.

A grid is an immutable object; solver parts ask it for metrics instead of assuming a layout, so a
later moving/overset grid can provide the same metrics. Storage convention (shared with
``kernels/cfd.py``): arrays are indexed [J, I] with ``GHOST`` ghost layers; cell (i, j) lives at
(J, I) = (j + GHOST, i + GHOST); u at storage (J, I) is the left face of cell column I; v at storage
(J, I) is the bottom face of cell row J. Shapes: p (ny+2G, nx+2G), u (ny+2G, nx+1+2G),
v (ny+1+2G, nx+2G).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .precision import DTYPE

GHOST = 2

__all__ = ["GHOST", "CartesianGrid", "stretched_faces"]


@dataclass(frozen=True, eq=False)
class CartesianGrid:
    """Staggered grid on [x_faces[0], x_faces[-1]] x [y_faces[0], y_faces[-1]].

    x_faces must be uniform (the pressure solver transforms along x); y_faces may be stretched.
    """

    x_faces: np.ndarray
    y_faces: np.ndarray

    def __post_init__(self):
        x = np.asarray(self.x_faces, dtype=DTYPE)
        y = np.asarray(self.y_faces, dtype=DTYPE)
        object.__setattr__(self, "x_faces", x)
        object.__setattr__(self, "y_faces", y)
        if x.ndim != 1 or x.size < 5:
            raise ValueError(f"x_faces: need a 1D array of >= 5 faces, got shape {x.shape}")
        if y.ndim != 1 or y.size < 5:
            raise ValueError(f"y_faces: need a 1D array of >= 5 faces, got shape {y.shape}")
        dx = np.diff(x)
        if np.any(dx <= 0) or np.ptp(dx) > 1e-9 * dx.mean():
            raise ValueError("x_faces: must be strictly increasing and uniform (allowed spread 1e-9 dx)")
        if np.any(np.diff(y) <= 0):
            raise ValueError("y_faces: must be strictly increasing")

    @classmethod
    def uniform(cls, nx: int, ny: int, x_range: tuple[float, float], y_range: tuple[float, float]):
        """Uniform grid of nx x ny cells."""
        if nx < 4 or ny < 4:
            raise ValueError(f"nx, ny: need >= 4 cells each, got {nx}, {ny}")
        return cls(np.linspace(*x_range, nx + 1), np.linspace(*y_range, ny + 1))

    # --- sizes and spacings -------------------------------------------------------------------
    @property
    def nx(self) -> int:
        return self.x_faces.size - 1

    @property
    def ny(self) -> int:
        return self.y_faces.size - 1

    @property
    def shape(self) -> tuple[int, int]:
        """(ny, nx) cells, the order of the arrays."""
        return (self.ny, self.nx)

    @property
    def dx(self) -> float:
        return float((self.x_faces[-1] - self.x_faces[0]) / self.nx)

    @property
    def dy(self) -> np.ndarray:
        """Cell heights (ny)."""
        return np.diff(self.y_faces)

    @property
    def y_uniform(self) -> bool:
        d = self.dy
        return bool(np.ptp(d) <= 1e-9 * d.mean())

    @property
    def x_centres(self) -> np.ndarray:
        return 0.5 * (self.x_faces[1:] + self.x_faces[:-1])

    @property
    def y_centres(self) -> np.ndarray:
        return 0.5 * (self.y_faces[1:] + self.y_faces[:-1])

    @property
    def min_spacing(self) -> float:
        return float(min(self.dx, self.dy.min()))

    # --- metrics in storage indexing (with ghosts, mirrored at the boundaries) ------------------
    def storage_shape(self, field: str) -> tuple[int, int]:
        """Storage shape (with ghosts) of ``field``: "u", "v" or "p" (module doc)."""
        g, nx, ny = GHOST, self.nx, self.ny
        shapes = {"u": (ny + 2 * g, nx + 1 + 2 * g), "v": (ny + 1 + 2 * g, nx + 2 * g), "p": (ny + 2 * g, nx + 2 * g)}
        if field not in shapes:
            raise ValueError(f"field: 'u', 'v' or 'p', got {field!r}")
        return shapes[field]

    def storage_y_centres(self) -> np.ndarray:
        """y of cell-row centres for storage rows 0..ny+2G-1 (ghost rows mirrored)."""
        g = GHOST
        yc = self.y_centres
        lo = 2 * self.y_faces[0] - yc[:g][::-1]
        hi = 2 * self.y_faces[-1] - yc[-g:][::-1]
        return np.concatenate([lo, yc, hi])

    def storage_y_faces(self) -> np.ndarray:
        """y of v-face rows for storage rows 0..ny+2G (ghost rows mirrored)."""
        g = GHOST
        yf = self.y_faces
        lo = 2 * yf[0] - yf[1:g + 1][::-1]
        hi = 2 * yf[-1] - yf[-g - 1:-1][::-1]
        return np.concatenate([lo, yf, hi])

    def hy_cells(self) -> np.ndarray:
        """Cell heights per storage row (ny+2G): control-volume height of u-faces."""
        yf = self.storage_y_faces()
        return np.diff(yf)

    def hy_faces(self) -> np.ndarray:
        """Centre-to-centre distance at each v-face storage row (ny+1+2G): v control-volume height.

        Entry J is the distance between cell rows J-1 and J; the first entry (no row -1) repeats
        its neighbour (never used by the kernels).
        """
        yc = self.storage_y_centres()
        d = np.diff(yc)
        return np.concatenate([[d[0]], d, [d[-1]]])

    def cell_areas(self) -> np.ndarray:
        """(ny, nx) cell areas."""
        return np.outer(self.dy, np.full(self.nx, self.dx))


def stretched_faces(lo: float, hi: float, core: tuple[float, float], h_core: float,
                    ratio: float = 1.05) -> np.ndarray:
    """Faces on [lo, hi]: uniform spacing h_core inside ``core``, geometric growth ``ratio`` outside.

    The outermost cells are adjusted so the faces end exactly at lo and hi.
    """
    c0, c1 = core
    if not (lo < c0 < c1 < hi):
        raise ValueError(f"core: need lo < core[0] < core[1] < hi, got {lo}, {core}, {hi}")
    if not 1.0 <= ratio <= 1.2:
        raise ValueError(f"ratio: allowed 1.0 .. 1.2, got {ratio}")
    if h_core <= 0:
        raise ValueError(f"h_core: must be > 0, got {h_core}")
    n_core = max(1, int(round((c1 - c0) / h_core)))
    core_faces = np.linspace(c0, c1, n_core + 1)
    h = (c1 - c0) / n_core

    def grow(length):
        out, s, step = [], 0.0, h
        while True:
            step *= ratio
            if s + step >= length - 0.5 * step:
                break
            s += step
            out.append(s)
        out.append(length)
        return np.array(out)

    below = c0 - grow(c0 - lo)[::-1]
    above = c1 + grow(hi - c1)
    return np.concatenate([below, core_faces, above])
