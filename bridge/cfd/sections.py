"""Deck cross-sections the aerodynamic stage moves in the CFD: thin flat plate, B/D = 5 rectangle,
streamlined closed box (the Great Belt East Bridge girder), and any outline the user draws (a polygon
deck: :class:`PolygonSection`, read and checked by :mod:`bridge.cfd.outline`).

Each section is a frozen dataclass validated on construction (a bad field raises
:class:`bridge.errors.InputError` naming ``deck_section.<field>``) and gives its outline as a
:class:`bridge.cfd.bodies.Polygon` in the section's own frame:

* x along the wind, the chord B from the leading edge at x = -B/2 to the trailing edge at x = +B/2;
* y up; the reference point (0, 0) is the mid-chord on the deck axis, taken at half the depth D (the
  rectangle's and plate's centroid; for the box, half-way between the flat bottom and the crown).
  It is the moment reference and the rotation centre of the flutter convention.  Nose-up pitch
  theta lifts the leading edge (x < 0), which is a clockwise rotation in this frame: a
  :mod:`bridge.cfd.motion` angle (counter-clockwise) is -theta.

Every section has ``chord_m`` (B), ``depth_m`` (D), a ``name`` (its key in :data:`SECTIONS`),
``describe()``, ``polygon()`` (the outline) and ``polygons()`` (the outline plus any separate solid
strips: the box's optional railings).  A scenario gives one as a ``[deck_section]`` table,
``shape = "<key of SECTIONS>"`` and the dataclass fields (units in the names), read by
:func:`section_from_mapping`.  A polygon deck keeps its own frame's rules (:class:`PolygonSection`):
the reference point is the middle of its width at half the main outline's height unless given.

Sources.  Flat plate: the Theodorsen validation of the issue (thickness <= 2 % of chord there).
Rectangle: the BARC benchmark, a B/D = 5 rectangular cylinder (Bruno, Salvetti and Ricciardelli 2014,
"Benchmark on the aerodynamics of a rectangular 5:1 cylinder: an overview after the first four years
of activity", J. Wind Eng. Ind. Aerodyn. 126, 87-106).  Box: the thesis gives B = 31 m and no
drawing in its text (SPEC: depth about 4.0-4.4 m, B/D about 7); Larsen (1993, "Aerodynamic aspects of
the final design of the 1624 m suspension bridge across the Great Belt", J. Wind Eng. Ind. Aerodyn.
48, 261-285) describes a 31 m wide, 4.4 m deep closed steel box with pointed edges.  Every other
dimension of the box is ASSUMED (marked at each field of :class:`StreamlinedBox`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import MISSING, InitVar, dataclass, field, fields
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ..errors import InputError, check_range
from ..toml_table import Table
from .bodies import Polygon

__all__ = ["FlatPlate", "Rectangle", "StreamlinedBox", "PolygonSection", "SECTIONS", "section_from_mapping",
           "great_belt_section"]

WHERE = "deck_section"  # the scenario table; the prefix of every error key raised here
ROUND_END_SEGMENTS = 16  # straight segments per semicircular plate end (area error 0.6 % of the end)


class _Section:
    """What every section shares: the polygon list and the scenario mapping."""

    name: ClassVar[str]

    def polygon(self) -> Polygon:  # pragma: no cover - every section defines it
        raise NotImplementedError

    def polygons(self) -> list[Polygon]:
        """The solid parts in the section frame: the outline first, then any separate strips."""
        return [self.polygon()]

    def to_mapping(self) -> dict[str, Any]:
        """The ``[deck_section]`` table that :func:`section_from_mapping` turns back into this section."""
        return {"shape": self.name, **{f.name: getattr(self, f.name) for f in fields(self)}}

    def _number(self, name: str, low: float | None = 0.0, high: float | None = None,
                low_open: bool = True, high_open: bool = False) -> float:
        """Check one numeric field and store it as a float (the dataclass is frozen)."""
        value = check_range(f"{WHERE}.{name}", getattr(self, name), low, high, low_open, high_open)
        object.__setattr__(self, name, value)
        return value


@dataclass(frozen=True)
class FlatPlate(_Section):
    """Thin plate: a chord_m x thickness_m rectangle, its ends square or semicircular.

    ``ends = "square"``: a plain rectangle (sharp corners).  ``ends = "round"``: semicircles of
    diameter thickness_m at both ends (polygonised with ``ROUND_END_SEGMENTS`` segments each, tips on
    x = +-B/2, so the chord stays B).  thickness_m <= 10 % of chord_m; the Theodorsen validation of
    the issue uses <= 2 %.  Resolve the thickness by at least two cells.
    """

    name: ClassVar[str] = "flat_plate"
    ends_allowed: ClassVar[tuple[str, ...]] = ("square", "round")

    chord_m: float
    thickness_m: float
    ends: str = "square"

    def __post_init__(self) -> None:
        chord = self._number("chord_m")
        self._number("thickness_m", 0.0, 0.1 * chord)
        if not isinstance(self.ends, str) or self.ends not in self.ends_allowed:
            raise InputError(f"{WHERE}.ends", self.ends, f"must be one of {', '.join(self.ends_allowed)}")

    @property
    def depth_m(self) -> float:
        return self.thickness_m

    def polygon(self) -> Polygon:
        a, r = 0.5 * self.chord_m, 0.5 * self.thickness_m
        if self.ends == "square":
            return Polygon(np.array([[-a, -r], [a, -r], [a, r], [-a, r]]))
        elif self.ends == "round":
            c = a - r  # centre of each end's semicircle
            phi = np.linspace(-0.5 * np.pi, 0.5 * np.pi, ROUND_END_SEGMENTS + 1)
            right = np.column_stack([c + r * np.cos(phi), r * np.sin(phi)])
            left = np.column_stack([-c - r * np.cos(phi), -r * np.sin(phi)])  # from the top round to the bottom
            return Polygon(np.vstack([right, left]))
        else:  # unreachable after __post_init__
            raise ValueError(f"ends: {self.ends!r} unknown")

    def describe(self) -> str:
        return (f"flat plate B = {self.chord_m:g} m, t = {self.thickness_m:g} m "
                f"(t/B = {100 * self.thickness_m / self.chord_m:.2g} %), {self.ends} ends")


@dataclass(frozen=True)
class Rectangle(_Section):
    """Sharp-edged rectangular cylinder chord_m x depth_m centred on (0, 0), 0 < depth_m <= chord_m.

    B/D = 5 is the BARC benchmark section (Bruno, Salvetti and Ricciardelli 2014, J. Wind Eng. Ind.
    Aerodyn. 126, 87-106): a bluff section with leading-edge separation and reattachment on the sides.
    """

    name: ClassVar[str] = "rectangle"

    chord_m: float
    depth_m: float

    def __post_init__(self) -> None:
        chord = self._number("chord_m")
        self._number("depth_m", 0.0, chord)

    def polygon(self) -> Polygon:
        a, h = 0.5 * self.chord_m, 0.5 * self.depth_m
        return Polygon(np.array([[-a, -h], [a, -h], [a, h], [-a, h]]))

    def describe(self) -> str:
        return (f"rectangle B = {self.chord_m:g} m, D = {self.depth_m:g} m "
                f"(B/D = {self.chord_m / self.depth_m:.3g})")


@dataclass(frozen=True)
class StreamlinedBox(_Section):
    """Streamlined closed box girder, symmetric fore and aft (defaults: the Great Belt East Bridge).

    Outline (counter-clockwise from the leading edge; b = bottom_flat_fraction B, t = top_flat_fraction B,
    y_n the edge-nose height; ASCII, not to scale)::

                      crown (0, D/2)
         (-t/2) ____-------^-------____ (t/2)      roof: cross_fall down both ways from the centre line
              /                          \\          short upper fairing panels
      nose   <                            >  nose  pointed edges at x = -+B/2, height y_n
              \\                          /          long inclined bottom panels
                \\______________________/
             (-b/2, -D/2)           (b/2, -D/2)    flat bottom

    * chord_m = 31 m: the thesis and Larsen (1993).
    * depth_m = 4.4 m at the centre line (crown to flat bottom): Larsen (1993); SPEC gives 4.0-4.4 m.
    * cross_fall = 0.02: slope of the roof from the centre line to each edge.  ASSUMED (a usual road
      cross-fall; not in the sources available here).
    * bottom_flat_fraction = 0.6: width of the flat bottom / B (18.6 m; inclined panels 6.2 m wide
      each).  ASSUMED (read as typical of the Great Belt drawings; no dimension in the sources here).
    * nose_height_fraction = 0.8: height of the pointed edge above the bottom as a fraction of the box
      depth at the edge line, D - cross_fall B/2 (1 puts the nose on the roof line, the roof then runs
      straight to it and top_flat_fraction has no effect).  ASSUMED: the Great Belt edges lie near the
      top; 0.8 puts the nose 0.82 m below the roof edge and gives upper and lower nose panels of the
      same slope (about 28 degrees) with the defaults.
    * top_flat_fraction = 0.9: width of the roof between the two upper fairing panels / B.  ASSUMED.
    * railings = False: if True, ``polygons()`` adds two thin solid vertical strips standing on the roof
      near the edges, each a separate polygon (``polygon()`` stays the box alone).  railing_height_m
      = 1.0 (ASSUMED), railing_thickness_m = 0.2 (ASSUMED: thicker than a real railing so that a
      grid of about 0.1 m resolves it; real railings are porous, a solid strip is the blockage upper
      bound), railing_inset_m = 0.5 from the roof edge at x = +-t/2 to the strip's outer face
      (ASSUMED).  The strip's base follows the roof line, so it touches the box without overlapping.
      Resolving a strip by two cells needs h <= railing_thickness_m / 2 (0.1 m, 310 cells per B); on
      a coarser grid a strip forces only a few faces and feels no drag.

    Not modelled: the thesis's central railing (its STAR-CCM+ model had lateral and central railings),
    guide vanes, porous railings, hangers and the vertical edges of the real cross-section details.
    """

    name: ClassVar[str] = "streamlined_box"

    chord_m: float = 31.0
    depth_m: float = 4.4
    cross_fall: float = 0.02
    bottom_flat_fraction: float = 0.6
    nose_height_fraction: float = 0.8
    top_flat_fraction: float = 0.9
    railings: bool = False
    railing_height_m: float = 1.0
    railing_thickness_m: float = 0.2
    railing_inset_m: float = 0.5

    def __post_init__(self) -> None:
        chord = self._number("chord_m")
        depth = self._number("depth_m", 0.0, 0.5 * chord)
        fall = self._number("cross_fall", 0.0, 0.1, low_open=False)
        if not fall * 0.5 * chord < depth:  # the roof must stay above the bottom at the edges
            raise InputError(f"{WHERE}.cross_fall", fall,
                             f"allowed range < 2 depth_m/chord_m = {2 * depth / chord:g}")
        self._number("bottom_flat_fraction", 0.0, 1.0, high_open=True)
        self._number("nose_height_fraction", 0.0, 1.0)
        top = self._number("top_flat_fraction", 0.0, 1.0)
        if not isinstance(self.railings, bool):
            raise InputError(f"{WHERE}.railings", self.railings, "must be true or false")
        self._number("railing_height_m", 0.0, depth)
        thickness = self._number("railing_thickness_m", 0.0, 0.05 * chord)
        room = 0.5 * top * chord - thickness  # the strip must stand on the roof
        self._number("railing_inset_m", 0.0, room, low_open=False, high_open=True)

    def _roof(self, x: float) -> float:
        """Height of the roof at x (crown at D/2, falling by cross_fall each way)."""
        return 0.5 * self.depth_m - self.cross_fall * abs(x)

    @property
    def nose_height_m(self) -> float:
        """y of the pointed edges."""
        edge_depth = self.depth_m - self.cross_fall * 0.5 * self.chord_m
        return -0.5 * self.depth_m + self.nose_height_fraction * edge_depth

    def polygon(self) -> Polygon:
        a, h = 0.5 * self.chord_m, 0.5 * self.depth_m
        b = 0.5 * self.bottom_flat_fraction * self.chord_m
        yn = self.nose_height_m
        lower = [(-a, yn), (-b, -h), (b, -h), (a, yn)]
        if self.nose_height_fraction < 1.0:
            t = 0.5 * self.top_flat_fraction * self.chord_m
            upper = [(t, self._roof(t)), (0.0, h), (-t, self._roof(t))]
        else:  # nose on the roof line: the roof runs straight to it
            upper = [(0.0, h)]
        return Polygon(np.array(lower + upper))

    def railing_polygons(self) -> list[Polygon]:
        """The two railing strips (empty unless ``railings``): leading-edge side first."""
        if not self.railings:
            return []
        outer = 0.5 * self.top_flat_fraction * self.chord_m - self.railing_inset_m
        inner = outer - self.railing_thickness_m
        top = self._roof(0.5 * (inner + outer)) + self.railing_height_m
        strips = []
        for s in (-1.0, 1.0):
            x0, x1 = sorted((s * inner, s * outer))
            strips.append(Polygon(np.array([[x0, self._roof(x0)], [x1, self._roof(x1)], [x1, top], [x0, top]])))
        return strips

    def polygons(self) -> list[Polygon]:
        return [self.polygon(), *self.railing_polygons()]

    def describe(self) -> str:
        rail = (f", railings {self.railing_height_m:g} m x {self.railing_thickness_m:g} m"
                if self.railings else "")
        return (f"streamlined box B = {self.chord_m:g} m, D = {self.depth_m:g} m "
                f"(B/D = {self.chord_m / self.depth_m:.3g}), cross-fall {100 * self.cross_fall:g} %, "
                f"flat bottom {self.bottom_flat_fraction:g} B, nose at {self.nose_height_fraction:g} "
                f"of the edge depth{rail}")


class _Shown(str):
    """A value shown in an InputError as it reads (no quotes): a summary of a long list of points."""

    def __repr__(self) -> str:
        return str(self)


def _point_list(key: str, value: Any) -> tuple[tuple[float, float], ...]:
    """A TOML list of [x, y] pairs as a tuple of float pairs (finiteness is checked with the outline)."""
    if not isinstance(value, (list, tuple)) or not value:
        raise InputError(key, value, "must be a list of [x, y] points in metres, e.g. [[0.0, 0.0], [31.0, 0.0], "
                         "[31.0, 4.0], [0.0, 0.0]] (the last repeats the first)")
    out = []
    for i, p in enumerate(value):
        if (not isinstance(p, (list, tuple)) or len(p) != 2
                or any(isinstance(c, bool) or not isinstance(c, (int, float)) for c in p)):
            raise InputError(key, _Shown(f"[... {p!r} ...]"), f"point {i + 1} (counted from 1) is not an [x, y] "
                             "pair of numbers")
        out.append((float(p[0]), float(p[1])))
    return tuple(out)


def _summary(points: tuple[tuple[float, float], ...]) -> _Shown:
    (x0, y0), (x1, y1) = points[0], points[-1]
    return _Shown(f"<{len(points)} points, ({x0:g}, {y0:g}) ... ({x1:g}, {y1:g})>")


@dataclass(frozen=True, eq=False)
class PolygonSection(_Section):
    """Any deck outline: one or more closed polygons (the box, wind screens, guide vanes), in metres.

    Give exactly one of (the TOML keys of ``[deck_section]`` with ``shape = "polygon"``):

    * ``vertices = [[x, y], ...]``: one outline, the last point repeating the first;
    * ``parts = [[[x, y], ...], [[x, y], ...]]``, or one ``[[deck_section.parts]]`` table with a ``vertices``
      key per part: several outlines;
    * ``outline_path = "deck.csv"`` or ``"deck.dxf"`` (relative: to the scenario file's folder, ``base_dir``),
      with ``outline_layer`` to read one layer of a DXF drawing (formats: :mod:`bridge.cfd.outline`).

    Frame: x downwind (the wind meets the smallest x first), y up, in the outline's own coordinates.  The
    *main outline* is the part of largest area (``polygon()``, first in ``polygons()``; the others follow
    in the order given).  ``chord_m`` (B) defaults to the width of all the parts together; it may be given,
    from that width to twice it (B is the CFD's unit of length and the reference length of every
    coefficient; below the width the parts would leave the grid's chord, far above it they would get few of
    its cells).  ``depth_m`` (D) is the height of the main outline (wind screens and vanes do not count, as
    the shipped box's railings do not).  ``reference_point_m = [x, y]`` sets the reference point (rotation
    centre and moment reference), inside the box that holds every part; by default it is the middle of the
    width of all parts at half the main outline's height (the shipped sections' mid-chord, half depth).
    The parts are stored translated so that the reference point is (0, 0): ``outline``, one
    :class:`Polygon` per part, counter-clockwise (a clockwise part is reversed).  The file is read on
    construction: ``dataclasses.replace`` reads it again, from ``base_dir`` if given there (else the working
    directory).

    Every problem raises :class:`InputError` naming ``deck_section.vertices``, ``deck_section.parts[i]``
    (counted from 0) or ``deck_section.outline_path`` and saying where and why
    (:func:`bridge.cfd.outline.check_ring`, :func:`~bridge.cfd.outline.check_parts`).
    """

    name: ClassVar[str] = "polygon"
    max_chord_over_width: ClassVar[float] = 2.0

    vertices: Any = None
    parts: Any = None
    outline_path: str | None = None
    outline_layer: str | None = None
    reference_point_m: Any = None
    chord_m: float | None = None
    base_dir: InitVar[str | Path | None] = None
    outline: tuple[Polygon, ...] = field(init=False, repr=False)

    def __post_init__(self, base_dir: str | Path | None) -> None:
        from .outline import OutlineError, check_parts, check_ring

        rings, keys, values = self._read(base_dir)
        checked = []
        for ring, key, value in zip(rings, keys, values, strict=True):
            try:
                checked.append(check_ring(ring)[0])
            except OutlineError as err:
                raise InputError(key, value, str(err)) from None
        try:
            check_parts(checked, [r.name or k.removeprefix(f"{WHERE}.") for r, k in zip(rings, keys, strict=True)])
        except OutlineError as err:
            raise InputError(keys[err.part], values[err.part], str(err)) from None
        main = max(range(len(checked)), key=lambda i: abs(Polygon(checked[i]).area))
        checked.insert(0, checked.pop(main))
        every = np.vstack(checked)
        lo, hi = every.min(axis=0), every.max(axis=0)
        width = float(hi[0] - lo[0])
        ref = self._reference_point(lo, hi, checked[0])
        if self.chord_m is None:
            object.__setattr__(self, "chord_m", width)
        else:
            chord = check_range(f"{WHERE}.chord_m", self.chord_m)
            if not width * (1 - 1e-9) <= chord <= self.max_chord_over_width * width:
                raise InputError(f"{WHERE}.chord_m", self.chord_m, f"must lie between the width of the parts "
                                 f"together, {width:g} m, and {self.max_chord_over_width:g} times it (or leave it out)")
            object.__setattr__(self, "chord_m", chord)
        object.__setattr__(self, "outline", tuple(Polygon(v - ref) for v in checked))

    def _read(self, base_dir: str | Path | None) -> tuple[list, list[str], list[Any]]:
        """The parts as given (:class:`bridge.cfd.outline.Ring`, unchecked), with the input key and the value
        that an error about each names; the inline lists are stored as tuples of float pairs."""
        from .outline import OutlineError, Ring, read_outline

        given = [k for k in ("vertices", "parts", "outline_path") if getattr(self, k) is not None]
        ways = 'vertices = [[x, y], ...], parts = [[[x, y], ...], ...] or outline_path = "file.csv" / "file.dxf"'
        if not given:
            raise InputError(f"{WHERE}.vertices", None, f"missing: give the outline as {ways}")
        if len(given) > 1:
            raise InputError(f"{WHERE}.{given[1]}", _Shown(f"(given with {given[0]})"),
                             f"give the outline one way: {ways}")
        if self.outline_layer is not None and (not isinstance(self.outline_layer, str) or self.outline_path is None
                                               or not str(self.outline_path).lower().endswith(".dxf")):
            raise InputError(f"{WHERE}.outline_layer", self.outline_layer,
                             "a layer name (a string), with a DXF outline_path only")
        if self.vertices is not None:
            pts = _point_list(f"{WHERE}.vertices", self.vertices)
            object.__setattr__(self, "vertices", pts)
            return [Ring(np.array(pts), ("",) * len(pts))], [f"{WHERE}.vertices"], [_summary(pts)]
        if self.parts is not None:
            if not isinstance(self.parts, (list, tuple)) or not self.parts:
                raise InputError(f"{WHERE}.parts", self.parts, "must be a list of outlines, each a list of [x, y] "
                                 "points in metres, or [[deck_section.parts]] tables with a vertices key")
            parts = []
            for i, part in enumerate(self.parts):
                key = f"{WHERE}.parts[{i}]"
                if isinstance(part, Mapping):  # the [[deck_section.parts]] form
                    table = Table(part, key)
                    part = table.raw("vertices")
                    table.done()
                parts.append(_point_list(key, part))
            object.__setattr__(self, "parts", tuple(parts))
            keys = [f"{WHERE}.parts[{i}]" for i in range(len(parts))]
            return [Ring(np.array(p), ("",) * len(p)) for p in parts], keys, [_summary(p) for p in parts]
        if not isinstance(self.outline_path, str) or not self.outline_path.strip():
            raise InputError(f"{WHERE}.outline_path", self.outline_path, "must be a file name (a string)")
        path = Path(self.outline_path)
        if not path.is_absolute() and base_dir is not None:
            path = Path(base_dir) / path
        try:
            rings = read_outline(path, self.outline_layer)
        except OutlineError as err:
            raise InputError(f"{WHERE}.outline_path", self.outline_path, str(err)) from None
        return rings, [f"{WHERE}.outline_path"] * len(rings), [self.outline_path] * len(rings)

    def _reference_point(self, lo: np.ndarray, hi: np.ndarray, main: np.ndarray) -> np.ndarray:
        """The reference point in the outline's coordinates (``lo``, ``hi``: corners of the box holding every
        part; ``main``: the main outline's vertices); a given one is checked and stored as a float pair."""
        if self.reference_point_m is None:
            return np.array([0.5 * (lo[0] + hi[0]), 0.5 * (main[:, 1].min() + main[:, 1].max())])
        key, given = f"{WHERE}.reference_point_m", self.reference_point_m
        if not isinstance(given, (list, tuple)) or len(given) != 2:
            raise InputError(key, given, "must be [x, y] in metres, in the outline's coordinates")
        ref = np.array([check_range(key, c) for c in given])
        slack = 1e-9 * float(np.max(hi - lo))
        if np.any(ref < lo - slack) or np.any(ref > hi + slack):
            raise InputError(key, given, f"must lie within the box that holds every part: x from {lo[0]:g} to "
                             f"{hi[0]:g}, y from {lo[1]:g} to {hi[1]:g} m")
        object.__setattr__(self, "reference_point_m", (float(ref[0]), float(ref[1])))
        return ref

    @property
    def depth_m(self) -> float:
        """D: the height of the main outline."""
        return float(np.ptp(self.outline[0].vertices[:, 1]))

    def polygon(self) -> Polygon:
        return self.outline[0]

    def polygons(self) -> list[Polygon]:
        return list(self.outline)

    def to_mapping(self) -> dict[str, Any]:
        out: dict[str, Any] = {"shape": self.name}
        for key in ("vertices", "parts", "outline_path", "outline_layer", "reference_point_m"):
            value = getattr(self, key)
            if value is not None:
                out[key] = _lists(value)
        out["chord_m"] = self.chord_m
        return out

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, PolygonSection):
            return NotImplemented
        mine, theirs = self.outline, other.outline
        return (self.to_mapping() == other.to_mapping() and len(mine) == len(theirs)
                and all(np.array_equal(a.vertices, b.vertices) for a, b in zip(mine, theirs, strict=True)))

    def __hash__(self) -> int:
        return hash((self.name, self.chord_m, tuple(p.vertices.tobytes() for p in self.outline)))

    def describe(self) -> str:
        source = "inline" if self.outline_path is None else self.outline_path
        layer = f" (layer {self.outline_layer})" if self.outline_layer is not None else ""
        n = len(self.outline)
        return (f"polygon outline from {source}{layer}, {n} part{'s' if n != 1 else ''}, B = {self.chord_m:.4g} m, "
                f"D = {self.depth_m:.4g} m (B/D = {self.chord_m / self.depth_m:.3g})")


def _lists(value: Any) -> Any:
    """Nested tuples as nested lists (a TOML-like mapping)."""
    return [_lists(v) for v in value] if isinstance(value, (list, tuple)) else value


SECTIONS: dict[str, type[_Section]] = {
    "flat_plate": FlatPlate,
    "rectangle": Rectangle,
    "streamlined_box": StreamlinedBox,
    "polygon": PolygonSection,
}


def section_from_mapping(mapping: Mapping[str, Any], where: str = WHERE,
                         base_dir: str | Path | None = None) -> _Section:
    """Validate a scenario's ``[deck_section]`` table and build the section.

    ``shape`` is a key of :data:`SECTIONS`; the other keys are that dataclass's fields.  A missing
    ``shape`` or required field, an unknown key, a wrong type or a value out of range raises
    :class:`InputError` naming ``<where>.<key>``.  ``base_dir``: the folder a relative ``outline_path``
    (shape "polygon") is taken from, the scenario file's (default: the working directory); the file is
    read and checked here.
    """
    table = Table(mapping, where)
    cls = SECTIONS[table.string("shape", choices=tuple(SECTIONS))]
    values = {}
    for f in fields(cls):
        if not f.init:  # computed from the others (PolygonSection.outline)
            continue
        default = f.default if f.default is not MISSING else ...
        values[f.name] = table.raw(f.name, default)
    table.done()
    if cls is PolygonSection:
        values["base_dir"] = base_dir
    try:
        return cls(**values)
    except InputError as err:  # re-key the dataclass's own error under the caller's table name
        if where == WHERE:
            raise
        raise InputError(where + err.key[len(WHERE):], err.value, err.allowed) from None


def great_belt_section() -> StreamlinedBox:
    """The Great Belt East Bridge girder with the documented defaults (no railings)."""
    return StreamlinedBox()
