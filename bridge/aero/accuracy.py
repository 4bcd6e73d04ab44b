"""How far a CFD preset's flutter speed lies from the grid-converged one, as the grid studies measured it.

A flutter speed from the CFD without its grid error is a number nobody can use.  The presets of
:data:`bridge.aero.forced_motion.QUALITY` were studied on one deck and one flow model - the Great Belt box
(:func:`bridge.cfd.sections.great_belt_section`, no railings) on the overset pair in URANS with the k-omega
SST model and the equilibrium wall at the deck's Reynolds number - and what the study found is recorded
here as data, beside how it was measured (docs/aero.md, "Grid study", reproduces each
figure).  A run of that deck and flow model gets its preset's record (:func:`grid_accuracy`); any other
deck, flow model or preset is told plainly that no grid study covers it.

The study (Great Belt deck, SST, V = 50 m/s, Re 1.05e8): V_c = 75.5 m/s on ``quick`` (16 cells per chord)
and 78.5 m/s on ``standard`` (40); the 80-cell grid's heave and pitch responses at Omega = 0.5 (next to the
flutter point, Omega = 0.52) put into the ``quick`` table give 79.9 m/s; the three grids converge at an
observed order of about 0.8 towards about 81.6 m/s (Richardson; rough with an order this low).  The
Reynolds number from 5.2e7 to 1.05e8 moved the responses by at most 0.4 %, the time step (CFL 0.5 to 0.25)
by 0.1 %.
"""

from __future__ import annotations

from dataclasses import dataclass

from bridge.aero.presets import QUALITY

__all__ = ["GridRecord", "GRID_STUDY", "grid_accuracy", "covered_by_study"]


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

# The deck and flow model the study ran (a run must match them for its preset's record to apply); the
# Reynolds numbers between which the responses were shown not to depend on it.
_STUDIED_FLOW = {"turbulence": "sst", "sst_walls": "equilibrium", "grid": "overset", "excitation": "single"}
_STUDIED_REYNOLDS = (5.0e7, 2.0e8)


def covered_by_study(section, aero_options, reynolds: float) -> bool:
    """True when the deck, its flow model and its Reynolds number are those of the grid study."""
    from bridge.cfd.sections import great_belt_section

    same_deck = section.to_mapping() == great_belt_section().to_mapping()
    same_flow = all(getattr(aero_options, k) == v for k, v in _STUDIED_FLOW.items())
    return same_deck and same_flow and _STUDIED_REYNOLDS[0] <= reynolds <= _STUDIED_REYNOLDS[1]


def grid_accuracy(section, aero_options, quality: str, reynolds: float) -> tuple[str, tuple[float, float] | None]:
    """A sentence on the grid error of a CFD V_c of this deck, flow model and preset, and the range (low,
    high) in per cent by which the V_c lies below the grid-converged estimate (None where no study covers
    the run: the sentence then says so)."""
    record = GRID_STUDY.get(quality)
    cells = aero_options.cells_per_chord
    own_grid = cells in (0, QUALITY[quality].grid.cells_per_chord)   # quality: a checked preset name
    if record is not None and own_grid and covered_by_study(section, aero_options, reynolds):
        lo, hi = record.vc_low_percent
        return (f"grid study of this deck and flow model: on '{quality}' V_c lies {lo:g}-{hi:g} % below the "
                f"grid-converged estimate and {record.derivatives} ({record.basis}; docs/aero.md)"), (lo, hi)
    if record is None:
        return (f"no grid study covers the '{quality}' preset: its grid error is unknown; a smoke run, not to be "
                "used"), None
    if not own_grid:
        return (f"no grid study covers '{quality}' on {cells} cells per chord (aero.cells_per_chord): its grid "
                "error is unknown; compare it with the preset's own grid"), None
    lo, hi = record.vc_low_percent
    return (f"no grid study covers this deck and flow model: the grid error of its V_c on '{quality}' is unknown "
            f"(on the Great Belt deck with k-omega SST on the overset pair the same preset's V_c lies {lo:g}-{hi:g} % "
            "low; docs/aero.md); run a finer preset to see how far it moves"), None
