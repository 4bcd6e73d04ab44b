"""Deck cross-sections the aerodynamic stage moves in the CFD: thin flat plate, B/D = 5 rectangle,
streamlined closed box (the Great Belt East Bridge girder).

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
:func:`section_from_mapping`.

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
from dataclasses import MISSING, dataclass, fields
from typing import Any, ClassVar

import numpy as np

from ..errors import InputError, check_range
from .bodies import Polygon

__all__ = ["FlatPlate", "Rectangle", "StreamlinedBox", "SECTIONS", "section_from_mapping",
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


SECTIONS: dict[str, type[_Section]] = {
    "flat_plate": FlatPlate,
    "rectangle": Rectangle,
    "streamlined_box": StreamlinedBox,
}


def section_from_mapping(mapping: Mapping[str, Any], where: str = WHERE) -> _Section:
    """Validate a scenario's ``[deck_section]`` table and build the section.

    ``shape`` is a key of :data:`SECTIONS`; the other keys are that dataclass's fields.  A missing
    ``shape`` or required field, an unknown key, a wrong type or a value out of range raises
    :class:`InputError` naming ``<where>.<key>``.
    """
    from ..config import _Table  # the scenario reader's key tracking (one validation path); lazy:
    # bridge.config may read [deck_section] through this module

    table = _Table(mapping, where)
    cls = SECTIONS[table.string("shape", choices=tuple(SECTIONS))]
    values = {}
    for f in fields(cls):
        default = f.default if f.default is not MISSING else ...
        values[f.name] = table.raw(f.name, default)
    table.done()
    try:
        return cls(**values)
    except InputError as err:  # re-key the dataclass's own error under the caller's table name
        if where == WHERE:
            raise
        raise InputError(where + err.key[len(WHERE):], err.value, err.allowed) from None


def great_belt_section() -> StreamlinedBox:
    """The Great Belt East Bridge girder with the documented defaults (no railings)."""
    return StreamlinedBox()
