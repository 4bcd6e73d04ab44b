"""Deck sections (bridge/cfd/sections.py): closed-form geometry, a valid simple counter-clockwise
outline for every registered section, input validation naming the key, the scenario mapping, and
immersion in the CFD on a tiny grid."""

import dataclasses

import numpy as np
import pytest

from bridge.cfd import BoundaryConditions, CartesianGrid, FlowConfig, Simulation, Stationary
from bridge.cfd.sections import (
    SECTIONS,
    FlatPlate,
    PolygonSection,
    Rectangle,
    StreamlinedBox,
    great_belt_section,
    section_from_mapping,
)
from bridge.errors import InputError

# One or more instances per registered shape: test_every_registered_shape_has_examples keeps a new
# shape from going untested.
EXAMPLES = {
    "flat_plate": [FlatPlate(1.0, 0.02), FlatPlate(2.0, 0.1, ends="round")],
    "rectangle": [Rectangle(5.0, 1.0), Rectangle(1.0, 1.0)],
    "streamlined_box": [great_belt_section(), StreamlinedBox(nose_height_fraction=1.0),
                        StreamlinedBox(cross_fall=0.0, bottom_flat_fraction=0.3, top_flat_fraction=1.0),
                        StreamlinedBox(railings=True)],
    # a symmetric hexagon in its own coordinates (tests/cfd/test_polygon_sections.py has the asymmetric decks)
    "polygon": [PolygonSection(vertices=[[0.0, 2.0], [4.0, 0.0], [16.0, 0.0], [20.0, 2.0], [16.0, 4.0], [4.0, 4.0],
                                         [0.0, 2.0]])],
}
ALL = [pytest.param(s, id=f"{name}-{i}") for name, ss in EXAMPLES.items() for i, s in enumerate(ss)]


# ------------------------------------------------------------------ independent geometry helpers
def signed_area(v):
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _segments_cross(p1, p2, q1, q2):
    """Proper or touching intersection of segments p1p2 and q1q2 (orientation test)."""
    def orient(a, b, c):
        return np.sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    d1, d2, d3, d4 = orient(q1, q2, p1), orient(q1, q2, p2), orient(p1, p2, q1), orient(p1, p2, q2)
    if d1 * d2 < 0 and d3 * d4 < 0:
        return True

    def on(a, b, c):  # c on segment ab, given collinear
        return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])

    return ((d1 == 0 and on(q1, q2, p1)) or (d2 == 0 and on(q1, q2, p2))
            or (d3 == 0 and on(p1, p2, q1)) or (d4 == 0 and on(p1, p2, q2)))


def self_intersects(v):
    n = len(v)
    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):  # adjacent edges share a vertex
                continue
            if _segments_cross(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n]):
                return True
    return False


def contains(v, point):
    """Ray casting to +x."""
    x, y = point
    inside = False
    for (x1, y1), (x2, y2) in zip(v, np.roll(v, -1, axis=0), strict=True):
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


def test_geometry_helpers_detect_what_they_claim():
    """Controls: a bow-tie self-intersects, a square does not; a point outside is outside."""
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    bow_tie = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
    assert not self_intersects(square) and self_intersects(bow_tie)
    assert contains(square, (0.5, 0.5)) and not contains(square, (1.5, 0.5))
    assert signed_area(square) == 1.0 and signed_area(square[::-1]) == -1.0


# ------------------------------------------------------------------ every section
def test_every_registered_shape_has_examples():
    assert set(EXAMPLES) == set(SECTIONS)
    for name, cls in SECTIONS.items():
        assert cls.name == name and all(isinstance(s, cls) for s in EXAMPLES[name])


@pytest.mark.parametrize("section", ALL)
def test_outline_is_simple_counter_clockwise_and_spans_chord_and_depth(section):
    v = section.polygon().vertices
    assert signed_area(v) > 0
    assert not self_intersects(v)
    assert contains(v, (0.0, 0.0))
    assert np.isclose(v[:, 0].max() - v[:, 0].min(), section.chord_m, rtol=1e-12)
    assert np.isclose(v[:, 0].max(), 0.5 * section.chord_m, rtol=1e-12)
    assert np.isclose(v[:, 1].max() - v[:, 1].min(), section.depth_m, rtol=1e-12)
    np.testing.assert_array_equal(section.polygons()[0].vertices, v)  # the outline comes first
    assert isinstance(section.describe(), str) and section.describe()


@pytest.mark.parametrize("section", ALL)
def test_outline_is_symmetric_fore_and_aft(section):
    """The shipped sections (the Great Belt girder too) and the polygon example are symmetric about x = 0."""
    v = np.vstack([p.vertices for p in section.polygons()])
    mirrored = v * np.array([-1.0, 1.0])
    key = lambda a: a[np.lexsort((a[:, 1], a[:, 0]))]  # noqa: E731
    np.testing.assert_allclose(key(mirrored), key(v), atol=1e-12)


# ------------------------------------------------------------------ closed forms
@pytest.mark.parametrize("chord, depth", [(5.0, 1.0), (2.0, 0.4), (3.0, 3.0)])
def test_rectangle_area_and_centroid(chord, depth):
    p = Rectangle(chord, depth).polygon()
    assert np.isclose(p.area, chord * depth, rtol=1e-14)
    np.testing.assert_allclose(p.centroid, [0.0, 0.0], atol=1e-14)
    # polar moment of a rectangle about its centroid: A (B^2 + D^2) / 12
    assert np.isclose(p.polar_moment_centroid, chord * depth * (chord**2 + depth**2) / 12, rtol=1e-12)


@pytest.mark.parametrize("chord, thickness", [(1.0, 0.02), (3.0, 0.3)])
def test_flat_plate_area(chord, thickness):
    square = FlatPlate(chord, thickness).polygon()
    assert np.isclose(square.area, chord * thickness, rtol=1e-14)
    round_ = FlatPlate(chord, thickness, ends="round").polygon()
    r, n = 0.5 * thickness, 16
    # two inscribed half n-gons: n triangles of area r^2 sin(pi/n)/2 each end, plus the straight part
    polygonised = (chord - thickness) * thickness + n * r * r * np.sin(np.pi / n)
    assert np.isclose(round_.area, polygonised, rtol=1e-12)
    exact = (chord - thickness) * thickness + np.pi * r * r
    assert abs(round_.area / exact - 1) < 0.01 * (thickness / chord)
    np.testing.assert_allclose(round_.centroid, [0.0, 0.0], atol=1e-14)


def _box_chains(B, D, fall, bottom, nose, top):
    """Lower and upper outline of the box as (x, y) breakpoints, written out from the docstring."""
    a, h = B / 2, D / 2
    yn = -h + nose * (D - fall * a)
    lower = np.array([[-a, yn], [-bottom * a, -h], [bottom * a, -h], [a, yn]])
    t = top * a
    upper = np.array([[-a, yn], [-t, h - fall * t], [0.0, h], [t, h - fall * t], [a, yn]])
    return lower, upper


def test_great_belt_box_dimensions_and_area():
    """B = 31 m, D = 4.4 m (Larsen 1993); the area against a trapezoid integral of the two chains."""
    box = great_belt_section()
    assert (box.chord_m, box.depth_m) == (31.0, 4.4)
    lower, upper = _box_chains(31.0, 4.4, 0.02, 0.6, 0.8, 0.9)
    x = np.union1d(lower[:, 0], upper[:, 0])  # all breakpoints: the trapezoid rule is exact
    gap = np.interp(x, upper[:, 0], upper[:, 1]) - np.interp(x, lower[:, 0], lower[:, 1])
    area = float(np.sum(0.5 * (gap[1:] + gap[:-1]) * np.diff(x)))
    p = box.polygon()
    assert np.isclose(p.area, area, rtol=1e-12)
    # the same outline by hand: nose 0.8 (4.4 - 0.31) - 2.2 = 1.072 m, roof edge 2.2 - 0.02 * 13.95
    expected = np.array([[-15.5, 1.072], [-9.3, -2.2], [9.3, -2.2], [15.5, 1.072],
                         [13.95, 1.921], [0.0, 2.2], [-13.95, 1.921]])
    np.testing.assert_allclose(p.vertices, expected, atol=1e-12)
    assert np.isclose(p.centroid[0], 0.0, atol=1e-12)


@pytest.mark.parametrize("kwargs", [dict(nose_height_fraction=1.0), dict(cross_fall=0.0),
                                    dict(bottom_flat_fraction=0.2, top_flat_fraction=0.7, depth_m=3.0)])
def test_box_area_matches_trapezoid_integral_for_other_parameters(kwargs):
    box = StreamlinedBox(**kwargs)
    lower, upper = _box_chains(box.chord_m, box.depth_m, box.cross_fall, box.bottom_flat_fraction,
                               box.nose_height_fraction, box.top_flat_fraction)
    x = np.union1d(lower[:, 0], upper[:, 0])
    gap = np.interp(x, upper[:, 0], upper[:, 1]) - np.interp(x, lower[:, 0], lower[:, 1])
    assert np.isclose(box.polygon().area, float(np.sum(0.5 * (gap[1:] + gap[:-1]) * np.diff(x))), rtol=1e-12)


def test_railings_stand_on_the_roof_as_separate_strips():
    box = StreamlinedBox(railings=True)
    assert len(StreamlinedBox().polygons()) == 1
    parts = box.polygons()
    assert len(parts) == 3 and parts[0].vertices.shape == box.polygon().vertices.shape
    for strip in parts[1:]:
        v = strip.vertices
        assert signed_area(v) > 0 and not self_intersects(v)
        base = v[:2]  # the two base vertices lie on the roof line y = D/2 - cross_fall |x|
        np.testing.assert_allclose(base[:, 1], 2.2 - 0.02 * np.abs(base[:, 0]), atol=1e-12)
        assert np.isclose(v[:, 0].max() - v[:, 0].min(), box.railing_thickness_m)
        assert np.isclose(v[2, 1] - strip.centroid[1], 0.5 * box.railing_height_m, rtol=1e-3)
        # outer face railing_inset_m inside the roof edge at x = +-t/2
        assert np.isclose(np.abs(v[:, 0]).max(), 0.5 * 0.9 * 31.0 - box.railing_inset_m)


# ------------------------------------------------------------------ validation
@pytest.mark.parametrize("cls, kwargs, key", [
    (FlatPlate, dict(chord_m=0.0, thickness_m=0.01), "chord_m"),
    (FlatPlate, dict(chord_m=1.0, thickness_m=0.2), "thickness_m"),
    (FlatPlate, dict(chord_m=1.0, thickness_m=-0.01), "thickness_m"),
    (FlatPlate, dict(chord_m=1.0, thickness_m=0.01, ends="pointed"), "ends"),
    (Rectangle, dict(chord_m=-1.0, depth_m=0.2), "chord_m"),
    (Rectangle, dict(chord_m=1.0, depth_m=2.0), "depth_m"),
    (Rectangle, dict(chord_m=1.0, depth_m="0.2"), "depth_m"),
    (Rectangle, dict(chord_m=float("nan"), depth_m=0.2), "chord_m"),
    (StreamlinedBox, dict(depth_m=20.0), "depth_m"),
    (StreamlinedBox, dict(cross_fall=-0.01), "cross_fall"),
    (StreamlinedBox, dict(cross_fall=0.08, depth_m=1.0), "cross_fall"),  # roof below the bottom
    (StreamlinedBox, dict(bottom_flat_fraction=1.0), "bottom_flat_fraction"),
    (StreamlinedBox, dict(nose_height_fraction=0.0), "nose_height_fraction"),
    (StreamlinedBox, dict(nose_height_fraction=1.2), "nose_height_fraction"),
    (StreamlinedBox, dict(top_flat_fraction=0.0), "top_flat_fraction"),
    (StreamlinedBox, dict(railings=1), "railings"),
    (StreamlinedBox, dict(railing_height_m=0.0), "railing_height_m"),
    (StreamlinedBox, dict(railing_inset_m=14.0), "railing_inset_m"),
])
def test_bad_input_names_the_key(cls, kwargs, key):
    with pytest.raises(InputError) as err:
        cls(**kwargs)
    assert err.value.key == f"deck_section.{key}"
    assert key in str(err.value)


def test_sections_are_frozen_and_store_floats():
    r = Rectangle(5, 1)
    assert isinstance(r.chord_m, float) and r == Rectangle(5.0, 1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.chord_m = 2.0


@pytest.mark.parametrize("section", ALL)
def test_mapping_round_trip(section):
    table = section.to_mapping()
    assert table["shape"] == section.name
    assert section_from_mapping(table) == section


def test_mapping_defaults_and_errors():
    assert section_from_mapping({"shape": "streamlined_box"}) == great_belt_section()
    cases = [
        ({"shape": "rectangle", "chord_m": 5.0, "depth_m": 1.0, "width_m": 3.0}, "deck_section.width_m"),
        ({"shape": "rectangle", "chord_m": 5.0}, "deck_section.depth_m"),  # missing required key
        ({"chord_m": 5.0, "depth_m": 1.0}, "deck_section.shape"),
        ({"shape": "ellipse"}, "deck_section.shape"),
        ({"shape": "flat_plate", "chord_m": 1.0, "thickness_m": 0.5}, "deck_section.thickness_m"),
    ]
    for table, key in cases:
        with pytest.raises(InputError) as err:
            section_from_mapping(table)
        assert err.value.key == key, table
    with pytest.raises(InputError) as err:
        section_from_mapping({"shape": "rectangle", "chord_m": 5.0, "depth_m": 9.0}, where="bridge.deck_section")
    assert err.value.key == "bridge.deck_section.depth_m"
    with pytest.raises(InputError) as err:
        section_from_mapping({"shape": "rectangle", "chord_m": 5.0, "depth_m": 1.0, "x": 1}, where="deck")
    assert err.value.key == "deck.x"


# ------------------------------------------------------------------ immersion in the CFD
@pytest.mark.parametrize("section, cells_per_chord", [
    (EXAMPLES["flat_plate"][1], 40),  # t = 0.05 B: two cells across
    (EXAMPLES["rectangle"][0], 40),
    (great_belt_section(), 40),
    # railings resolved by 2.6 cells (the default 0.2 m strip would need h <= 0.1 m, 310 cells per B)
    (StreamlinedBox(railings=True, railing_thickness_m=1.0), 80),
], ids=["plate", "rectangle", "box", "box-railings"])
def test_section_immerses_and_steps(section, cells_per_chord):
    """Every polygon of the section held at rest in a uniform stream, two steps on 2400-9600 cells:
    forces finite, each part forces some faces and feels a positive drag."""
    B, n = section.chord_m, cells_per_chord
    grid = CartesianGrid.uniform(3 * n, n // 2, (-B, 2 * B), (-0.25 * B, 0.25 * B))
    bc = BoundaryConditions(left="inflow", right="outflow", bottom="slip", top="slip")
    sim = Simulation(grid, FlowConfig(nu=B / 100.0, cfl=0.5, threads=1, bc=bc))
    bodies = [sim.add_body(polygon, Stationary()) for polygon in section.polygons()]
    sim.set_state(u=1.0)
    sim.step()
    sim.step()
    forces = np.array(sim.last_force)
    assert forces.shape == (len(section.polygons()), 3) and np.all(np.isfinite(forces))
    assert np.all(forces[:, 0] > 0)
    assert all(body.forced_cells().any() for body in bodies)
