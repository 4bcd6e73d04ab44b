"""How far a CFD preset's flutter speed lies from the grid-converged one, as the grid studies measured it.

A flutter speed from the CFD without its grid error is a number nobody can use.  The presets of
:data:`bridge.aero.forced_motion.QUALITY` were studied on one deck and one flow model - the Great Belt box
(:func:`bridge.cfd.sections.great_belt_section`, no railings) on the overset pair in URANS with the k-omega
SST model and the equilibrium wall at the deck's Reynolds number, and ``quick`` on the body-fitted pair
(wall resolved) - and what the studies found is recorded here as data, beside how it was measured
(docs/aero.md, "Grid study" and "The chain on the body-fitted pair", reproduces each figure).  A run of
that deck and flow model gets its preset's record (:func:`grid_accuracy`); any other deck, flow model or
preset is told plainly that no grid study covers it.

The study (Great Belt deck, SST, V = 50 m/s, Re 1.05e8): V_c = 75.5 m/s on ``quick`` (16 cells per chord)
and 78.5 m/s on ``standard`` (40); the 80-cell grid's heave and pitch responses at Omega = 0.5 (next to the
flutter point, Omega = 0.52) put into the ``quick`` table give 79.9 m/s; the three grids converge at an
observed order of about 0.8 towards about 81.6 m/s (Richardson; rough with an order this low).  The
Reynolds number from 5.2e7 to 1.05e8 moved the responses by at most 0.4 %, the time step (CFL 0.5 to 0.25)
by 0.1 %.

On the body-fitted pair (same deck, SST, wall resolved): V_c = 80.4 m/s on ``quick`` (16 cells per chord) and
80.9 m/s on its grid of 24 (``cells_per_chord = 24``), +0.6 %; two grids cannot measure an order, so the
converged V_c is Richardson's for an order between 0.8 (the overset pair's observed) and 2 (the scheme's):
1.2-2.3 % above ``quick``'s, recorded as 1-3 %.  An estimate resting on that assumption, not a measured
convergence: the derivatives still move by up to 15 % between the two grids.  Run at Re 1.05e8 only (the
O-grid's first cell follows the Reynolds number), so the record holds within 5 % of it.
"""

from __future__ import annotations

from dataclasses import dataclass

from bridge.aero.presets import QUALITY

__all__ = ["GridRecord", "GRID_STUDY", "BODY_FITTED_STUDY", "STUDIED_MAIN_SPAN_M", "grid_accuracy",
           "covered_by_study"]

# Both studies' V_c come from the Great Belt's own modes (main span 1624 m).  How far a V_c moves with the grid
# depends on where its bridge flutters as well as on the deck: on the body-fitted pair, 16 -> 24 cells moved the
# Great Belt's +0.6 % and the up-scaled spans' (2000-4000 m) between -0.4 and +1.2 % (docs/flutter.md), so the
# headline turns a record into a grid-converged V_c only for this span (bridge.results).
STUDIED_MAIN_SPAN_M = 1624.0


@dataclass(frozen=True)
class GridRecord:
    """One preset's place in the grid study: its V_c lies ``vc_low_percent`` (low, high) per cent below
    the grid-converged estimate; ``derivatives`` says how far its flutter derivatives are from a finer
    grid's; ``basis`` how the figures were obtained."""

    quality: str
    vc_low_percent: tuple[float, float]
    derivatives: str
    basis: str


GRID_STUDY = {
    "quick": GridRecord("quick", (6.0, 8.0), "its heave and pitch responses differ by 7-19 % from 'standard''s",
                        "V_c run on 'quick' and 'standard', three grids (16, 40, 80 cells per chord) at Omega = 0.5"),
    "standard": GridRecord("standard", (2.0, 4.0),
                           "its responses differ by 5-15 % from the 80-cell grid's (the lift's the most)",
                           "V_c run on 'standard', three grids (16, 40, 80 cells per chord) at Omega = 0.5"),
    "fine": GridRecord("fine", (1.0, 3.0), "its held deck's lift slope is within about 2 % of a grid twice as fine",
                       "an estimate: the 80-cell responses at Omega = 0.5 scaled into the table (no 'fine' run of "
                       "the whole table), and the held deck on 160 cells per chord"),
}

# The body-fitted pair's study: 'quick' only (module doc).
BODY_FITTED_STUDY = {
    "quick": GridRecord("quick", (1.0, 3.0),
                        "its derivatives differ by up to 15 % (A2*) from 24 cells per chord's, H2* and H4* by sign",
                        "V_c run on 16 and 24 cells per chord (+0.6 %), the converged V_c by Richardson for an "
                        "assumed order of 0.8-2"),
}


@dataclass(frozen=True)
class _Study:
    """One grid study: its records by preset, the flow model a run must match for them to apply (on the
    body-fitted pair the wall is resolved whatever ``sst_walls``), the Reynolds numbers between which the
    responses were shown not to depend on it, and the pair's name in messages."""

    records: dict
    flow: dict
    reynolds: tuple[float, float]
    pair: str


_STUDIES = {
    "overset": _Study(GRID_STUDY, {"turbulence": "sst", "sst_walls": "equilibrium", "grid": "overset",
                                   "excitation": "single"}, (5.0e7, 2.0e8), "overset"),
    "body_fitted": _Study(BODY_FITTED_STUDY, {"turbulence": "sst", "grid": "body_fitted", "excitation": "single"},
                          (1.0e8, 1.1e8), "body-fitted"),
}


def _study(aero_options) -> _Study:
    """The study of the run's grid (a single grid has none of its own: the overset pair's is quoted)."""
    return _STUDIES.get(aero_options.grid, _STUDIES["overset"])


def covered_by_study(section, aero_options, reynolds: float) -> bool:
    """True when the deck, its flow model and its Reynolds number are those of its grid's study."""
    from bridge.cfd.sections import great_belt_section

    study = _study(aero_options)
    same_deck = section.to_mapping() == great_belt_section().to_mapping()
    same_flow = all(getattr(aero_options, k) == v for k, v in study.flow.items())
    return same_deck and same_flow and study.reynolds[0] <= reynolds <= study.reynolds[1]


def grid_accuracy(section, aero_options, quality: str, reynolds: float) -> tuple[str, tuple[float, float] | None]:
    """A sentence on the grid error of a CFD V_c of this deck, flow model and preset, and the range (low,
    high) in per cent by which the V_c lies below the grid-converged estimate (None where no study covers
    the run: the sentence then says so)."""
    study = _study(aero_options)
    record = study.records.get(quality)
    cells = aero_options.cells_per_chord
    own_grid = cells in (0, QUALITY[quality].grid.cells_per_chord)   # quality: a checked preset name
    if record is not None and own_grid and covered_by_study(section, aero_options, reynolds):
        lo, hi = record.vc_low_percent
        return (f"grid study of this deck and flow model: on '{quality}' V_c lies {lo:g}-{hi:g} % below the "
                f"grid-converged estimate and {record.derivatives} ({record.basis}; docs/aero.md)"), (lo, hi)
    if record is None:
        return (f"no grid study covers the '{quality}' preset on the {aero_options.grid.replace('_', '-')} grid: its "
                "grid error is unknown" + ("; a smoke run, not to be used" if quality == "tiny" else "")), None
    if not own_grid:
        return (f"no grid study covers '{quality}' on {cells} cells per chord (aero.cells_per_chord): its grid "
                "error is unknown; compare it with the preset's own grid"), None
    lo, hi = record.vc_low_percent
    return (f"no grid study covers this deck and flow model: the grid error of its V_c on '{quality}' is unknown "
            f"(on the Great Belt deck with k-omega SST on the {study.pair} pair the same preset's V_c lies "
            f"{lo:g}-{hi:g} % low; docs/aero.md); run a finer preset to see how far it moves"), None
