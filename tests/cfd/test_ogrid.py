"""Body-fitted O-grid generator (bridge/cfd/ogrid.py): the circle's grid is the polar grid (radii, radial lines and
cell areas in closed form); the first height and the growth ratio are honoured on the Great Belt box and the 2 %
plate; on every shape (circle, square, plate, box, the shipped asymmetric outline, an L with a concave corner) the
lines leave the wall orthogonally, every cell is valid, the corners are nodes and the outer boundary lies at the
outer distance without kinks; the quality report in closed form on a twisted polar grid; every bad input refused
with a message that says where and why.  Geometry in the tests is computed here, independently of the module."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bridge.cfd import circle
from bridge.cfd.ogrid import MAX_GROWTH, OGrid, layer_heights, o_grid, wall_points
from bridge.cfd.sections import SECTIONS, FlatPlate, PolygonSection, Rectangle, great_belt_section

REPO = Path(__file__).resolve().parents[2]

FIRST, GROWTH, OUTER = 1e-3, 1.1, 0.35  # chord 1: the brief's case
N_AROUND = 256


def unit_outline(section) -> np.ndarray:
    """The unit-chord outline the CFD uses."""
    return section.polygons()[0].vertices / section.chord_m


SHAPES = {
    "circle": circle(1.0, 128).vertices,
    "square": np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]),
    "plate_2pc": unit_outline(FlatPlate(1.0, 0.02)),
    "plate_round_ends": unit_outline(FlatPlate(1.0, 0.02, ends="round")),  # curved, no corner: refined all the same
    "rectangle_5_1": unit_outline(Rectangle(5.0, 1.0)),
    "great_belt": unit_outline(great_belt_section()),
    "asymmetric_box": unit_outline(PolygonSection(outline_path=str(REPO / "scenarios/outlines/asymmetric_box.csv"))),
    # a 90-degree concave corner at (0.4, 0.4)
    "L": np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.4], [0.4, 0.4], [0.4, 1.0], [0.0, 1.0]]),
}
SECTION_EXAMPLES = {"flat_plate": ["plate_2pc", "plate_round_ends"], "rectangle": ["rectangle_5_1"],
                    "streamlined_box": ["great_belt"], "polygon": ["asymmetric_box"]}
_GRIDS: dict[str, OGrid] = {}


def grid(name: str) -> OGrid:
    """The brief's grid around SHAPES[name] (built once per session)."""
    if name not in _GRIDS:
        n = len(SHAPES["circle"]) if name == "circle" else N_AROUND
        _GRIDS[name] = o_grid(SHAPES[name], n, FIRST, GROWTH, OUTER)
    return _GRIDS[name]


def test_every_registered_section_shape_is_meshed_here():
    assert set(SECTION_EXAMPLES) == set(SECTIONS)
    assert all(name in SHAPES for names in SECTION_EXAMPLES.values() for name in names)


# ------------------------------------------------------------------ independent geometry
def distance_to_outline(points: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Distance of each point from the closed polygon v."""
    out = np.full(len(points), np.inf)
    for a, b in zip(v, np.roll(v, -1, axis=0), strict=True):
        t = np.clip(((points - a) @ (b - a)) / ((b - a) @ (b - a)), 0.0, 1.0)
        out = np.minimum(out, np.linalg.norm(points - a - t[:, None] * (b - a), axis=1))
    return out


def turning_deg(r: np.ndarray) -> np.ndarray:
    """Signed turning angle at each vertex of the closed polyline r (> 0 left)."""
    a = np.roll(r, -1, axis=0) - r
    b = np.roll(a, 1, axis=0)
    return np.degrees(np.arctan2(b[:, 0] * a[:, 1] - b[:, 1] * a[:, 0], (b * a).sum(axis=1)))


def outward_normals(r: np.ndarray) -> np.ndarray:
    """At each node of a counter-clockwise closed polyline: the bisector of its two segments' outward normals."""
    seg = np.roll(r, -1, axis=0) - r
    n_out = np.column_stack([seg[:, 1], -seg[:, 0]]) / np.linalg.norm(seg, axis=1)[:, None]
    n = n_out + np.roll(n_out, 1, axis=0)
    return n / np.linalg.norm(n, axis=1)[:, None]


# ------------------------------------------------------------------ the circle: the polar grid in closed form
def test_circle_grid_is_the_polar_grid():
    v = SHAPES["circle"]
    n = len(v)
    radius = np.hypot(*v[0])
    # an outer distance that the nominal ratio reaches in 40 layers: the heights are h g^j exactly
    outer = FIRST * (GROWTH**40 - 1) / (GROWTH - 1)
    g = o_grid(v, n, FIRST, GROWTH, outer)
    assert g.n_normal == 40 and g.n_around == n and g.corners == ()
    j = np.arange(41)[:, None]
    r_expected = radius + FIRST * (GROWTH**j - 1) / (GROWTH - 1)
    assert np.max(np.abs(np.hypot(g.x, g.y) - r_expected)) < 1e-12
    theta = np.angle(v[:, 0] + 1j * v[:, 1])  # every line radial: the angle of its wall vertex
    assert np.max(np.abs(np.angle(np.exp(1j * (np.angle(g.x + 1j * g.y) - theta))))) < 1e-12
    area = 0.5 * (r_expected[1:] ** 2 - r_expected[:-1] ** 2) * np.sin(2 * np.pi / n)  # two triangles of a sector
    assert np.allclose(g.cell_areas(), np.broadcast_to(area, (40, n)), rtol=1e-10, atol=0)
    q = g.quality()
    assert q.max_wall_angle_deg < 1e-8
    assert abs(q.max_skewness_deg - 180.0 / n) < 1e-8  # an isosceles trapezoid: 90 +- half the sector angle
    assert abs(q.max_growth_ratio - GROWTH) < 1e-9 and abs(q.min_growth_ratio - GROWTH) < 1e-9


# ------------------------------------------------------------------ first height and growth
@pytest.mark.parametrize("name", ["great_belt", "plate_2pc"])
def test_first_height_and_growth_are_honoured(name):
    g = grid(name)
    wall = g.nodes[0]
    first = distance_to_outline(g.nodes[1], wall)  # from the grid's wall polygon
    assert np.allclose(first, FIRST, rtol=1e-9, atol=0)
    # which cuts a vertex that is no corner (the box's crown, 2.3 degrees) by a hair's breadth
    assert np.allclose(distance_to_outline(g.nodes[1], SHAPES[name]), FIRST, rtol=1e-4, atol=0)
    edges = np.linalg.norm(np.diff(g.nodes, axis=0), axis=2)
    assert np.allclose(edges[0], FIRST, rtol=1e-9, atol=0)  # also along the line: the first step is normal
    heights = layer_heights(FIRST, GROWTH, OUTER)
    ratio = heights[1] / heights[0]
    assert 1.09 < ratio <= GROWTH and g.n_normal == len(heights)
    growth = edges[1:] / edges[:-1]
    assert np.all(np.abs(growth - ratio) < 0.01), (growth.min(), growth.max())
    q = g.quality()
    assert q.first_height_min == pytest.approx(FIRST, rel=1e-9) and q.first_height_max == pytest.approx(FIRST, rel=1e-9)
    assert q.max_growth_ratio == pytest.approx(growth.max()) and q.max_growth_ratio < GROWTH + 0.01
    assert np.all(distance_to_outline(wall, SHAPES[name]) < 1e-12)  # the wall nodes lie on the outline


# ------------------------------------------------------------------ every shape: orthogonal, valid, outer boundary
@pytest.mark.parametrize("name", list(SHAPES))
def test_lines_leave_the_wall_orthogonally_and_every_cell_is_valid(name):
    g = grid(name)
    p = g.nodes
    first = p[1] - p[0]
    normal = outward_normals(p[0])
    angle = np.degrees(np.arctan2(np.abs(normal[:, 0] * first[:, 1] - normal[:, 1] * first[:, 0]),
                                  np.sum(first * normal, axis=1)))
    off_corner = np.setdiff1d(np.arange(g.n_around), g.corners)
    assert angle[off_corner].max() < 2.0
    assert g.quality().max_wall_angle_deg == pytest.approx(angle[off_corner].max(), abs=1e-9)
    # at a corner the line leaves along the bisector, too (the outline's two sides there)
    assert angle[list(g.corners)].max(initial=0.0) < 2.0
    # every cell convex with positive area: the cross products at its four corners (i, j), (i, j+1), (i+1, j+1),
    # (i+1, j), counter-clockwise for a valid cell of this left-handed (i, j) frame
    q = np.roll(p, -1, axis=1)
    c = [p[:-1], p[1:], q[1:], q[:-1]]
    def cross(a, b):
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]

    corner_jacobians = [cross(c[(k + 1) % 4] - c[k], c[k - 1] - c[k]) for k in range(4)]
    assert min(x.min() for x in corner_jacobians) > 0
    assert g.cell_areas().min() > 0 and g.quality().min_area == pytest.approx(g.cell_areas().min())
    # every corner of the outline (turning > 15 degrees) is a wall node
    v = SHAPES[name]
    corners = v[np.abs(turning_deg(v)) > 15.0]
    assert len(corners) == len(g.corners)
    for corner in corners:
        assert np.min(np.linalg.norm(p[0][list(g.corners)] - corner, axis=1)) < 1e-12


@pytest.mark.parametrize("name", list(SHAPES))
def test_outer_boundary_reaches_the_outer_distance_without_kinks(name):
    g = grid(name)
    outer = g.nodes[-1]
    assert distance_to_outline(outer, SHAPES[name]).min() > 0.95 * OUTER
    turn = turning_deg(outer)
    # n_around = 256: a rounded offset curve, no kink; convex around a convex outline, nearly so around the L
    assert turn.max() < 20.0 and turn.min() > (-8.0 if name == "L" else -0.5)
    # and the lines come out smoothly: neighbouring cells of a layer differ in width by a factor < 2.5
    assert g.quality().max_width_ratio < 2.5


def test_pure_normal_extrusion_folds_at_the_concave_corner():
    """The control: without the dissipation the L's lines cross near (0.4, 0.4)."""
    with pytest.raises(ValueError, match=r"folds at layer j = \d+.*\(0\.4"):
        o_grid(SHAPES["L"], N_AROUND, FIRST, GROWTH, OUTER, smoothing=0.0)


# ------------------------------------------------------------------ wall nodes and layer heights
def test_wall_points_cluster_at_corners_smoothly():
    v = SHAPES["plate_2pc"]
    points, corners = wall_points(v, N_AROUND, corner_refinement=8.0, spacing_ratio=1.2)
    assert points.shape == (N_AROUND, 2) and corners.tolist()[0] == 0 and len(corners) == 4
    assert np.allclose(points[corners], v)  # vertex order kept, from the first corner
    ds = np.linalg.norm(np.roll(points, -1, axis=0) - points, axis=1)
    ratio = ds / np.roll(ds, 1)
    assert np.max(np.maximum(ratio, 1 / ratio)) < 1.25
    assert 6.0 < ds.max() / ds[corners].min() < 10.0  # corner_refinement 8 at a square corner
    # a round plate end (16 segments of 11.25 degrees: no corner) is refined as a bend; the L's concave corner not
    round_ends, round_corners = wall_points(SHAPES["plate_round_ends"], N_AROUND)
    dr = np.linalg.norm(np.roll(round_ends, -1, axis=0) - round_ends, axis=1)
    assert len(round_corners) == 0 and dr[np.abs(round_ends[:, 0]) > 0.49].max() < dr.max() / 4
    ell, ell_corners = wall_points(SHAPES["L"], N_AROUND)
    dl = np.linalg.norm(np.roll(ell, -1, axis=0) - ell, axis=1)
    concave = ell_corners[np.argmin(np.linalg.norm(ell[ell_corners] - [0.4, 0.4], axis=1))]
    assert dl[concave] == pytest.approx(dl.max(), rel=0.05) and dl[ell_corners].min() < dl.max() / 6
    # corner_refinement 1: no clustering
    uniform, _ = wall_points(SHAPES["square"], 64, corner_refinement=1.0)
    d = np.linalg.norm(np.roll(uniform, -1, axis=0) - uniform, axis=1)
    assert np.allclose(d, 4.0 / 64)


def test_layer_heights_add_up_with_the_growth_never_raised():
    h = layer_heights(FIRST, GROWTH, OUTER)
    assert h[0] == FIRST and h.sum() == pytest.approx(OUTER, rel=1e-12)
    r = h[1:] / h[:-1]
    assert np.allclose(r, r[0]) and r[0] <= GROWTH
    assert layer_heights(FIRST, GROWTH, OUTER * 0.999).size == h.size  # the fewest layers that reach it
    u = layer_heights(0.01, 1.0, 0.105)
    assert np.allclose(u[:-1], 0.01) and u.sum() == pytest.approx(0.105) and 0 < u[-1] <= 0.01


# ------------------------------------------------------------------ the quality report in closed form
def test_quality_report_of_a_twisted_polar_grid():
    """Layer j: a regular n-gon of radius q^j turned by j phi.  Every cell is the same shape scaled and turned, so
    with gamma = arg(q e^{i phi} - 1): corner angles 90 + dth/2 -+ gamma and 90 - dth/2 +- (gamma - phi), skewness
    dth/2 + gamma; first lines off the radial normal by gamma; edges along a line |q e^{i phi} - 1| q^j (growth q);
    cell area (q^2j+2 - q^2j) sin(dth) / 2 (the twist cancels)."""
    n, layers, q, phi = 48, 12, 1.15, np.radians(3.0)
    dth = 2 * np.pi / n
    j = np.arange(layers + 1)[:, None]
    z = q**j * np.exp(1j * (dth * np.arange(n)[None, :] + j * phi))
    g = OGrid(z.real, z.imag)
    gamma = np.angle(q * np.exp(1j * phi) - 1)
    report = g.quality()
    assert report.max_skewness_deg == pytest.approx(np.degrees(dth / 2 + gamma), abs=1e-9)
    assert report.max_wall_angle_deg == pytest.approx(np.degrees(gamma), abs=1e-9)
    assert report.max_growth_ratio == pytest.approx(q, rel=1e-12) and report.min_growth_ratio == pytest.approx(q)
    area = 0.5 * (q ** (2 * j[1:]) - q ** (2 * j[:-1])) * np.sin(dth)
    assert np.allclose(g.cell_areas(), np.broadcast_to(area, (layers, n)), rtol=1e-12)
    assert report.min_area == pytest.approx(area.min()) and report.min_area_at[1] == 0
    width = 2 * np.sin(dth / 2) * (1 + q) / 2  # mean of the two sides along i, layer 0
    height = area[0, 0] / width
    assert report.max_aspect_ratio == pytest.approx(max(width / height, height / width), rel=1e-9)
    assert report.max_width_ratio == pytest.approx(1.0)
    # the centroid of each cell lies inside it, between its inner and outer radius
    rc = np.abs(g.cell_centres() @ np.array([1.0, 1j]))
    assert np.all((rc > np.abs(z[:-1])) & (rc < np.abs(z[1:])))


def test_first_height_is_the_distance_from_the_wall():
    """On the twisted grid the first node lies off the wall node's normal: its distance from the wall polygon (the
    nodes j = 0) is the perpendicular height, smaller than the edge."""
    n, q, phi = 64, 1.05, np.radians(5.0)
    j = np.arange(3)[:, None]
    z = q**j * np.exp(1j * (2 * np.pi * np.arange(n)[None, :] / n + j * phi))
    report = OGrid(z.real, z.imag).quality()
    wall = np.column_stack([z[0].real, z[0].imag])
    first = distance_to_outline(np.column_stack([z[1].real, z[1].imag]), wall)
    assert report.first_height_min == pytest.approx(first.min(), rel=1e-12)
    assert report.first_height_max == pytest.approx(first.max(), rel=1e-12)
    assert report.first_height_max < abs(q * np.exp(1j * phi) - 1)


# ------------------------------------------------------------------ refusals: where and why
def test_growth_out_of_range_is_refused():
    with pytest.raises(ValueError, match=rf"growth = 1\.5: .* \[1, {MAX_GROWTH}\]"):
        o_grid(SHAPES["square"], 64, FIRST, 1.5, OUTER)
    with pytest.raises(ValueError, match="growth = 0.9"):
        o_grid(SHAPES["square"], 64, FIRST, 0.9, OUTER)


def test_clockwise_outline_is_refused():
    with pytest.raises(ValueError, match=r"outline: clockwise .*counter-clockwise"):
        o_grid(SHAPES["square"][::-1], 64, FIRST, GROWTH, OUTER)


def test_self_intersecting_outline_is_refused_naming_the_edges():
    bow_tie = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
    with pytest.raises(ValueError, match=r"outline: crosses itself: the edge from point 0 \(0, 0\) to point 1 "
                                         r"\(1, 1\) meets the edge from point 2 \(1, 0\) to point 3 \(0, 1\) at "
                                         r"\(0\.5, 0\.5\)"):
        o_grid(bow_tie, 64, FIRST, GROWTH, OUTER)


def test_too_few_points_and_bad_arguments_are_refused():
    with pytest.raises(ValueError, match=r"outline: need vertices of shape \(n >= 3, 2\)"):
        o_grid(np.array([[0.0, 0.0], [1.0, 0.0]]), 64, FIRST, GROWTH, OUTER)
    with pytest.raises(ValueError, match="n_around = 4"):
        o_grid(SHAPES["square"], 4, FIRST, GROWTH, OUTER)
    with pytest.raises(ValueError, match="outer_distance"):
        o_grid(SHAPES["square"], 64, FIRST, GROWTH, FIRST / 2)
    with pytest.raises(ValueError, match="smoothing"):
        o_grid(SHAPES["square"], 64, FIRST, GROWTH, OUTER, smoothing=-1.0)


def slot(width: float) -> np.ndarray:
    """A 1 x 0.2 box with a slot of ``width`` cut 0.1 deep into its top at x = 0."""
    w = width / 2
    return np.array([[-0.5, -0.1], [0.5, -0.1], [0.5, 0.1], [w, 0.1], [w, 0.0], [-w, 0.0], [-w, 0.1], [-0.5, 0.1]])


def test_a_cavity_narrower_than_the_layers_is_refused_saying_where():
    # 4 mm wide: the first layers from the two sides meet inside it
    with pytest.raises(ValueError, match=r"grid folds at layer j = \d+.*cell \(i, j\) = \(\d+, \d+\), nodes \(-?0\.00"):
        o_grid(slot(0.004), N_AROUND, FIRST, GROWTH, OUTER)
    # 20 mm wide: the layers from its walls cross about 10 mm out
    with pytest.raises(ValueError, match=r"layer j = \d+, 0\.0\d+ from the wall, crosses itself: .*node i = \d+"):
        o_grid(slot(0.02), N_AROUND, FIRST, GROWTH, OUTER)


def test_a_first_layer_taller_than_the_spacing_at_a_concave_corner_is_refused():
    with pytest.raises(ValueError, match=r"first_height = 0\.05 is too large for the concave corner at \(0\.4, 0\.4\)"):
        o_grid(SHAPES["L"], N_AROUND, 0.05, GROWTH, OUTER)


def test_a_folded_grid_cannot_be_built():
    z = (1 + 0.1 * np.arange(3)[:, None]) * np.exp(2j * np.pi * np.arange(16)[None, :] / 16)
    z[1, 5], z[1, 6] = z[1, 6], z[1, 5]  # two nodes of layer 1 swapped: their lines cross
    with pytest.raises(ValueError, match=r"folded grid: cell \(i, j\) = \(\d, [01]\)"):
        OGrid(z.real, z.imag)
