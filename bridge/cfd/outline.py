"""Deck outlines of any shape: reading and checking the closed polygons of a ``shape = "polygon"`` deck.

An outline is one or more *parts* (the deck box, a wind screen, guide vanes), each a closed polygon in
metres, x downwind and y up.  They come from the scenario's own lists or from a file:

* CSV: one point a row, columns ``x, y`` and an optional ``part`` (a label; the rows of one part
  together), an optional header row naming the columns, blank lines and ``#`` comments ignored;
* DXF (read with the ezdxf library): every LWPOLYLINE and 2D POLYLINE of the model space is a part
  (optionally only those on one layer); arcs (bulges) are cut into straight segments whose distance
  from the arc is at most ``ARC_TOLERANCE`` of the polyline's size; the drawing's ``$INSUNITS`` gives
  the unit (none: metres).

Every part is checked (:func:`check_ring`): finite coordinates, closed (the last point repeats the
first, so that a list cut short is caught; a DXF polyline may instead carry the closed flag), at least
three distinct points, an area, no edge crossing or touching another edge of the same part; then the
parts together (:func:`check_parts`): no part crosses, touches or lies inside another.  Repeated
consecutive points are dropped; a clockwise part is reversed (:class:`bridge.cfd.bodies.Polygon` is
counter-clockwise).  A problem raises :class:`OutlineError` with a message that says where (row of
the CSV file, polyline of the drawing, coordinates) and why; the caller names the input key.

The geometry helpers (orientation, segment intersection, point in polygon) are the textbook
predicates (e.g. de Berg et al., "Computational Geometry", 3rd ed., ch. 1-2), applied in coordinates
scaled by the outline's size with a relative tolerance ``TOLERANCE``: points closer than that to a
line count as on it, so that touching is found in spite of rounding.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["OutlineError", "Ring", "orientation", "segment_intersection", "point_in_polygon", "signed_area",
           "check_ring", "check_parts", "read_outline", "read_csv", "read_dxf", "MAX_POINTS", "ARC_TOLERANCE"]

TOLERANCE = 1e-9      # relative to the outline's size: closure, duplicate points, "on a line"
ARC_TOLERANCE = 1e-4  # DXF bulges: largest distance of a segment from its arc, relative to the polyline's size
MAX_POINTS = 2000     # points of one part: far more than the finest preset resolves (80 cells per chord), and
# the outline is stored among the scenario's inputs in results.h5, whose attributes hold at most 64 KiB each


class OutlineError(ValueError):
    """A deck outline that cannot be used; ``part``: index of the part concerned (None: the whole outline)."""

    def __init__(self, message: str, part: int | None = None):
        super().__init__(message)
        self.part = part


@dataclass(frozen=True)
class Ring:
    """One part as read, before checking: ``points`` (n, 2) in metres, the closing point included;
    ``labels`` where each point came from ("row 12"; "" inline), ``name`` the part in messages ("" when
    the input key names it), ``closed`` whether the source marks it closed (a DXF flag), ``open_hint`` what
    to do about a part that is not closed."""

    points: np.ndarray
    labels: tuple[str, ...]
    name: str = ""
    closed: bool = False
    open_hint: str = "a list or file that ends early looks like this"


# ------------------------------------------------------------------------------------------- geometry
def orientation(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Twice the signed area of the triangle a, b, c: > 0 counter-clockwise, < 0 clockwise, 0 on one line
    (arrays of points broadcast)."""
    return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])


def signed_area(v: np.ndarray) -> float:
    """Shoelace area of the closed polygon v (n, 2), the last point joined to the first; > 0 counter-clockwise."""
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _within(a, b, c, eps):
    """c inside the bounding box of segment ab (grown by eps): with c on the line ab, c lies on the segment."""
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    return np.all((lo - eps <= c) & (c <= hi + eps), axis=-1)


def _hits(p1, p2, q1, q2, size: float):
    """Mask over the segments q1q2 (arrays) that cross or touch the segment p1p2, to TOLERANCE of ``size``."""
    eps = TOLERANCE * size * size  # of the orientation test, an area
    d1, d2 = orientation(q1, q2, p1), orientation(q1, q2, p2)
    d3, d4 = orientation(p1, p2, q1), orientation(p1, p2, q2)
    s1, s2, s3, s4 = (np.where(np.abs(d) <= eps, 0, np.sign(d)) for d in (d1, d2, d3, d4))
    proper = (s1 * s2 < 0) & (s3 * s4 < 0)
    e = TOLERANCE * size
    touch = (((s1 == 0) & _within(q1, q2, p1, e)) | ((s2 == 0) & _within(q1, q2, p2, e))
             | ((s3 == 0) & _within(p1, p2, q1, e)) | ((s4 == 0) & _within(p1, p2, q2, e)))
    return proper | touch


def segment_intersection(p1: Sequence[float], p2: Sequence[float], q1: Sequence[float], q2: Sequence[float],
                         size: float | None = None) -> np.ndarray | None:
    """A point the segments p1p2 and q1q2 share (their crossing, or a touching end point), or None.

    Points closer than TOLERANCE ``size`` (default: the extent of the four points) to a segment count as on it."""
    p1, p2, q1, q2 = (np.asarray(v, dtype=float) for v in (p1, p2, q1, q2))
    if size is None:
        size = float(np.ptp(np.array([p1, p2, q1, q2]), axis=0).max())
    size = max(size, 1e-300)
    if not _hits(p1, p2, q1[None], q2[None], size)[0]:
        return None
    r, s = p2 - p1, q2 - q1
    denom = float(r[0] * s[1] - r[1] * s[0])
    if abs(denom) > TOLERANCE * size * size:  # not parallel: the crossing of the two lines
        t = float((q1 - p1)[0] * s[1] - (q1 - p1)[1] * s[0]) / denom
        return p1 + min(max(t, 0.0), 1.0) * r
    for c, a, b in ((p1, q1, q2), (p2, q1, q2), (q1, p1, p2), (q2, p1, p2)):  # parallel: an end point on the other
        if abs(float(orientation(a, b, c))) <= TOLERANCE * size * size and _within(a, b, c, TOLERANCE * size):
            return c.copy()
    return None  # pragma: no cover - _hits found a contact


def point_in_polygon(point: Sequence[float], v: np.ndarray) -> bool:
    """Whether ``point`` lies inside the closed polygon v (n, 2) (even-odd rule, a ray towards +x)."""
    x, y = float(point[0]), float(point[1])
    x1, y1 = v[:, 0], v[:, 1]
    x2, y2 = np.roll(x1, -1), np.roll(y1, -1)
    straddle = (y1 > y) != (y2 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
    return bool(np.count_nonzero(straddle & (x < xc)) % 2)


def _first_contact(v: np.ndarray, w: np.ndarray | None, size: float):
    """The first pair of edges (i of v, j of w) that cross or touch, and the shared point; ``w`` None: the
    edges of v against each other, neighbours excepted (they share a vertex) unless they fold back onto
    each other (a spike of no width)."""
    same = w is None
    w = v if same else w
    a, b = v, np.roll(v, -1, axis=0)
    c, d = w, np.roll(w, -1, axis=0)
    lo, hi = np.minimum(c, d), np.maximum(c, d)
    n, e = len(v), TOLERANCE * size
    for i in range(n):
        if same:
            k = (i + 1) % n  # the next edge, from b[i]: collinear and turning back?
            if (abs(float(orientation(a[i], b[i], b[k]))) <= TOLERANCE * size * size
                    and float(np.dot(b[i] - a[i], b[k] - a[k])) < 0):
                return i, k, b[i].copy()
            js = np.arange(i + 2, n - 1 if i == 0 else n)
        else:
            js = np.arange(len(w))
        near = js[(lo[js, 0] <= max(a[i, 0], b[i, 0]) + e) & (hi[js, 0] >= min(a[i, 0], b[i, 0]) - e)
                  & (lo[js, 1] <= max(a[i, 1], b[i, 1]) + e) & (hi[js, 1] >= min(a[i, 1], b[i, 1]) - e)]
        if near.size:
            hit = _hits(a[i], b[i], c[near], d[near], size)
            if hit.any():
                j = int(near[np.argmax(hit)])
                return i, j, segment_intersection(a[i], b[i], c[j], d[j], size)
    return None


# ------------------------------------------------------------------------------------------- checking
def _pt(p) -> str:
    return f"({float(p[0]):.6g}, {float(p[1]):.6g})"


def _at(labels: Sequence[str], v: np.ndarray, i: int) -> str:
    """Point i in words: its source (a CSV row) and coordinates."""
    return f"{labels[i]} {_pt(v[i])}" if labels[i] else _pt(v[i])


def _edge(labels: Sequence[str], v: np.ndarray, i: int) -> str:
    j = (i + 1) % len(v)
    return f"the edge from {_at(labels, v, i)} to {_at(labels, v, j)}"


def check_ring(ring: Ring) -> tuple[np.ndarray, tuple[str, ...]]:
    """Check one part (see the module docstring) and return its vertices, counter-clockwise, without the
    closing point and without repeated consecutive points, with their labels.  Raises OutlineError."""
    name = f"{ring.name}: " if ring.name else ""
    p = np.asarray(ring.points, dtype=float)
    labels = tuple(ring.labels)
    if p.ndim != 2 or p.shape[1] != 2 or len(p) == 0:
        raise OutlineError(f"{name}no points")
    bad = np.nonzero(~np.isfinite(p).all(axis=1))[0]
    if bad.size:
        i = int(bad[0])
        where = labels[i] or f"point {i + 1} (counted from 1)"
        raise OutlineError(f"{name}{where} is {_pt(p[i])}: every coordinate must be a finite number")
    size = float(np.ptp(p, axis=0).max())
    close = TOLERANCE * max(size, 1e-300)
    if not np.all(np.abs(p[-1] - p[0]) <= close):
        if not ring.closed:
            raise OutlineError(f"{name}not closed: the last point, {_at(labels, p, len(p) - 1)}, must repeat the "
                               f"first, {_at(labels, p, 0)} ({ring.open_hint})")
    else:
        p, labels = p[:-1], labels[:-1]
    if len(p) < 3:
        raise OutlineError(f"{name}fewer than 3 distinct points")
    keep = [0]
    for i in range(1, len(p)):  # repeated consecutive points are dropped
        if np.any(np.abs(p[i] - p[keep[-1]]) > close):
            keep.append(i)
    while len(keep) > 1 and np.all(np.abs(p[keep[-1]] - p[keep[0]]) <= close):
        keep.pop()
    p, labels = p[keep], tuple(labels[i] for i in keep)
    if len(np.unique(p, axis=0)) < 3:
        raise OutlineError(f"{name}fewer than 3 distinct points ({len(p)} after dropping repeated ones)")
    if len(p) > MAX_POINTS:
        raise OutlineError(f"{name}{len(p)} points, more than {MAX_POINTS}: simplify the outline (the finest "
                           "preset's grid has 80 cells per chord; arcs need a few segments each)")
    far = p[int(np.argmax(np.hypot(*(p - p[0]).T)))]
    if np.abs(orientation(p[0], far, p)).max() <= TOLERANCE * size * size:
        raise OutlineError(f"{name}encloses no area: its points lie on one line")
    hit = _first_contact(p, None, size)
    if hit is not None:
        i, j, at = hit
        raise OutlineError(f"{name}crosses itself: {_edge(labels, p, i)} meets {_edge(labels, p, j)} at {_pt(at)}")
    area = signed_area(p)  # a simple polygon that is not a line has an area
    if area < 0:  # clockwise: reversed
        p, labels = p[::-1].copy(), labels[::-1]
    return p, labels


def check_parts(parts: Sequence[np.ndarray], names: Sequence[str]) -> None:
    """Raise OutlineError (``part``: the later part's index) if two checked parts cross, touch or nest."""
    allp = np.vstack(parts)
    size = float(np.ptp(allp, axis=0).max())
    for j in range(len(parts)):
        for i in range(j):
            v, w = parts[i], parts[j]
            if (v[:, 0].min() > w[:, 0].max() + TOLERANCE * size or w[:, 0].min() > v[:, 0].max() + TOLERANCE * size
                    or v[:, 1].min() > w[:, 1].max() + TOLERANCE * size
                    or w[:, 1].min() > v[:, 1].max() + TOLERANCE * size):
                continue
            hit = _first_contact(v, w, size)
            if hit is not None:
                a, b, at = hit
                raise OutlineError(f"{names[j]} touches or crosses {names[i]} at {_pt(at)}: an edge of {names[j]} "
                                   f"from {_pt(w[b])} to {_pt(w[(b + 1) % len(w)])} meets the edge of {names[i]} from "
                                   f"{_pt(v[a])} to {_pt(v[(a + 1) % len(v)])}; parts must stand apart (leave a gap, "
                                   "or draw touching parts as one outline)", j)
            if point_in_polygon(w[0], v) or point_in_polygon(v[0], w):
                inner, outer = (names[j], names[i]) if point_in_polygon(w[0], v) else (names[i], names[j])
                raise OutlineError(f"{inner} lies inside {outer}: parts must stand apart (a hollow is not "
                                   "modelled: the flow never enters a closed box)", j)


# ------------------------------------------------------------------------------------------- reading
def read_outline(path: Path, layer: str | None = None) -> list[Ring]:
    """The parts of the outline file ``path`` (.csv or .dxf; ``layer`` for DXF only), unchecked.
    Raises OutlineError for a file that is missing, of another kind or unreadable."""
    path = Path(path)
    kind = path.suffix.lower()
    if kind not in (".csv", ".dxf"):
        raise OutlineError(f"is not a CSV (.csv) or DXF (.dxf) file (its name ends in {path.suffix or 'nothing'!r})")
    if not path.is_file():
        raise OutlineError(f"file not found (looked for {path.resolve()})")
    if layer is not None and kind != ".dxf":
        raise OutlineError("outline_layer applies to a DXF file only")
    return read_csv(path) if kind == ".csv" else read_dxf(path, layer)


_HEADER = {"x": "x", "x_m": "x", "y": "y", "y_m": "y", "part": "part"}


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _number(cell: str, row: int, column: str) -> float:
    try:
        value = float(cell)
    except ValueError:
        raise OutlineError(f"row {row}, column {column}: {cell!r} is not a number") from None
    if not math.isfinite(value):
        raise OutlineError(f"row {row}, column {column}: {cell!r} is not a finite number")
    return value


def read_csv(path: Path) -> list[Ring]:
    """Parts of a CSV outline (see the module docstring).  Rows are the file's lines, counted from 1."""
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise OutlineError("is not a text (UTF-8) CSV file") from None
    rows = []
    reader = csv.reader(text.splitlines())
    for cells in reader:
        cells = [c.strip() for c in cells]
        if not any(cells) or cells[0].startswith("#"):
            continue
        if len(cells) == 1 and any(sep in cells[0] for sep in ";\t"):
            raise OutlineError(f"row {reader.line_num}: separate the values by commas (x, y[, part])")
        rows.append((reader.line_num, cells))
    if not rows:
        raise OutlineError("holds no points: one row per point, x, y in metres (and an optional part column)")
    columns = ["x", "y"] if len(rows[0][1]) < 3 else ["x", "y", "part"]
    first_row, first = rows[0]
    if not any(_is_number(c) for c in first):  # a header
        names = [_HEADER.get(c.lower()) for c in first]
        if None in names or "x" not in names or "y" not in names or len(set(names)) != len(names):
            raise OutlineError(f"row {first_row}: the header {', '.join(first)} must name the columns x, y and "
                               "optionally part (each once)")
        columns = names
        rows = rows[1:]
        if not rows:
            raise OutlineError("holds a header but no points")
    ix, iy = columns.index("x"), columns.index("y")
    ip = columns.index("part") if "part" in columns else None
    parts: dict[str, list] = {}
    order: list[str] = []
    for row, cells in rows:
        if len(cells) != len(columns):
            raise OutlineError(f"row {row}: {len(cells)} values, expected {len(columns)} ({', '.join(columns)}) "
                               "separated by commas")
        label = cells[ip] if ip is not None else ""
        if ip is not None and not label:
            raise OutlineError(f"row {row}, column part: empty (every row names its part)")
        if label not in parts:
            parts[label] = []
            order.append(label)
        elif order[-1] != label:
            raise OutlineError(f"row {row}: part {label!r} again after part {order[-1]!r}: the rows of one part "
                               "must follow each other")
        parts[label].append((row, _number(cells[ix], row, "x"), _number(cells[iy], row, "y")))
    rings = []
    for label in order:
        pts = parts[label]
        name = f"part {label!r} (rows {pts[0][0]}-{pts[-1][0]})" if ip is not None else ""
        rings.append(Ring(np.array([[x, y] for _, x, y in pts]), tuple(f"row {r}" for r, _, _ in pts), name))
    return rings


def read_dxf(path: Path, layer: str | None = None) -> list[Ring]:
    """Parts of a DXF outline (see the module docstring), in metres, in the order of the model space."""
    import ezdxf
    from ezdxf import path as dxf_path
    from ezdxf import units

    try:
        doc = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFError, UnicodeDecodeError, ValueError) as err:
        raise OutlineError(f"is not a readable DXF file ({type(err).__name__}: {err})") from None
    code = int(doc.header.get("$INSUNITS", 0) or 0)
    try:
        factor = 1.0 if code == 0 else float(units.conversion_factor(code, units.M))
    except (KeyError, ValueError, TypeError):
        raise OutlineError(f"the drawing's unit ($INSUNITS = {code}) is not a length ezdxf knows: save it in "
                           "mm, cm or m") from None
    rings, layers = [], []
    count = 0
    for e in doc.modelspace().query("LWPOLYLINE POLYLINE"):
        if e.dxftype() == "POLYLINE" and not e.is_2d_polyline:
            continue  # 3D polylines and meshes
        layers.append(e.dxf.layer)
        if layer is not None and e.dxf.layer.lower() != layer.lower():
            continue
        count += 1
        closed = bool(e.closed if e.dxftype() == "LWPOLYLINE" else e.is_closed)
        p = dxf_path.make_path(e)
        corners = np.array([(v.x, v.y) for v in p.control_vertices()], dtype=float).reshape(-1, 2)
        size = float(np.ptp(corners, axis=0).max()) if len(corners) else 0.0
        pts = np.array([(v.x, v.y) for v in p.flattening(max(ARC_TOLERANCE * size, 1e-12))],
                       dtype=float).reshape(-1, 2) * factor
        name = f"polyline {count} ({e.dxftype()} on layer {e.dxf.layer!r}, handle {e.dxf.handle})"
        rings.append(Ring(pts, ("",) * len(pts), name, closed, "mark the polyline closed in the drawing, or put the "
                          "outline on a layer of its own and name it with outline_layer"))
    if not rings:
        where = f" on layer {layer!r}" if layer is not None else ""
        found = f" (polylines are on layers {', '.join(sorted(set(layers)))})" if layers else ""
        raise OutlineError(f"holds no closed polyline{where}{found}: draw the outline as closed polylines "
                           "(LWPOLYLINE or 2D POLYLINE in the model space, one per part)")
    return rings
