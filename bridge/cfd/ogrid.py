"""Body-fitted O-grid around one closed outline (a deck section), graded from the wall.

The grid is structured, ``(n_normal + 1) x n_around`` nodes: index i runs around the outline in its own
(counter-clockwise) order and is periodic (node ``n_around`` is node 0, not stored twice); index j = 0 is the
wall, j = ``n_normal`` the outer boundary.  It is built in three steps.

1. Wall nodes (:func:`wall_points`).  Every outline vertex whose turning angle exceeds ``corner_angle_deg`` is a
   *corner* and becomes a node.  Between corners the nodes follow a target spacing, finest at the convex corners
   (the far spacing divided by up to ``corner_refinement``, in proportion to the turning angle up to 90 degrees)
   and growing away from each by ``spacing_ratio`` from node to node (a geometric progression), scaled so that
   there are ``n_around`` nodes.  A curve that turns by more than ``corner_angle_deg`` within one mean spacing (a
   round plate end) is refined in the same way, at each of its vertices, which need not be nodes.  Concave corners
   are not refined: grid lines converge there, and a spacing below the first layers folds the grid.  Node 0 is
   the outline's first corner (vertex 0 if it has none).
2. Layer heights (:func:`layer_heights`).  The first is ``first_height``, each next one ``growth`` times the last,
   and their number is the smallest that reaches ``outer_distance``.  The ratio is then lowered a little (never
   raised) so that the heights add up to ``outer_distance`` exactly.
3. Hyperbolic marching, one layer at a time (Steger and Chaussee 1980, "Generation of body-fitted coordinates
   using hyperbolic partial differential equations", SIAM J. Sci. Stat. Comput. 1(4), 431-437).  The
   orthogonality condition r_xi . r_eta = 0 and the cell-area condition (x_eta y_xi - x_xi y_eta = dA) are
   linearised about the explicit step e (the front's normal times the layer height h).  The new layer's
   xi-derivatives are taken implicitly with central differences, which couples the nodes of a layer in one
   periodic 2 x 2 block tridiagonal system for the step, in delta form: dr + B^-1 A delta_xi(dr) = e.
   Smoothing follows Chan and Steger (1992, "Enhancements of a three-dimensional hyperbolic grid generation
   scheme", Appl. Math. Comput. 51, 181-205): a second-difference dissipation, explicit on the node positions
   and implicit (twice as large) on the step, so that it is stable for any coefficient.  Its coefficient is
   ``smoothing`` x (step / spacing) x ((a) + (b)):
   (a) their distance scaling sqrt(l / (L - 1)) times their grid-convergence sensor (spacing of the previous
       layer over this one's, to the power 2 / the scaling, capped at ``SENSOR_MAX``: large where lines converge
       near the wall);
   (b) our addition, a concave term: 2 x (distance marched / spacing), fully on where the front turns concave by
       45 degrees or more within the distance marched.  A dissipation that grows with the distance lets the
       rounding of a concave corner grow as fast as the layers; without it the lines focus onto the corner's
       bisector (the L-shaped outline of the tests folds there at layer 22, 0.07 chord out).
   The explicit part moves nodes along the front and outwards, never inwards (at a convex corner it would pull
   the node behind the last layer).  Every node then advances by at least h: a step that the dissipation made
   shorter is stretched back to h (so the layers' spacing along the lines keeps the growth ratio), one that it
   made longer is kept (a concave corner's layers round off ahead of the offset curve).  A corner node steps
   along the bisector of the front: h at a convex corner, which then fans out, and the mitre h / cos(t/2) at a
   concave turn t.

The first layer is the exact normal step (no coupling, no smoothing): grid lines leave the wall orthogonally,
along the bisector of the two sides at a corner node, and the first nodes lie ``first_height`` from the wall.  Each
layer is checked as it is made: every cell a convex quadrilateral (its four corner Jacobians positive) and no
crossing between nodes far apart in i (the layers from two sides of a gap meeting).  An outline that cannot be
meshed raises ``ValueError`` saying where and why; :class:`OGrid` checks every cell again on construction, so a
folded grid is never returned.

Limits: no elliptic smoothing afterwards (the grid is orthogonal near the wall by construction; its outer
boundary is a smoothed offset curve of the outline, a rounded box around a deck, not a circle).  At a sharp
convex corner the node's single line leaves the two wall cells skewed by half the turning angle (a 90-degree
corner: 45 degrees), and a first layer much thicker than the corner spacing keeps the fan narrow for a few
layers.  Deep notches and cavities (a 0.1 x 0.05 notch in a unit-chord box, say, with 400 nodes around) can fold
where the layers leave them: a larger ``smoothing`` or fewer nodes help.  The quality measures follow Thompson,
Warsi and Mastin ("Numerical Grid Generation", 1985).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.optimize import brentq
from scipy.sparse.linalg import spsolve

from .outline import Ring, check_ring, signed_area

__all__ = ["OGrid", "GridQuality", "o_grid", "wall_points", "layer_heights", "MAX_GROWTH", "CORNER_ANGLE_DEG"]

MAX_GROWTH = 1.2           # largest wall-normal growth ratio accepted (body-fitted grids that resolve a boundary
# layer grade by <= 1.2: the STYLE.md survey of OVERFLOW-style O-grids and prism layers)
CORNER_ANGLE_DEG = 15.0    # turning angle above which an outline vertex is a corner (the Great Belt crown turns by
# 2.3 degrees, its panel edges by 28 and its noses by 123; a 16-segment round plate end by 11.25 at each vertex)
SENSOR_MAX = 50.0          # cap of the grid-convergence sensor (Chan and Steger's is unbounded)
CONCAVE_FACTOR = 2.0       # of the concave dissipation term (b) of the module docstring
CONCAVE_TURN = np.radians(45.0)  # turning within the distance marched at which that term is fully on
SAMPLES_PER_SEGMENT = 4000  # of the target spacing, per corner-to-corner segment (integrated numerically)


def _pt(p) -> str:
    return f"({float(p[0]):.6g}, {float(p[1]):.6g})"


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def _norm(a: np.ndarray) -> np.ndarray:
    return np.hypot(a[..., 0], a[..., 1])


def _front_frame(r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Of the closed polyline r (n, 2): at each node the unit tangent (bisector of the two segments' directions),
    the unit outward normal (the tangent turned clockwise: outward for a counter-clockwise curve), the spacing
    (mean length of the two segments) and the signed turning angle (> 0 a left turn: convex for a
    counter-clockwise outline; < 0 concave)."""
    seg = np.roll(r, -1, axis=0) - r
    length = _norm(seg)
    t_out = seg / length[:, None]
    t_in = np.roll(t_out, 1, axis=0)
    turn = np.arctan2(_cross(t_in, t_out), _dot(t_in, t_out))
    t = t_in + t_out
    size = _norm(t)
    # where the polyline turns straight back the bisector of the directions is the in-segment turned left
    t = np.where(size[:, None] > 1e-12, t / np.maximum(size, 1e-300)[:, None],
                 np.column_stack([-t_in[:, 1], t_in[:, 0]]))
    normal = np.column_stack([t[:, 1], -t[:, 0]])
    return t, normal, 0.5 * (length + np.roll(length, 1)), turn


def _distance_to_polyline(p: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Distance of each point p (m, 2) from the closed polyline v (n, 2)."""
    a = v[None, :, :]
    ab = np.roll(v, -1, axis=0)[None, :, :] - a
    ap = p[:, None, :] - a
    t = np.clip(_dot(ap, ab) / np.maximum(_dot(ab, ab), 1e-300), 0.0, 1.0)
    return _norm(ap - t[..., None] * ab).min(axis=1)


# ------------------------------------------------------------------------------------------- the grid
@dataclass(frozen=True)
class GridQuality:
    """Quality report of an :class:`OGrid`.  Angles in degrees; locations (i, j) = (around, from the wall) of a cell,
    cell (i, j) having the nodes (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1).

    * ``min_area`` at ``min_area_at``: the smallest cell area (the cell Jacobian integrated over the cell).
    * ``min_jacobian_ratio``: the smallest, over the cells, of a cell's smallest corner Jacobian (the cross product
      of the two sides that meet at a corner) over its largest: 1 for a parallelogram, > 0 for a convex cell.
    * ``max_skewness_deg`` at ``max_skewness_at``: the largest deviation of a cell's corner angle from 90 degrees.
      At a corner of the outline the two cells at the wall are skewed by half the corner's turning angle at least
      (45 degrees at a square corner: one node, one grid line along the bisector).
    * ``max_aspect_ratio`` at ``max_aspect_ratio_at``: the larger over the smaller of a cell's width (mean length of
      its two sides along i) and height (area over width).
    * ``max_width_ratio``: the largest ratio of the widths of two neighbouring cells of a layer (smoothness around).
    * ``max_wall_angle_deg`` at ``max_wall_angle_at`` (an i): the largest angle between a first grid line (node
      j = 0 to j = 1) and the wall normal (bisector of the normals of the two wall segments at the node), the
      corner nodes excepted.
    * ``max_growth_ratio``, ``min_growth_ratio``: of the lengths of consecutive edges along each line i (from node
      j to j + 1, then j + 1 to j + 2), over all lines.
    * ``first_height_min``, ``first_height_max``: the distance of the nodes j = 1 from the wall (the polygon of
      the nodes j = 0), over all i.
    """

    min_area: float
    min_area_at: tuple[int, int]
    min_jacobian_ratio: float
    max_skewness_deg: float
    max_skewness_at: tuple[int, int]
    max_aspect_ratio: float
    max_aspect_ratio_at: tuple[int, int]
    max_width_ratio: float
    max_wall_angle_deg: float
    max_wall_angle_at: int
    max_growth_ratio: float
    min_growth_ratio: float
    first_height_min: float
    first_height_max: float

    def summary(self) -> str:
        """The report in a few lines."""
        return (f"min cell area {self.min_area:.3e} at (i, j) = {self.min_area_at}, min corner-Jacobian ratio "
                f"{self.min_jacobian_ratio:.3f}\n"
                f"max skewness {self.max_skewness_deg:.1f} deg at {self.max_skewness_at}, max aspect ratio "
                f"{self.max_aspect_ratio:.1f} at {self.max_aspect_ratio_at}, max width ratio of neighbours "
                f"{self.max_width_ratio:.2f}\n"
                f"first grid line off the wall normal by {self.max_wall_angle_deg:.2f} deg at most (i = "
                f"{self.max_wall_angle_at}, corners excepted)\n"
                f"wall-normal growth ratio {self.min_growth_ratio:.4f} to {self.max_growth_ratio:.4f}, first height "
                f"{self.first_height_min:.4e} to {self.first_height_max:.4e}")


@dataclass(frozen=True, eq=False)
class OGrid:
    """Structured body-fitted O-grid.  ``x``, ``y``: node coordinates, shape ``(n_normal + 1, n_around)``, row j = 0
    on the wall, row j = n_normal the outer boundary, column i periodic (node n_around is node 0, not stored).
    ``corners``: the columns i whose wall node is a corner of the outline (sorted).

    With i counter-clockwise around the body and j outwards, (xi, eta) = (i, j) is a left-handed frame: the
    Jacobian x_eta y_xi - x_xi y_eta is positive, and so are the cell areas reported here.  Checked on
    construction: shapes, finite values, and every cell a convex quadrilateral (``ValueError`` naming the cell).
    """

    x: np.ndarray
    y: np.ndarray
    corners: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        x = np.array(self.x, dtype=np.float64)
        y = np.array(self.y, dtype=np.float64)
        if x.ndim != 2 or x.shape != y.shape or x.shape[0] < 2 or x.shape[1] < 3:
            raise ValueError(f"x, y: need the same shape (n_normal + 1 >= 2, n_around >= 3), got {x.shape} and "
                             f"{y.shape}")
        finite = np.isfinite(x) & np.isfinite(y)
        if not finite.all():
            j, i = np.argwhere(~finite)[0]
            raise ValueError(f"x, y: node (i, j) = ({i}, {j}) is not finite")
        corners = tuple(sorted(int(c) for c in self.corners))
        if any(c < 0 or c >= x.shape[1] for c in corners):
            raise ValueError(f"corners: column indices in [0, {x.shape[1]}) needed, got {corners}")
        x.flags.writeable = False
        y.flags.writeable = False
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "corners", corners)
        jac = _corner_jacobians(self.nodes)
        bad = jac.min(axis=0) <= 0.0
        if bad.any():
            j, i = np.argwhere(bad)[0]
            raise ValueError(f"folded grid: cell (i, j) = ({i}, {j}), nodes {_cell_nodes(self.nodes, i, j)}, is not a "
                             f"convex quadrilateral (smallest corner Jacobian {jac[:, j, i].min():.3e})")

    @property
    def n_around(self) -> int:
        return self.x.shape[1]

    @property
    def n_normal(self) -> int:
        """Number of cells from the wall to the outer boundary."""
        return self.x.shape[0] - 1

    @property
    def nodes(self) -> np.ndarray:
        """(n_normal + 1, n_around, 2) node coordinates."""
        return np.stack([self.x, self.y], axis=-1)

    def cell_areas(self) -> np.ndarray:
        """(n_normal, n_around) area of each cell (shoelace over its four nodes), > 0."""
        a, b, c, d = _cell_corners(self.nodes)
        return 0.5 * _cross(c - a, d - b)

    def cell_centres(self) -> np.ndarray:
        """(n_normal, n_around, 2) centroid of each cell (of its two triangles, weighted by their areas)."""
        a, b, c, d = _cell_corners(self.nodes)
        a1 = _cross(b - a, c - a)[..., None]
        a2 = _cross(c - a, d - a)[..., None]
        return (a1 * (a + b + c) + a2 * (a + c + d)) / (3.0 * (a1 + a2))

    def wall_normals(self) -> np.ndarray:
        """(n_around, 2) unit outward normal at each wall node: the bisector of the two wall segments' normals."""
        return _front_frame(self.nodes[0])[1]

    def quality(self) -> GridQuality:
        """The quality report (:class:`GridQuality`)."""
        p = self.nodes
        jac = _corner_jacobians(p)
        area = self.cell_areas()
        corners = _cell_corners(p)
        a, b, c, d = corners

        skew = np.zeros(area.shape)
        for k in range(4):  # the angle at each corner, between the sides to the next and to the previous corner
            u, w = corners[(k + 1) % 4] - corners[k], corners[k - 1] - corners[k]
            skew = np.maximum(skew, np.abs(np.degrees(np.arctan2(_cross(u, w), _dot(u, w))) - 90.0))

        width = 0.5 * (_norm(d - a) + _norm(c - b))  # along i
        height = area / width
        aspect = np.maximum(width / height, height / width)
        neighbours = width / np.roll(width, 1, axis=1)

        first = p[1] - p[0]
        normals = self.wall_normals()
        wall_angle = np.degrees(np.arctan2(np.abs(_cross(normals, first)), _dot(normals, first)))
        wall_angle[list(self.corners)] = 0.0
        iw = int(np.argmax(wall_angle))

        edge = _norm(np.diff(p, axis=0))  # (n_normal, n_around): along each line i
        growth = edge[1:] / edge[:-1] if len(edge) > 1 else np.ones((1, 1))
        first_height = _distance_to_polyline(p[1], p[0])

        def at(values: np.ndarray, pick) -> tuple[float, tuple[int, int]]:
            j, i = np.unravel_index(pick(values), values.shape)
            return float(values[j, i]), (int(i), int(j))

        return GridQuality(*at(area, np.argmin), float((jac.min(axis=0) / jac.max(axis=0)).min()),
                           *at(skew, np.argmax), *at(aspect, np.argmax),
                           float(np.maximum(neighbours, 1.0 / neighbours).max()),
                           float(wall_angle[iw]), iw, float(growth.max()), float(growth.min()),
                           float(first_height.min()), float(first_height.max()))


def _cell_corners(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The four corners of every cell of the nodes p (n_normal + 1, n_around, 2), each (n_normal, n_around, 2), in
    the order (i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j): counter-clockwise for a valid cell."""
    q = np.roll(p, -1, axis=1)
    return p[:-1], p[1:], q[1:], q[:-1]


def _corner_jacobians(p: np.ndarray) -> np.ndarray:
    """(4, n_normal, n_around): at each corner of each cell, the cross product of the side to the next corner with
    the side to the previous one (counter-clockwise order), all > 0 for a convex cell."""
    c = _cell_corners(p)
    return np.stack([_cross(c[(k + 1) % 4] - c[k], c[k - 1] - c[k]) for k in range(4)])


def _cell_nodes(p: np.ndarray, i: int, j: int) -> str:
    k = (i + 1) % p.shape[1]
    return ", ".join(_pt(p[jj, ii]) for ii, jj in ((i, j), (k, j), (k, j + 1), (i, j + 1)))


# ------------------------------------------------------------------------------------------- the wall
def _checked_outline(outline) -> np.ndarray:
    """The outline's vertices (n, 2) without a closing repeat or repeated points; ValueError for one that has fewer
    than 3 points, is not finite, crosses itself or is clockwise (bridge.cfd.outline.check_ring says where)."""
    p = np.asarray(outline, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 3:
        raise ValueError(f"outline: need vertices of shape (n >= 3, 2), got shape {p.shape}")
    labels = tuple(f"point {k}" for k in range(len(p)))
    try:
        v, _ = check_ring(Ring(p, labels, "outline", closed=True))
    except ValueError as err:  # an OutlineError: where and why, as a plain ValueError of this library
        raise ValueError(str(err)) from None
    area = signed_area(p)
    if area < 0:
        raise ValueError(f"outline: clockwise (signed area {area:.6g} < 0): give the vertices counter-clockwise, the "
                         "body on the left of each edge (as Polygon.vertices)")
    return v


def _target_spacing(s: np.ndarray, fine_s: np.ndarray, fine: np.ndarray, far: float, rate: float,
                    perimeter: float) -> np.ndarray:
    """Target node spacing at arc positions s: the smallest of ``far`` and, for each refined point at arc position
    fine_s, its spacing far / fine growing by ``rate`` per unit of distance along the outline (either way round).
    A spacing that grows linearly, a + rate d, puts the nodes in a geometric progression of ratio exp(rate)."""
    if len(fine_s) == 0:
        return np.full(s.shape, far)
    d = np.abs(s[:, None] - fine_s[None, :])
    d = np.minimum(d, perimeter - d)
    return np.minimum(far, (far / fine[None, :] + rate * d).min(axis=1))


def wall_points(outline, n_around: int, *, corner_refinement: float = 8.0, corner_angle_deg: float = CORNER_ANGLE_DEG,
                spacing_ratio: float = 1.2) -> tuple[np.ndarray, np.ndarray]:
    """``n_around`` nodes on the closed counter-clockwise ``outline`` (n, 2) and the indices of those that are its
    corners, counter-clockwise from the first corner (from vertex 0 if it has none); see the module docstring.

    A convex corner of turning angle t (or a bend: a curve turning by t > ``corner_angle_deg`` within one mean
    spacing) gets the spacing far / (1 + (corner_refinement - 1) min(1, t / 90 deg)), a concave one the far
    spacing; the spacing grows away from them by ``spacing_ratio`` from node to node, up to the far spacing.
    Raises ValueError for a bad outline or argument."""
    v = _checked_outline(outline)
    if isinstance(n_around, bool) or not isinstance(n_around, (int, np.integer)) or n_around < 8:
        raise ValueError(f"n_around = {n_around!r}: an integer >= 8 needed")
    if not 1.0 <= corner_refinement <= 100.0:
        raise ValueError(f"corner_refinement = {corner_refinement!r}: must lie in [1, 100]")
    if not 0.0 < corner_angle_deg < 180.0:
        raise ValueError(f"corner_angle_deg = {corner_angle_deg!r}: must lie in (0, 180)")
    if not 1.0 < spacing_ratio <= 1.5:
        raise ValueError(f"spacing_ratio = {spacing_ratio!r}: must lie in (1, 1.5]")
    turn = _front_frame(v)[3]
    is_corner = np.abs(turn) > np.radians(corner_angle_deg)
    if 2 * int(is_corner.sum()) > n_around:
        raise ValueError(f"n_around = {n_around}: the outline has {int(is_corner.sum())} corners (turning angle over "
                         f"{corner_angle_deg:g} deg); give at least two wall nodes per corner")
    start = int(np.argmax(is_corner)) if is_corner.any() else 0
    v, turn, is_corner = (np.roll(a, -start, axis=0) for a in (v, turn, is_corner))
    closed = np.vstack([v, v[:1]])
    arc = np.concatenate([[0.0], np.cumsum(_norm(np.diff(closed, axis=0)))])
    perimeter = float(arc[-1])
    corner_s = arc[:-1][is_corner]
    # a curve that turns by more than corner_angle_deg within one mean spacing (a round plate end) is refined like a
    # corner, at each of its vertices, though they need not be nodes
    bend = np.where(is_corner, turn, _window_sum(v, turn, perimeter / n_around))
    refined = np.abs(bend) > np.radians(corner_angle_deg)
    # convex corners only: lines converge at a concave one, where a spacing below the layer heights folds the grid
    fine = 1.0 + (corner_refinement - 1.0) * np.clip(bend[refined] / (0.5 * np.pi), 0.0, 1.0)
    rate = np.log(spacing_ratio)
    bounds = np.append(corner_s, perimeter) if len(corner_s) else np.array([0.0, perimeter])
    samples = [np.linspace(a, b, SAMPLES_PER_SEGMENT + 1) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]

    def cumulative(s: np.ndarray, far: float) -> np.ndarray:  # nodes from the segment's start to each s (real)
        density = 1.0 / _target_spacing(s, arc[:-1][refined], fine, far, rate, perimeter)
        return np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(s))])

    def count(far: float) -> float:
        return sum(cumulative(s, far)[-1] for s in samples) - n_around

    if refined.any() and count(perimeter) > 0:  # the clustering alone takes more nodes than there are
        raise ValueError(f"n_around = {n_around}: too few for the clustering at {int(refined.sum())} corners or bends "
                         f"(corner_refinement = {corner_refinement:g}, spacing_ratio = {spacing_ratio:g}), which "
                         f"takes {count(perimeter) + n_around:.0f}: give more nodes or a smaller corner_refinement")
    far = perimeter / n_around if not refined.any() else \
        brentq(count, 0.5 * perimeter / n_around, perimeter, xtol=1e-12 * perimeter)
    real = np.array([cumulative(s, far)[-1] for s in samples])
    n_seg = np.maximum(1, np.floor(real).astype(int))
    while n_seg.sum() < n_around:  # the largest remainders get the nodes left over
        n_seg[np.argmax(real - n_seg)] += 1
    while n_seg.sum() > n_around:  # (only if some segment was raised to 1)
        n_seg[np.argmin(np.where(n_seg > 1, real - n_seg, np.inf))] -= 1
    s_nodes = []
    for s, n in zip(samples, n_seg, strict=True):
        cum = cumulative(s, far)
        s_nodes.append(np.interp(np.arange(n) * cum[-1] / n, cum, s))
    corners = np.cumsum([0] + [len(s) for s in s_nodes[:-1]]) if is_corner.any() else np.zeros(0, dtype=int)
    s_all = np.concatenate(s_nodes)
    points = np.column_stack([np.interp(s_all, arc, closed[:, 0]), np.interp(s_all, arc, closed[:, 1])])
    return points, np.asarray(corners, dtype=int)


# ------------------------------------------------------------------------------------------- the layers
def layer_heights(first_height: float, growth: float, outer_distance: float) -> np.ndarray:
    """Heights of the layers from the wall out: ``first_height``, then each ``growth`` times the last (``growth`` in
    [1, MAX_GROWTH]), as many as reach ``outer_distance``; the ratio is then lowered to the one whose heights add
    up to ``outer_distance`` exactly (if that would take a ratio below 1, the last layer is shortened instead)."""
    if not (np.isfinite(growth) and 1.0 <= growth <= MAX_GROWTH):
        raise ValueError(f"growth = {growth!r}: the wall-normal growth ratio must lie in [1, {MAX_GROWTH}]")
    if not (np.isfinite(first_height) and first_height > 0):
        raise ValueError(f"first_height = {first_height!r}: must be > 0")
    if not (np.isfinite(outer_distance) and outer_distance > first_height):
        raise ValueError(f"outer_distance = {outer_distance!r}: must be > first_height = {first_height!r}")

    def total(g: float, n: int) -> float:
        return first_height * n if g == 1.0 else first_height * (g**n - 1.0) / (g - 1.0)

    layers = outer_distance / first_height if growth == 1.0 else \
        np.log1p(outer_distance * (growth - 1.0) / first_height) / np.log(growth)
    n = int(np.ceil(layers - 1e-9))  # the fewest that reach outer_distance (>= 2, as outer_distance > first_height)
    if total(1.0, n) < outer_distance < total(growth, n):  # a ratio in (1, growth) adds up exactly
        g = brentq(lambda q: total(q, n) - outer_distance, 1.0 + 1e-14, growth, xtol=1e-15, rtol=1e-15)
        return first_height * g ** np.arange(n)
    h = first_height * growth ** np.arange(n, dtype=float)
    h[-1] = outer_distance - h[:-1].sum()
    return h


# ------------------------------------------------------------------------------------------- marching
def _crossing(r: np.ndarray) -> tuple[int, int] | None:
    """A pair of segments (k, m), k < m, not neighbours, of the closed polyline r (n, 2) that cross or touch; None if
    the polyline is simple."""
    n = len(r)
    a, b = r, np.roll(r, -1, axis=0)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    m = np.arange(n)
    for k0 in range(0, n, 256):
        k = np.arange(k0, min(n, k0 + 256))
        near = ((lo[k, None, 0] <= hi[None, :, 0]) & (lo[None, :, 0] <= hi[k, None, 0])
                & (lo[k, None, 1] <= hi[None, :, 1]) & (lo[None, :, 1] <= hi[k, None, 1]))
        gap = m[None, :] - k[:, None]
        near &= (gap > 1) & (gap < n - 1)  # each pair once, neighbours (which share a node) excepted
        kk, mm = np.nonzero(near)
        if kk.size == 0:
            continue
        kk = k[kk]
        p1, p2, q1, q2 = a[kk], b[kk], a[mm], b[mm]
        hit = ((_cross(q2 - q1, p1 - q1) * _cross(q2 - q1, p2 - q1) <= 0)
               & (_cross(p2 - p1, q1 - p1) * _cross(p2 - p1, q2 - p1) <= 0))
        if hit.any():
            h = int(np.argmax(hit))
            return int(kk[h]), int(mm[h])
    return None


def _window_sum(r: np.ndarray, values: np.ndarray, half_width: float) -> np.ndarray:
    """At each node of the closed polyline r (n, 2), the sum of ``values`` (n,) over the nodes within ``half_width``
    of it along the polyline."""
    seg = _norm(np.roll(r, -1, axis=0) - r)
    perimeter = seg.sum()
    arc = np.concatenate([[0.0], np.cumsum(seg[:-1])])
    w = min(half_width, 0.5 * perimeter)
    ext = np.concatenate([arc - perimeter, arc, arc + perimeter])
    cum = np.concatenate([[0.0], np.cumsum(np.tile(values, 3))])
    return cum[np.searchsorted(ext, arc + w, side="right")] - cum[np.searchsorted(ext, arc - w, side="left")]


def _periodic_block_solve(diag: np.ndarray, upper: np.ndarray, lower: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve  lower_i u_(i-1) + diag_i u_i + upper_i u_(i+1) = rhs_i,  i periodic, 2 x 2 blocks (n, 2, 2), rhs
    (n, 2) (a sparse LU: the system is banded but for its two corner blocks)."""
    n = len(diag)
    i = np.arange(n)
    rows, cols, vals = [], [], []
    for block, shift in ((diag, 0), (upper, 1), (lower, -1)):
        col = (i + shift) % n
        for a in range(2):
            for b in range(2):
                rows.append(2 * i + a)
                cols.append(2 * col + b)
                vals.append(block[:, a, b])
    m = sparse.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(2 * n, 2 * n))
    return spsolve(m, rhs.reshape(-1)).reshape(n, 2)


def _hyperbolic_step(r: np.ndarray, h: float, layer: int, n_layers: int, distance: float,
                     spacing_before: np.ndarray | None, smoothing: float) -> tuple[np.ndarray, np.ndarray]:
    """The step dr (n, 2) from the front r (n, 2) to the next layer, of height h (module docstring, step 3), and the
    front's node spacing.  ``layer``: index of the front (0 the wall); ``distance``: marched so far."""
    tangent, normal, spacing, turn = _front_frame(r)
    # along the front's normal: h; the mitre h / cos(t/2) at a concave turn t (the offset curve's corner)
    step = h / np.cos(0.5 * np.clip(turn, -0.9 * np.pi, 0.0))
    explicit = step[:, None] * normal
    if layer == 0 or smoothing == 0.0:
        return explicit, spacing
    # linearised conditions B (r_eta - e) + A delta_xi(dr) = 0, about r_xi0 = tangent x spacing and r_eta0 = e
    xi = tangent * spacing[:, None]
    ex, ey = explicit[:, 0], explicit[:, 1]
    a_mat = np.stack([np.stack([ex, ey], -1), np.stack([-ey, ex], -1)], -2)
    b_mat = np.stack([np.stack([xi[:, 0], xi[:, 1]], -1), np.stack([xi[:, 1], -xi[:, 0]], -1)], -2)
    c_mat = b_mat @ a_mat / (spacing**2)[:, None, None]  # B^-1 A, with B^-1 = B / |r_xi|^2
    scale = np.sqrt(layer / max(n_layers - 1, 1))
    # the sensor is at least 1 (Chan and Steger let it fall to 0.1 where lines diverge: 1 keeps some smoothing in
    # the fan of a convex corner, which evens its lines out)
    sensor = np.ones_like(spacing) if spacing_before is None else \
        np.clip((spacing_before / spacing) ** (2.0 / max(scale, 0.1)), 1.0, SENSOR_MAX)
    concave = np.clip(-_window_sum(r, turn, distance) / CONCAVE_TURN, 0.0, 1.0)
    eps = smoothing * (step / spacing) * (scale * sensor + CONCAVE_FACTOR * concave * distance / spacing)
    second_difference = np.roll(r, -1, axis=0) - 2.0 * r + np.roll(r, 1, axis=0)
    # its outward normal part (a concave dent) is kept, its inward one (a convex front, which it would pull back,
    # at a corner even behind the last layer) dropped
    inward = np.minimum(_dot(second_difference, normal), 0.0)
    second_difference -= inward[:, None] * normal
    eye = np.eye(2)
    eps_i = 2.0 * eps[:, None, None]
    delta = _periodic_block_solve((1.0 + 2.0 * eps_i) * eye, 0.5 * c_mat - eps_i * eye, -0.5 * c_mat - eps_i * eye,
                                  explicit + eps[:, None] * second_difference)
    advance = _dot(delta, normal)
    if (advance <= 0.0).any():
        i = int(np.argmin(advance))
        raise ValueError(f"marching failed at layer j = {layer + 1}: node i = {i}, {_pt(r[i])}, would step back "
                         f"towards the wall (grid lines converging: a concave corner too sharp or a gap too narrow "
                         f"for layers {distance:.3g} from the wall)")
    # stretch a step that the dissipation shortened back to the length h (mitre: h / cos(t/2)); one that it
    # lengthened (a concave corner rounding off) stays
    length = _norm(delta)
    return delta * np.where(advance < step, step / length, 1.0)[:, None], spacing


def _march(wall: np.ndarray, heights: np.ndarray, smoothing: float) -> np.ndarray:
    """The nodes (len(heights) + 1, n, 2) marched out from the wall nodes (n, 2); ValueError at the first layer with
    a folded cell or a crossing."""
    n_layers = len(heights)
    nodes = np.empty((n_layers + 1, len(wall), 2))
    nodes[0] = wall
    spacing_before = None
    distance = 0.0
    for l, h in enumerate(heights):
        delta, spacing_before = _hyperbolic_step(nodes[l], h, l, n_layers, distance, spacing_before, smoothing)
        nodes[l + 1] = nodes[l] + delta
        distance += h
        jac = _corner_jacobians(nodes[l:l + 2])[:, 0]
        if (jac <= 0.0).any():
            i = int(np.argmin(jac.min(axis=0)))
            raise ValueError(f"grid folds at layer j = {l + 1}, {distance:.4g} from the wall: cell (i, j) = "
                             f"({i}, {l}), nodes {_cell_nodes(nodes, i, l)}, is not a convex quadrilateral (grid "
                             "lines cross: a concave corner too sharp or a gap too narrow for these layers; try a "
                             "larger smoothing, a coarser wall spacing there or a smaller outer_distance)")
        hit = _crossing(nodes[l + 1])
        if hit is not None:
            k, m = hit
            raise ValueError(f"layer j = {l + 1}, {distance:.4g} from the wall, crosses itself: the segment from node "
                             f"i = {k} to {k + 1} meets the one from i = {m} to {(m + 1) % len(wall)} near "
                             f"{_pt(nodes[l + 1, k])} (the layers from two parts of the outline less than about "
                             f"{2 * distance:.3g} apart meet: a gap or cavity too narrow for outer_distance)")
    return nodes


def _check_concave_corners(wall: np.ndarray, first_height: float) -> None:
    """ValueError if the first layer folds at a concave wall node: its mitre step, first_height / cos(t/2) along the
    bisector of a turn t, passes a neighbour that is closer than first_height tan(|t|/2)."""
    seg = _norm(np.roll(wall, -1, axis=0) - wall)
    nearest = np.minimum(seg, np.roll(seg, 1))
    turn = _front_frame(wall)[3]
    reach = first_height * np.tan(0.5 * np.clip(-turn, 0.0, 0.9 * np.pi))
    bad = np.nonzero(nearest <= reach)[0]
    if bad.size:
        i = int(bad[np.argmax((reach / nearest)[bad])])
        raise ValueError(f"first_height = {first_height:g} is too large for the concave corner at {_pt(wall[i])} (wall "
                         f"node i = {i}, turning {np.degrees(-turn[i]):.1f} deg inwards): its neighbour is "
                         f"{nearest[i]:.3g} away, and the first layer's lines cross unless first_height < "
                         f"{nearest[i] / np.tan(0.5 * -turn[i]):.3g} (or the wall spacing there is larger: fewer "
                         "nodes)")


# ------------------------------------------------------------------------------------------- the builder
def o_grid(outline, n_around: int, first_height: float, growth: float, outer_distance: float, *,
           corner_refinement: float = 8.0, corner_angle_deg: float = CORNER_ANGLE_DEG, spacing_ratio: float = 1.2,
           smoothing: float = 0.5) -> OGrid:
    """Body-fitted O-grid around ``outline`` (n, 2), a closed counter-clockwise polygon such as
    ``Polygon.vertices`` (module docstring).

    ``n_around`` wall nodes (:func:`wall_points`, with ``corner_refinement``, ``corner_angle_deg`` and
    ``spacing_ratio``); layers from ``first_height``, growing by ``growth`` (in [1, MAX_GROWTH]) out to
    ``outer_distance`` from the wall (:func:`layer_heights`); hyperbolic marching with the dissipation coefficient
    ``smoothing`` (0: none, pure normal extrusion, which folds at concave corners; larger values fan the lines at
    corners out sooner, at some cost in orthogonality away from the wall).  Raises ``ValueError`` saying where and
    why for an argument out of range, an outline that cannot be meshed (fewer than 3 points, crossing itself,
    clockwise) and layers that would fold or cross (a concave corner too sharp, a gap too narrow).
    """
    if not (np.isfinite(smoothing) and 0.0 <= smoothing <= 10.0):
        raise ValueError(f"smoothing = {smoothing!r}: must lie in [0, 10]")
    heights = layer_heights(first_height, growth, outer_distance)
    wall, corners = wall_points(outline, n_around, corner_refinement=corner_refinement,
                                corner_angle_deg=corner_angle_deg, spacing_ratio=spacing_ratio)
    hit = _crossing(wall)
    if hit is not None:  # the wall nodes cut across the outline (a thin part resolved by too few nodes)
        k, m = hit
        raise ValueError(f"the wall nodes cross: the chords from node i = {k} to {k + 1} and from i = {m} to "
                         f"{(m + 1) % len(wall)}, near {_pt(wall[k])}, meet (give more nodes, n_around = {n_around})")
    _check_concave_corners(wall, heights[0])
    nodes = _march(wall, heights, smoothing)
    return OGrid(nodes[..., 0], nodes[..., 1], tuple(int(c) for c in corners))
