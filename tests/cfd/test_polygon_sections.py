"""Polygon decks, ``[deck_section] shape = "polygon"`` (bridge/cfd/sections.py PolygonSection, bridge/cfd/outline.py):
the same outline inline, from CSV and from DXF; units, orientation, reference point and chord; every malformed
outline refused with one InputError naming its key (and once through the real command line); the outline in the
aero stage's cache key; the shipped example; an asymmetric deck with a wind screen through the CFD."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bridge.cfd.outline import orientation, point_in_polygon, segment_intersection
from bridge.cfd.sections import PolygonSection, section_from_mapping
from bridge.errors import InputError

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "scenarios" / "outlines" / "asymmetric_box.csv"

# an asymmetric box (blunt windward edge at x = 0, pointed leeward edge at x = 31), counter-clockwise, and a wind
# screen strip above its roof: the shipped example's numbers
BOX = [(6.0, 0.0), (24.0, 0.0), (31.0, 3.0), (29.5, 3.72), (15.5, 4.0), (1.5, 3.72), (0.0, 3.3), (0.0, 2.0)]
SCREEN = [(2.0, 4.0), (2.25, 4.0), (2.25, 6.0), (2.0, 6.0)]
SQUARE = [(0.0, 0.0), (10.0, 0.0), (10.0, 2.0), (0.0, 2.0)]


def closed(points) -> list[list[float]]:
    """The TOML form: a list of [x, y], the last repeating the first."""
    return [list(p) for p in points] + [list(points[0])]


def write_csv(path: Path, parts: dict[str, list]) -> Path:
    """A header, then the parts' closed outlines with their labels in the part column."""
    lines = ["x,y,part"] + [f"{x},{y},{name}" for name, pts in parts.items() for x, y in closed(pts)]
    path.write_text("\n".join(lines) + "\n")
    return path


def write_dxf(path: Path, parts: list, insunits: int = 6, scale: float = 1.0, layer: str = "DECK",
              close: bool = True) -> Path:
    """Each part a closed LWPOLYLINE (the second, if any, a 2D POLYLINE: both kinds are read)."""
    import ezdxf

    doc = ezdxf.new(units=insunits)
    msp = doc.modelspace()
    for i, pts in enumerate(parts):
        xy = [(x * scale, y * scale) for x, y in pts]
        if i % 2 == 0:
            msp.add_lwpolyline(xy, close=close, dxfattribs={"layer": layer})
        else:
            msp.add_polyline2d(xy, close=close, dxfattribs={"layer": layer})
    doc.saveas(path)
    return path


def vertices(section: PolygonSection) -> list[np.ndarray]:
    return [p.vertices for p in section.polygons()]


def same_polygons(a: PolygonSection, b: PolygonSection, atol: float = 1e-9) -> None:
    assert len(a.polygons()) == len(b.polygons())
    for va, vb in zip(vertices(a), vertices(b), strict=True):
        np.testing.assert_allclose(va, vb, atol=atol)


# ------------------------------------------------------------------ geometry helpers
def test_geometry_helpers():
    np.testing.assert_allclose(segment_intersection((0, 0), (2, 2), (0, 2), (2, 0)), [1.0, 1.0])
    np.testing.assert_allclose(segment_intersection((0, 0), (2, 0), (1, 0), (1, 3)), [1.0, 0.0])   # T: touching
    shared = segment_intersection((0, 0), (2, 0), (1, 0), (3, 0))                                # overlapping
    assert shared[1] == 0.0 and 1.0 <= shared[0] <= 2.0
    assert segment_intersection((0, 0), (2, 0), (0, 1), (2, 1)) is None                           # parallel
    assert segment_intersection((0, 0), (1, 0), (2, -1), (2, 1)) is None                          # short of it
    square = np.array(SQUARE)
    assert point_in_polygon((5, 1), square) and not point_in_polygon((11, 1), square)
    assert orientation(np.array([0, 0]), np.array([1, 0]), np.array([0, 1])) > 0


# ------------------------------------------------------------------ the same outline from every source
@pytest.mark.parametrize("insunits, scale", [(6, 1.0), (4, 1000.0), (5, 100.0)], ids=["m", "mm", "cm"])
def test_inline_csv_and_dxf_give_the_same_polygons(tmp_path, insunits, scale):
    inline = PolygonSection(parts=[closed(BOX), closed(SCREEN)])
    table = section_from_mapping({"shape": "polygon", "parts": [{"vertices": closed(BOX)},
                                                                 {"vertices": closed(SCREEN)}]})
    write_csv(tmp_path / "deck.csv", {"box": BOX, "screen": SCREEN})
    csv = PolygonSection(outline_path="deck.csv", base_dir=tmp_path)
    write_dxf(tmp_path / "deck.dxf", [SCREEN, BOX], insunits, scale)   # drawn screen first: the box still leads
    dxf = PolygonSection(outline_path=str(tmp_path / "deck.dxf"))
    for other in (table, csv, dxf):
        same_polygons(inline, other)
    assert table == inline
    assert (inline.chord_m, inline.depth_m) == (31.0, 4.0)
    # the reference point: mid-width of all parts, half the box's height
    np.testing.assert_allclose(inline.polygon().vertices[0], [6.0 - 15.5, 0.0 - 2.0])
    assert "2 parts" in inline.describe() and "inline" in inline.describe() and "deck.csv" in csv.describe()


def test_csv_without_header_or_part_column(tmp_path):
    path = tmp_path / "d.csv"
    path.write_text("# one part, no header\n" + "\n".join(f"{x}, {y}" for x, y in closed(BOX)) + "\n\n")
    same_polygons(PolygonSection(outline_path=str(path)), PolygonSection(vertices=closed(BOX)))
    path.write_text("y_m,x_m\n" + "\n".join(f"{y},{x}" for x, y in closed(BOX)))   # a header names the order
    same_polygons(PolygonSection(outline_path=str(path)), PolygonSection(vertices=closed(BOX)))


def test_clockwise_outline_is_reversed_and_repeated_points_dropped():
    ccw = PolygonSection(vertices=closed(BOX))
    cw = PolygonSection(vertices=closed(BOX[::-1]))
    doubled = PolygonSection(vertices=closed([BOX[0], *BOX[1:4], BOX[3], *BOX[4:]]))
    for s in (cw, doubled):
        v = s.polygon().vertices
        assert s.polygon().area > 0 and len(v) == len(BOX)
        start = int(np.argmin(np.hypot(*(v - ccw.polygon().vertices[0]).T)))
        np.testing.assert_allclose(np.roll(v, -start, axis=0), ccw.polygon().vertices, atol=1e-12)


def test_reference_point_and_chord():
    plain = PolygonSection(vertices=closed(BOX))
    moved = PolygonSection(vertices=closed(BOX), reference_point_m=[10.0, 1.0])
    np.testing.assert_allclose(moved.polygon().vertices, np.array(BOX) - [10.0, 1.0])
    np.testing.assert_allclose(plain.polygon().vertices, np.array(BOX) - [15.5, 2.0])
    assert moved.chord_m == 31.0 and moved.depth_m == 4.0
    wide = PolygonSection(vertices=closed(BOX), chord_m=35.0)
    assert wide.chord_m == 35.0 and "B = 35 m" in wide.describe()
    for section in (plain, moved, wide):
        assert section_from_mapping(section.to_mapping()) == section
    assert plain != moved and hash(plain) == hash(PolygonSection(vertices=closed(BOX)))


def test_file_section_round_trips_with_its_folder(tmp_path):
    write_csv(tmp_path / "deck.csv", {"box": BOX, "screen": SCREEN})
    section = section_from_mapping({"shape": "polygon", "outline_path": "deck.csv"}, base_dir=tmp_path)
    table = section.to_mapping()
    assert table["outline_path"] == "deck.csv" and "vertices" not in table
    assert section_from_mapping(table, base_dir=tmp_path) == section


# ------------------------------------------------------------------ what is refused
OPEN = [list(p) for p in BOX]                                             # the last point does not repeat the first
CROSSED = closed([(0.0, 0.0), (10.0, 0.0), (0.0, 2.0), (10.0, 2.0)])      # a bow tie: crossing at (5, 1)
LINE = closed([(0.0, 0.0), (5.0, 0.0), (10.0, 0.0)])
TWO = [[0.0, 0.0], [10.0, 0.0], [0.0, 0.0]]
SPIKE = closed([(0.0, 0.0), (10.0, 0.0), (10.0, 2.0), (10.0, 1.0), (0.0, 2.0)])  # folds back on its right edge


@pytest.mark.parametrize("table, key, words", [
    ({"vertices": OPEN}, "vertices", "not closed"),
    ({"vertices": CROSSED}, "vertices", "crosses itself: the edge from (10, 0) to (0, 2) meets the edge from "
                                         "(10, 2) to (0, 0) at (5, 1)"),
    ({"vertices": LINE}, "vertices", "no area"),
    ({"vertices": TWO}, "vertices", "fewer than 3 distinct points"),
    ({"vertices": SPIKE}, "vertices", "crosses itself"),
    ({"vertices": closed([(0.0, 0.0), (10.0, float("nan")), (0.0, 2.0)])}, "vertices", "finite"),
    ({"vertices": closed([(0.0, 0.0), (10.0, float("inf")), (0.0, 2.0)])}, "vertices", "finite"),
    ({"vertices": [[0.0, 0.0], [1.0, "a"], [0.0, 0.0]]}, "vertices", "pair of numbers"),
    ({"vertices": "0 0 1 1"}, "vertices", "list of [x, y]"),
    ({"parts": [closed(BOX), OPEN]}, "parts[1]", "not closed"),
    ({"parts": [closed(BOX), closed([(2.0, 3.0), (3.0, 3.0), (3.0, 5.0), (2.0, 5.0)])]}, "parts[1]",
     "touches or crosses parts[0]"),                                         # overlaps the roof
    ({"parts": [closed(BOX), closed([(1.5, 3.72), (2.5, 3.74), (2.5, 5.0), (1.5, 5.0)])]}, "parts[1]",
     "touches or crosses"),                                                  # stands on the roof: touches
    ({"parts": [closed(BOX), closed([(10.0, 1.0), (12.0, 1.0), (12.0, 2.0), (10.0, 2.0)])]}, "parts[1]",
     "parts[1] lies inside parts[0]"),
    ({"parts": [closed([(10.0, 1.0), (12.0, 1.0), (12.0, 2.0), (10.0, 2.0)]), closed(BOX)]}, "parts[1]",
     "parts[0] lies inside parts[1]"),
    ({"parts": [closed(BOX), {"vertices": closed(SCREEN), "name": "x"}]}, "parts[1].name", "unknown key"),
    ({"parts": []}, "parts", "list of outlines"),
    ({}, "vertices", "missing"),
    ({"vertices": closed(BOX), "parts": [closed(BOX)]}, "parts", "one way"),
    ({"vertices": closed(BOX), "outline_layer": "DECK"}, "outline_layer", "DXF"),
    ({"vertices": closed(BOX), "reference_point_m": [40.0, 1.0]}, "reference_point_m", "within the box"),
    ({"vertices": closed(BOX), "reference_point_m": [1.0]}, "reference_point_m", "[x, y]"),
    ({"vertices": closed(BOX), "chord_m": 30.0}, "chord_m", "between the width"),
    ({"vertices": closed(BOX), "chord_m": 70.0}, "chord_m", "between the width"),
    ({"vertices": closed(BOX), "depth_m": 4.0}, "depth_m", "unknown key"),
    ({"outline_path": "missing.csv"}, "outline_path", "file not found"),
    ({"outline_path": "deck.txt"}, "outline_path", "not a CSV (.csv) or DXF (.dxf) file"),
])
def test_a_malformed_inline_outline_names_its_key(table, key, words):
    with pytest.raises(InputError) as err:
        section_from_mapping({"shape": "polygon", **table})
    assert err.value.key == f"deck_section.{key}"
    assert words in str(err.value), str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("content, words", [
    ("x,y\n0,0\n10,0\n10,2\n0,2\n", "not closed: the last point, row 5 (0, 2), must repeat the first, row 2 (0, 0)"),
    ("x,y\n0,0\n10,0\n# a comment\n\n10,2\nn/a,2\n0,0\n", "row 7, column x: 'n/a' is not a number"),
    ("x,y\n0,0\n10,0\n10,n/a\n0,0\n", "row 4, column y: 'n/a' is not a number"),
    ("x,y\n0,0\n10,0\n10,nan\n0,0\n", "row 4, column y: 'nan' is not a finite number"),
    ("0,0\n10,0\n0,2\n10,2\n0,0\n", "crosses itself: the edge from row 2 (10, 0) to row 3 (0, 2) meets the edge from "
                                    "row 4 (10, 2) to row 1 (0, 0) at (5, 1)"),
    ("x,y\n0,0\n10,0\n20,0\n0,0\n", "no area"),
    ("x,y\n0,0\n10,0,3\n", "row 3: 3 values, expected 2 (x, y)"),
    ("x,z\n0,0\n", "row 1: the header x, z must name the columns x, y"),
    ("# nothing\n", "holds no points"),
    ("x,y,part\n0,0,a\n10,0,a\n10,2,a\n0,0,a\n20,0,b\n30,0,b\n30,2,b\n20,0,b\n1,1,a\n", "row 10: part 'a' again"),
    ("x,y,part\n0,0,a\n10,0,a\n10,2,a\n0,2,a\n0,0,a\n5,1,b\n6,1,b\n6,3,b\n5,3,b\n5,1,b\n",
     "part 'b' (rows 7-11) touches or crosses part 'a' (rows 2-6)"),
    ("x,y,part\n0,0,a\n10,0,a\n10,2,a\n0,2,a\n0,0,a\n1,0.5,b\n2,0.5,b\n2,1,b\n1,0.5,b\n", "lies inside"),
    ("x,y,part\n0,0,a\n10,0,a\n10,2,\n0,0,a\n", "row 4, column part: empty"),
    ("x;y\n0;0\n", "row 1: separate the values by commas"),
])
def test_a_malformed_csv_outline_says_where(tmp_path, content, words):
    (tmp_path / "deck.csv").write_text(content)
    with pytest.raises(InputError) as err:
        section_from_mapping({"shape": "polygon", "outline_path": "deck.csv"}, base_dir=tmp_path)
    assert err.value.key == "deck_section.outline_path" and err.value.value == "deck.csv"
    assert words in str(err.value), str(err.value)


def test_a_malformed_dxf_outline_says_where(tmp_path):
    import ezdxf

    def refused(path: Path, **kw) -> str:
        with pytest.raises(InputError) as err:
            PolygonSection(outline_path=str(path), **kw)
        assert err.value.key == "deck_section.outline_path"
        return str(err.value)

    assert "not closed" in refused(write_dxf(tmp_path / "open.dxf", [BOX], close=False))
    assert "crosses itself" in refused(write_dxf(tmp_path / "bow.dxf", [CROSSED[:-1]]))
    assert "touches or crosses polyline 1" in refused(write_dxf(tmp_path / "touch.dxf", [SQUARE, [
        (10.0, 1.0), (12.0, 1.0), (12.0, 3.0), (10.0, 3.0)]]))
    doc = ezdxf.new()
    for a, b in zip(SQUARE, SQUARE[1:] + SQUARE[:1], strict=True):
        doc.modelspace().add_line(a, b)
    doc.saveas(tmp_path / "lines.dxf")
    assert "draw the outline as closed polylines" in refused(tmp_path / "lines.dxf")
    path = write_dxf(tmp_path / "layer.dxf", [BOX], layer="DECK")
    words = "no closed polyline on layer 'SCREEN' (polylines are on layers DECK)"
    assert words in refused(path, outline_layer="SCREEN")
    assert PolygonSection(outline_path=str(path), outline_layer="deck").polygon().area > 0   # layers: any case
    (tmp_path / "bad.dxf").write_text("not a drawing\n")
    assert "not a readable DXF file" in refused(tmp_path / "bad.dxf")


def test_a_dxf_arc_is_flattened():
    """A bulge of 1 on the right-hand edge of a 10 m x 2 m rectangle: a half circle of radius 1 m."""
    import tempfile

    import ezdxf

    with tempfile.TemporaryDirectory() as folder:
        doc = ezdxf.new(units=6)
        doc.modelspace().add_lwpolyline([(0, 0, 0, 0, 0), (10, 0, 0, 0, 1), (10, 2, 0, 0, 0), (0, 2, 0, 0, 0)],
                                        format="xyseb", close=True)
        doc.saveas(Path(folder) / "arc.dxf")
        section = PolygonSection(outline_path=str(Path(folder) / "arc.dxf"))
    assert section.chord_m == pytest.approx(11.0)
    assert section.polygon().area == pytest.approx(20.0 + np.pi / 2, rel=1e-3)
    assert len(section.polygon().vertices) > 12


# ------------------------------------------------------------------ scenario, cache key and command line
def scenario_file(folder: Path, deck: str) -> Path:
    path = folder / "mine.toml"
    path.write_text(f'reference = "great_belt"\nmain_span_m = 1624.0\n\n[deck_section]\nshape = "polygon"\n{deck}\n')
    return path


def aero_key(path: Path) -> str:
    from bridge.config import load_scenario
    from bridge.pipeline import stage_keys

    return stage_keys(load_scenario(path), ["aero"])["aero"]


def test_the_outline_is_in_the_aero_stage_key(tmp_path):
    """Moving one vertex changes the key, inline or in a file (whose bytes are in the key too)."""
    from bridge.config import load_scenario
    from bridge.pipeline import stage_keys

    def inline(box):
        return aero_key(scenario_file(tmp_path, f"vertices = {closed(box)}"))

    moved = [BOX[0], (24.0, -0.1), *BOX[2:]]
    assert inline(BOX) == inline(BOX) != inline(moved)

    sub = tmp_path / "outlines"
    sub.mkdir()
    csv = write_csv(sub / "deck.csv", {"box": BOX, "screen": SCREEN})
    path = scenario_file(tmp_path, 'outline_path = "outlines/deck.csv"')
    scenario = load_scenario(path)          # read relative to the scenario file, not the working directory
    assert scenario.deck_section.polygons()[1].area == pytest.approx(0.5)
    before = stage_keys(scenario, ["aero"])["aero"]
    csv.write_text(csv.read_text() + "# an edit that leaves the outline as it was\n")
    assert stage_keys(scenario, ["aero"])["aero"] != before     # the file's digest
    edited = aero_key(path)
    write_csv(csv, {"box": moved, "screen": SCREEN})
    assert aero_key(path) not in (before, edited)

    write_dxf(sub / "deck.dxf", [BOX, SCREEN])
    path = scenario_file(tmp_path, 'outline_path = "outlines/deck.dxf"')
    first = aero_key(path)
    write_dxf(sub / "deck.dxf", [moved, SCREEN])
    assert aero_key(path) != first


def test_a_bad_outline_stops_the_command_with_one_line_and_writes_nothing(tmp_path):
    (tmp_path / "deck.csv").write_text("x,y\n0,0\n31,0\n31,4\n0,4\n")   # cut short: not closed
    path = scenario_file(tmp_path, 'outline_path = "deck.csv"')
    out = tmp_path / "out"
    out.mkdir()
    proc = subprocess.run([sys.executable, "-m", "bridge.scenario", str(path), "--stages", "aero", "--quality", "tiny",
                           "--out", str(out)], capture_output=True, text=True, cwd=REPO, timeout=300)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("error: deck_section.outline_path = 'deck.csv': not closed: the last point, row 5")
    assert list(out.iterdir()) == []


# ------------------------------------------------------------------ the shipped example and the CFD
def test_the_shipped_example_outline():
    section = PolygonSection(outline_path=str(EXAMPLE))
    assert len(section.polygons()) == 2
    assert section.chord_m == 31.0 and 3.5 <= section.depth_m <= 4.5
    box = section.polygon().vertices
    mirrored = box * [-1.0, 1.0]
    key = lambda a: a[np.lexsort((a[:, 1], a[:, 0]))]  # noqa: E731
    assert not np.allclose(key(mirrored), key(box))   # not symmetric fore and aft
    same_polygons(section, PolygonSection(parts=[closed(BOX), closed(SCREEN)]))


def test_an_asymmetric_deck_with_a_wind_screen_runs_through_the_cfd():
    """One short forced heave on the 'tiny' preset (a few seconds): the forces are finite."""
    from bridge.aero.forced_motion import ForcedCase, run_case
    from bridge.aero.presets import preset, section_polygons

    section = PolygonSection(outline_path=str(EXAMPLE))
    polys = section_polygons(section)
    assert len(polys) == 2 and np.ptp(np.vstack([p.vertices for p in polys])[:, 0]) == pytest.approx(1.0)
    rec = run_case(polys, ForcedCase("heave", (2.5,), (0.005,)), preset("tiny"))
    assert rec.steps > 10
    for name in ("lift", "drag", "moment"):
        assert np.all(np.isfinite(getattr(rec, name))), name
    assert np.abs(rec.lift).max() > 0


@pytest.mark.slow   # ~2.5 min: three runs of the whole chain (coarse FEM, 'tiny' CFD); runs in CI with -m slow
def test_a_polygon_deck_inline_from_csv_and_from_dxf_runs_through_the_chain(tmp_path):
    """The same asymmetric deck given three ways runs cable, fem, aero and flutter, gives one answer, and the
    headline says that no grid study covers this deck (and that the screen is too thin for the grid)."""
    write_csv(tmp_path / "deck.csv", {"box": BOX, "screen": SCREEN})
    write_dxf(tmp_path / "deck.dxf", [BOX, SCREEN])
    ways = {"inline": f"parts = {[closed(BOX), closed(SCREEN)]}", "csv": 'outline_path = "deck.csv"',
            "dxf": 'outline_path = "deck.dxf"'}
    found = {}
    for way, table in ways.items():
        path = scenario_file(tmp_path, table)
        out = tmp_path / f"out_{way}"
        proc = subprocess.run([sys.executable, "-m", "bridge.scenario", str(path), "--quick", "--out", str(out)],
                              capture_output=True, text=True, cwd=REPO, timeout=900)
        assert proc.returncode == 0, proc.stderr[-3000:]
        head = proc.stdout
        assert "the deck's own, from forced-motion CFD" in head and "no grid study covers" in head, head
        assert "part 2 of the section" in proc.stderr                       # the 0.25 m screen on 'tiny'
        found[way] = [line for line in head.splitlines() if "V_c" in line or "no flutter" in line.lower()][0]
    assert found["inline"] == found["csv"] == found["dxf"], found
