"""The aero stage's presets and the flows they build, for a deck section in a uniform wind.

A preset (:class:`Quality`) is three things: the grid (:class:`GridSpec`: cells per chord, domain, one grid
or the overset pair), the physics (:class:`Physics`: Reynolds number, turbulence model and wall treatment)
and the run (:class:`RunLength`: Courant number, periods run and dropped, how long a section is held).
Every setting is checked in one place, its part's constructor, and a bad value raises
:class:`bridge.errors.InputError` naming the ``aero.`` key.  The shipped presets are :data:`QUALITY`;
:func:`preset` picks one on a grid, and :meth:`Quality.with_` changes any setting by name::

    from bridge.aero.presets import preset, build_flow, section_polygons
    q = preset("quick", "overset").with_(turbulence="sst", reynolds=1.05e8)
    flow = build_flow(q, section_polygons(section), case)   # a bridge.cfd.flow.Flow
    bridge.cfd.run(flow, case.end_time(q), monitors=[...])

The CFD runs in units of the chord and the wind speed (B = 1, V = 1, rho = 1, nu = 1 / Re).
:func:`build_flow` makes the preset's flow for the section's polygons (chord 1) and a case (anything with
``motion()`` and ``excursion(radius)``: bridge.aero.forced_motion's ForcedCase and StaticCase): one grid with
the section immersed and moving on it, or the overset pair with the section fixed in a body grid that moves
with it; with ``turbulence = "sst"`` the flow owns a k-omega SST model, which it advances itself.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from bridge.errors import InputError, check_range

__all__ = ["GridSpec", "Physics", "RunLength", "Quality", "QUALITY", "SHORT_DOMAIN_40", "preset", "GRIDS",
           "TURBULENCE", "SST_WALLS", "USER_SST_WALLS", "check_flow_model", "build_flow", "preset_grid",
           "section_polygons"]

GRIDS = ("single", "overset", "body_fitted")
TURBULENCE = ("laminar", "sst")
SST_WALLS = ("equilibrium", "function", "blended", "resolved")
USER_SST_WALLS = SST_WALLS[:3]   # "resolved" is a diagnostic of the tools, not a scenario's choice


def check_flow_model(turbulence: str, sst_walls: str, walls: tuple[str, ...] = SST_WALLS) -> None:
    """The turbulence model and the wall treatment: names checked here only (a scenario's [aero] and a
    preset's :class:`Physics` both call this)."""
    if turbulence not in TURBULENCE:
        raise InputError("aero.turbulence", turbulence, f"one of {', '.join(TURBULENCE)}")
    if sst_walls not in walls:
        raise InputError("aero.sst_walls", sst_walls, f"one of {', '.join(walls)}")


@dataclass(frozen=True)
class GridSpec:
    """The grid of a preset, in chords.  x is uniform (the direct Poisson solver); y is uniform with spacing
    ``dy_over_dx`` dx in a core band (half height ``core_half_height`` at least, the body's reach with 4 cells
    to spare) around the deck and stretches by ``stretch`` beyond, to ``half_height``.  ``overset``: the
    section in a body grid of this spacing reaching ``body_margin`` chords (at least 6 background cells)
    beyond it, over a background whose cells are ``background_coarsening`` times larger; else one grid, the
    section an immersed body moving on it."""

    cells_per_chord: int
    dy_over_dx: float
    upstream: float
    downstream: float
    half_height: float
    core_half_height: float
    stretch: float = 1.08
    overset: bool = False
    background_coarsening: int = 2
    body_margin: float = 0.35
    # the body-fitted grid (bridge.cfd.curvilinear, bridge.cfd.body_fitted): an O-grid round the section reaching
    # body_margin chords beyond it, over the overset pair's background; its wall cells first_height chords
    # high (0: 0.1 / cells_per_chord), each layer growth times thicker, around_per_chord nodes per chord of the
    # outline (0: 2 cells_per_chord)
    body_fitted: bool = False
    first_height: float = 0.0
    growth: float = 1.1
    around_per_chord: float = 0.0

    def __post_init__(self):
        check_range("aero.cells_per_chord", self.cells_per_chord, 8, 2000)
        check_range("aero.dy_over_dx", self.dy_over_dx, 0.05, 1.0)
        check_range("aero.upstream", self.upstream, 0.25, 1000.0)
        check_range("aero.downstream", self.downstream, 0.5, 1000.0)
        check_range("aero.core_half_height", self.core_half_height, 0.0, 100.0)
        check_range("aero.half_height", self.half_height, self.core_half_height, 1000.0)
        check_range("aero.stretch", self.stretch, 1.0, 1.5, low_open=False)
        check_range("aero.background_coarsening", self.background_coarsening, 1, 16)
        check_range("aero.body_margin", self.body_margin, 0.05, 5.0)
        check_range("aero.first_height", self.first_height, 0.0, 0.1)
        check_range("aero.growth", self.growth, 1.0, 1.2)
        check_range("aero.around_per_chord", self.around_per_chord, 0.0, 5000.0)
        if self.body_fitted and self.overset:
            raise InputError("aero.grid", "overset and body_fitted", "one of them")


@dataclass(frozen=True)
class Physics:
    """The flow's physics: the Reynolds number V B / nu; "laminar", or "sst" (k-omega SST-2003,
    bridge.cfd.turbulence) with the section's walls treated by ``sst_walls`` ("equilibrium": Spalding's wall
    function with the log layer's own production of k, the presets'; "function": the same with the model's
    production; "blended": the no-slip profile where the layer is laminar, under study; "resolved": a
    diagnostic for grids whose first cell lies in the viscous sublayer)."""

    reynolds: float
    turbulence: str = "laminar"
    sst_walls: str = "equilibrium"

    def __post_init__(self):
        check_flow_model(self.turbulence, self.sst_walls)
        check_range("aero.reynolds", self.reynolds, 1.0, 1e6 if self.turbulence == "laminar" else 1e10)


@dataclass(frozen=True)
class RunLength:
    """How a case steps and how long it runs: the Courant number; forced motion runs ``periods`` periods of
    its lowest frequency and fits all but the first ``discard_periods`` (more if they last less than
    ``settle_time`` convective times B / V); a section held still runs ``static_duration`` B / V."""

    cfl: float = 0.5
    periods: int = 5
    discard_periods: int = 2
    static_duration: float = 30.0
    settle_time: float = 16.0

    def __post_init__(self):
        check_range("aero.cfl", self.cfl, 0.0, 1.0)
        check_range("aero.static_duration", self.static_duration, 1.0, 1e4)
        check_range("aero.settle_time", self.settle_time, 0.0, 1e4)
        if not (0 < self.discard_periods < self.periods):
            raise InputError("aero.discard_periods", self.discard_periods,
                             f"must be >= 1 and below periods ({self.periods})")


_PARTS = {"grid": GridSpec, "physics": Physics, "run": RunLength}


@dataclass(frozen=True)
class Quality:
    """A named preset: its grid, physics and run (module doc)."""

    name: str
    grid: GridSpec
    physics: Physics
    run: RunLength

    def with_(self, **changes) -> Quality:
        """This preset with settings changed by name (``name`` or any field of its three parts), each checked
        by its part: ``q.with_(cells_per_chord=24, reynolds=1e7, static_duration=1.0)``."""
        parts = {}
        name = changes.pop("name", self.name)
        for part, cls in _PARTS.items():
            own = {f.name for f in fields(cls)}
            mine = {k: changes.pop(k) for k in list(changes) if k in own}
            parts[part] = replace(getattr(self, part), **mine) if mine else getattr(self, part)
        if changes:
            key = sorted(changes)[0]
            raise InputError(f"aero.{key}", changes[key], "unknown preset setting; known: " + ", ".join(
                f.name for cls in _PARTS.values() for f in fields(cls)))
        return Quality(name, **parts)


def _quality(name: str, cells: int, dy_over_dx: float, upstream: float, downstream: float, half_height: float,
             core: float, reynolds: float, **run) -> Quality:
    return Quality(name, GridSpec(cells, dy_over_dx, upstream, downstream, half_height, core), Physics(reynolds),
                   RunLength(**run))


# The presets: laminar at a low Reynolds number as shipped; the aero stage sets the deck's own Reynolds number
# and the SST model from the scenario's [aero] table (bridge.aero.stage).
QUALITY = {
    "tiny": _quality("tiny", 12, 0.5, 1.0, 2.0, 1.0, 0.25, 500.0, periods=3, discard_periods=1, static_duration=6.0,
                     settle_time=2.0),
    # quick, standard and fine share one domain and halve the cell from one to the next: a grid sequence.
    # The wake must be long: with 3 chords of it the lift of a pitching plate came out 25 % high, with 10
    # chords 13 %, with 20 chords within 0.3 % of Theodorsen (docs/aero.md).  quick: a first look in minutes,
    # not a converged answer (its distance from the finer presets: bridge/aero/accuracy.py); one period
    # dropped instead of two (the fits of periods 2-3 and 3-4 of the deck's runs agreed within 1.3 %) and
    # statics of 20 B/V (settled to 0.5 % after 10 B/V).
    "quick": _quality("quick", 16, 0.25, 3.0, 20.0, 3.0, 0.2, 1000.0, periods=3, discard_periods=1,
                      static_duration=20.0),
    "standard": _quality("standard", 40, 0.25, 3.0, 20.0, 3.0, 0.2, 1000.0, periods=4, discard_periods=2),
    "fine": _quality("fine", 80, 0.25, 3.0, 20.0, 3.0, 0.2, 2000.0, periods=5, discard_periods=2,
                     static_duration=40.0),
}

# 40 cells per chord on a short domain (2 chords upstream, 10 down, 2 to each side): the grid of the tools'
# and tests' reference runs that predate the long wake (docs/aero.md); not a user preset.
SHORT_DOMAIN_40 = _quality("short-domain-40", 40, 0.25, 2.0, 10.0, 2.0, 0.2, 1000.0, periods=4, discard_periods=2)


def preset(quality: str, grid: str = "single") -> Quality:
    """The preset named ``quality`` on one grid ("single") or on the overset pair ("overset")."""
    if quality not in QUALITY:
        raise InputError("aero.quality", quality, f"one of {', '.join(QUALITY)}")
    if grid not in GRIDS:
        raise InputError("aero.grid", grid, f"one of {', '.join(GRIDS)}")
    return QUALITY[quality].with_(overset=grid == "overset", body_fitted=grid == "body_fitted")


def section_polygons(section) -> list:
    """Every part of a deck section (bridge.cfd.sections: the box and any railings, or a polygon outline's
    parts) as CFD polygons scaled to chord 1, the CFD's unit of length."""
    from bridge.cfd import Polygon

    return [Polygon(p.vertices / section.chord_m) for p in section.polygons()]


def preset_grid(q: Quality, reach: float, h: float | None = None, upstream: float | None = None,
                downstream: float | None = None, side_cells: int = 0):
    """The preset's Cartesian grid (single grid, or the overset pair's background); its uniform core band
    holds the body wherever the motion takes it (``reach``: largest |y| of the body over the motion) with 4
    cells to spare.  ``h`` (default the preset's dx), ``upstream``, ``downstream`` override the preset's;
    ``side_cells``: cells kept between the core and the sides at least (the sides move out if needed)."""
    from bridge.cfd import CartesianGrid, stretched_faces

    g = q.grid
    h = 1.0 / g.cells_per_chord if h is None else h
    up = g.upstream if upstream is None else upstream
    down = g.downstream if downstream is None else downstream
    nx = int(round((up + down) / h))
    x = np.linspace(-up, down, nx + 1)
    core = max(g.core_half_height, reach + 4 * h)
    half = max(g.half_height, core + side_cells * h)
    y = stretched_faces(-half, half, (-core, core), g.dy_over_dx * h, g.stretch)
    return CartesianGrid(x, y)


def build_flow(q: Quality, polygons: list, case, threads: int | None = None):
    """The preset's flow (bridge.cfd.flow.Flow) for the section's ``polygons`` (chord 1, moving together; their
    loads are summed) in a uniform stream V = 1 from the left, moved as ``case`` says: a ``Simulation`` with the
    section immersed (``q.grid.overset`` False) or an ``OversetPair``; with ``q.physics.turbulence = "sst"`` the
    flow owns a k-omega SST model at the freestream's turbulence.  ``threads``: CPU threads of the step
    (default 1 below 20 000 cells, where waiting for a second thread costs more than it saves, else 2; the
    numbers do not depend on it).  A section and motion that the preset's domain cannot hold raise InputError
    (``aero.quality``)."""
    polygons = list(polygons)
    if not polygons:
        raise ValueError("build_flow: no polygon")
    _check_fits(q, polygons, case)
    if q.grid.body_fitted:
        return _body_fitted_flow(q, polygons, case, threads)
    return (_overset_flow if q.grid.overset else _single_grid_flow)(q, polygons, case, threads)


def _check_fits(q: Quality, polygons: list, case) -> None:
    """The section inside the single grid's length, with 4 cells to spare at either end (the grids grow
    across the stream to hold the motion, and the overset background grows along it to hold the body grid)."""
    if q.grid.overset or q.grid.body_fitted:
        return
    g = q.grid
    xs = np.concatenate([p.vertices[:, 0] for p in polygons])
    margin = 4.0 / g.cells_per_chord
    if xs.min() - margin <= -g.upstream or xs.max() + margin >= g.downstream:
        raise InputError("aero.quality", q.name, f"its single grid ({g.upstream:g} chords upstream of the reference "
                         f"point, {g.downstream:g} downstream) cannot hold this section (x from {xs.min():.3g} to "
                         f"{xs.max():.3g} chords) with 4 cells to spare; use the overset grid or a longer domain")


def _flow_config(q: Quality, threads: int):
    from bridge.cfd import BoundaryConditions, FlowConfig

    bc = BoundaryConditions(left="inflow", right="outflow", bottom="slip", top="slip")
    return FlowConfig(nu=1.0 / q.physics.reynolds, advection="vanleer", cfl=q.run.cfl, threads=threads, bc=bc)


def _single_grid_flow(q: Quality, polygons: list, case, threads: int | None):
    """One grid, the section an immersed body moving on it."""
    from bridge.cfd import KOmegaSST, Simulation, freestream_turbulence

    radius = max(p.radius for p in polygons)
    grid = preset_grid(q, max(float(np.abs(p.vertices[:, 1]).max()) for p in polygons) + case.excursion(radius))
    if threads is None:
        threads = 1 if grid.nx * grid.ny < 20_000 else 2
    sim = Simulation(grid, _flow_config(q, threads))
    for p in polygons:
        sim.add_body(p, case.motion())
    sim.set_state(u=1.0)
    if q.physics.turbulence == "sst":
        KOmegaSST(sim, *freestream_turbulence(1.0, 1.0 / q.physics.reynolds), body_walls=q.physics.sst_walls)
    return sim


def _overset_flow(q: Quality, polygons: list, case, threads: int | None):
    """The section in a body grid that moves with it over a coarser fixed background (bridge.cfd.OversetPair)."""
    from bridge.cfd import CartesianGrid, OversetPair, OversetSST, freestream_turbulence

    g = q.grid
    h = 1.0 / g.cells_per_chord
    dy = g.dy_over_dx * h
    xs = np.concatenate([p.vertices[:, 0] for p in polygons])
    ys = np.concatenate([p.vertices[:, 1] for p in polygons])
    H = g.background_coarsening * h
    m = max(g.body_margin, 6 * H)   # the hole (4 background cells inside the body grid) covers the body
    nbx = int(np.ceil((xs.max() - xs.min() + 2 * m) / h))
    nby = int(np.ceil((ys.max() - ys.min() + 2 * m) / dy))
    cx, cy = 0.5 * (xs.max() + xs.min()), 0.5 * (ys.max() + ys.min())
    body = CartesianGrid.uniform(nbx, nby, (cx - 0.5 * nbx * h, cx + 0.5 * nbx * h),
                                 (cy - 0.5 * nby * dy, cy + 0.5 * nby * dy))
    # background: the preset's grid with cells background_coarsening times larger, its uniform core holding
    # the body grid wherever the motion takes it, and the fringe kept 8 cells clear of in-, outflow and sides
    corners = np.array([[body.x_faces[i], body.y_faces[j]] for i in (0, -1) for j in (0, -1)])
    reach = float(np.abs(corners[:, 1]).max()) + case.excursion(float(np.hypot(*corners.T).max()))
    background = preset_grid(q, reach, h=H, upstream=max(g.upstream, -body.x_faces[0] + 8 * H),
                             downstream=max(g.downstream, body.x_faces[-1] + 8 * H), side_cells=8)
    if threads is None:
        threads = 1 if background.nx * background.ny < 20_000 else 2
    pair = OversetPair(background, body, _flow_config(q, threads), case.motion(), polygon=polygons)
    pair.set_uniform_flow(1.0)
    if q.physics.turbulence == "sst":
        OversetSST(pair, *freestream_turbulence(1.0, 1.0 / q.physics.reynolds), body_walls=q.physics.sst_walls)
    return pair


def _body_fitted_flow(q: Quality, polygons: list, case, threads: int | None):
    """The section in a body-fitted O-grid that moves with it over the overset pair's background
    (bridge.cfd.body_fitted.BodyFittedPair): one outline (appendages are not resolved yet); with SST
    (bridge.cfd.body_fitted.BodyFittedSST) the first cell at y+ ~ 1 unless the preset's ``first_height`` says
    otherwise, and the wall treatment chosen by that height (:func:`body_fitted_walls`): resolved up to twice
    the y+ ~ 1 height, Spalding's wall function above (bridge/cfd/curvilinear_sst.py)."""
    from bridge.cfd import CartesianGrid, freestream_turbulence
    from bridge.cfd.body_fitted import BodyFittedPair, BodyFittedSST
    from bridge.cfd.curvilinear import CurvilinearGrid
    from bridge.cfd.curvilinear_sst import first_height_for
    from bridge.cfd.ogrid import o_grid

    if len(polygons) > 1:
        raise InputError("aero.grid", "body_fitted", f"one outline only: this section has {len(polygons)} parts (the "
                         "body-fitted grid does not resolve railings or screens yet); use grid = \"overset\"")
    g = q.grid
    outline = polygons[0].vertices
    x, y = outline[:, 0], outline[:, 1]
    perimeter = float(np.hypot(np.diff(x, append=x[0]), np.diff(y, append=y[0])).sum())
    n_around = int(round(perimeter * (g.around_per_chord or 2.0 * g.cells_per_chord)))
    sst = q.physics.turbulence == "sst"
    first = g.first_height or (first_height_for(q.physics.reynolds) if sst else 0.1 / g.cells_per_chord)
    H = g.background_coarsening / g.cells_per_chord
    margin = max(g.body_margin, 8 * H)   # the hole (4 background cells inside the O-grid) leaves rings to overlap
    try:
        og = o_grid(outline, n_around, first, g.growth, margin)
    except ValueError as err:   # an outline the generator cannot mesh: the user's section, named where
        raise InputError("deck_section", "outline", f"cannot be meshed by the body-fitted grid: {err}") from None
    ogrid = CurvilinearGrid(og.x, og.y)
    xs, ys = ogrid.x.ravel(), ogrid.y.ravel()
    reach_r = float(np.hypot(xs, ys).max())
    reach = float(np.abs(ys).max()) + case.excursion(reach_r)
    extent = CartesianGrid.uniform(4, 4, (xs.min(), xs.max()), (ys.min(), ys.max()))
    background = preset_grid(q, reach + 4 * H, h=H, upstream=max(g.upstream, -extent.x_faces[0] + 8 * H),
                             downstream=max(g.downstream, extent.x_faces[-1] + 8 * H), side_cells=8)
    if threads is None:
        threads = 1 if background.nx * background.ny < 20_000 else 2
    pair = BodyFittedPair(background, ogrid, _flow_config(q, threads), case.motion())
    pair.set_uniform_flow(1.0)
    if sst:
        BodyFittedSST(pair, *freestream_turbulence(1.0, 1.0 / q.physics.reynolds), walls=body_fitted_walls(q))
    return pair


def body_fitted_walls(q: Quality) -> str:
    """The body-fitted O-grid's wall treatment with SST, by its first cell's height: "resolved" where it is at
    most twice the height that puts y+ ~ 1 at the cell's top (``first_height_for``; the default height) or
    ``sst_walls`` is "resolved", else "equilibrium" (Spalding's wall function with the log layer's production of
    k, bridge/cfd/curvilinear_sst.py; checked for first-cell centres at y+ 18-75, docs/validation.md row 17c)."""
    from bridge.cfd.curvilinear_sst import first_height_for

    first = q.grid.first_height
    if q.physics.sst_walls == "resolved" or first == 0.0 or first <= 2.0 * first_height_for(q.physics.reynolds):
        return "resolved"
    return "equilibrium"
