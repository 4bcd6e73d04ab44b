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

On the body-fitted pair (same deck, SST, wall resolved): V_c = 80.4, 80.9, 80.8 and 80.5 m/s on 16 (``quick``),
24, 32 and 40 cells per chord (``cells_per_chord``), the same pair governing.  The sequence does not converge
(the last change, -0.35 %, is the largest after the first), so no order can be measured; ``quick`` lies 0.2 %
below the finest.  The derivatives still move from 32 to 40 cells (H1* and H3* by up to 4 %, the moment's
derivatives by up to 1.6 %, H2* and H4* by 9-63 %), with elasticities of V_c of 0.2-0.3 for A1*, A2*, A3*, H3*:
the record's band, 1.5 % either way, is an allowance for that, not a measurement.  Run at Re 1.05e8 only (the
O-grid's first cell follows the Reynolds number), so the record holds within 5 % of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bridge.aero.presets import QUALITY

__all__ = ["GridRecord", "GRID_STUDY", "BODY_FITTED_STUDY", "STUDIED_MAIN_SPAN_M", "grid_accuracy",
           "covered_by_study", "ThreeGrids", "three_grids"]

# Both studies' V_c come from the Great Belt's own modes (main span 1624 m).  How far a V_c moves with the grid
# depends on where its bridge flutters as well as on the deck: on the body-fitted pair, 16 -> 40 cells moved the
# Great Belt's +0.2 % and the up-scaled spans' (2000-4000 m) between -0.9 and +0.6 % (docs/flutter.md), so the
# headline turns a record into a grid-converged V_c only for this span (bridge.results).
STUDIED_MAIN_SPAN_M = 1624.0


@dataclass(frozen=True)
class GridRecord:
    """One preset's place in the grid study: its V_c lies ``vc_low_percent`` (low, high) per cent below
    the grid-converged estimate; ``derivatives`` says how far its flutter derivatives are from a finer
    grid's; ``basis`` how the figures were obtained.  Where the study ran the preset's whole table on a finer
    grid (``finest_cells`` per chord), ``derivative_change`` holds, per Scanlan derivative, its change from the
    preset's grid to that one at each of ``reduced_velocities`` (finest / preset - 1; results.h5 keeps them)."""

    quality: str
    vc_low_percent: tuple[float, float]
    derivatives: str
    basis: str
    finest_cells: int = 0
    reduced_velocities: tuple[float, ...] = ()
    derivative_change: tuple[tuple[str, tuple[float, ...]], ...] = ()


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

# The body-fitted pair's study: 'quick' only (module doc).  Each derivative's change from 16 to 40 cells per chord
# at U/(fB) 8, 4 pi, 16 and 20: tools/grid_convergence.py on the chains (docs/aero.md).
BODY_FITTED_STUDY = {
    "quick": GridRecord("quick", (-1.5, 1.5),
                        "its H1*, H3*, A1*, A2*, A3* differ by up to 24 % (A2*) from 40 cells per chord's, A4* by up "
                        "to 30 %, H2* and H4* by several times or sign",
                        "V_c run on 16, 24, 32 and 40 cells per chord: 80.4, 80.9, 80.8, 80.5 m/s, not converging "
                        "(no observed order); the band an allowance for the derivatives still moving from 32 to 40 "
                        "(H1*, H3* by up to 4 %), not a measurement",
                        40, (8.0, 4.0 * math.pi, 16.0, 20.0),
                        (("H1", (-0.017, 0.041, 0.079, 0.110)), ("H2", (-1.228, -4.293, -12.849, 154.854)),
                         ("H3", (-0.042, 0.049, 0.083, 0.106)), ("H4", (-3.163, 2.159, 2.391, 2.570)),
                         ("A1", (-0.064, -0.039, -0.016, 0.002)), ("A2", (-0.064, 0.105, 0.165, 0.243)),
                         ("A3", (-0.056, -0.025, -0.012, -0.000)), ("A4", (0.083, 0.082, 0.219, 0.296)))),
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


def _band(lo: float, hi: float) -> str:
    """Where V_c lies against the grid-converged estimate, (lo, hi) per cent below it, in words."""
    if lo >= 0.0:
        return f"{lo:g}-{hi:g} % below"
    if lo == -hi:
        return f"within {hi:g} % either side of"
    return f"between {-lo:g} % above and {hi:g} % below"


def grid_accuracy(section, aero_options, quality: str, reynolds: float
                  ) -> tuple[str, tuple[float, float] | None, GridRecord | None]:
    """A sentence on the grid error of a CFD V_c of this deck, flow model and preset, the range (low, high) in
    per cent by which the V_c lies below the grid-converged estimate and the study's record of the preset (both
    None where no study covers the run: the sentence then says so)."""
    study = _study(aero_options)
    record = study.records.get(quality)
    cells = aero_options.cells_per_chord
    own_grid = cells in (0, QUALITY[quality].grid.cells_per_chord)   # quality: a checked preset name
    if record is not None and own_grid and covered_by_study(section, aero_options, reynolds):
        lo, hi = record.vc_low_percent
        return (f"grid study of this deck and flow model: on '{quality}' V_c lies {_band(lo, hi)} the "
                f"grid-converged estimate and {record.derivatives} ({record.basis}; docs/aero.md)"), (lo, hi), record
    if record is None:
        return (f"no grid study covers the '{quality}' preset on the {aero_options.grid.replace('_', '-')} grid: its "
                "grid error is unknown" + ("; a smoke run, not to be used" if quality == "tiny" else "")), None, None
    if not own_grid:
        return (f"no grid study covers '{quality}' on {cells} cells per chord (aero.cells_per_chord): its grid "
                "error is unknown; compare it with the preset's own grid"), None, None
    lo, hi = record.vc_low_percent
    return (f"no grid study covers this deck and flow model: the grid error of its V_c on '{quality}' is unknown "
            f"(on the Great Belt deck with k-omega SST on the {study.pair} pair the same preset's V_c lies "
            f"{_band(lo, hi)} its grid-converged one; docs/aero.md); run a finer preset to see how far it moves"), \
        None, None


# ------------------------------------------------------------------------------------------- three grids
@dataclass(frozen=True)
class ThreeGrids:
    """What three grids say of one result (:func:`three_grids`): the observed order ``order``, the extrapolated
    value ``extrapolated`` and the finest grid's grid convergence index ``gci_fine`` (a fraction of its value),
    all NaN unless the sequence is ``monotone`` (the two changes of one sign) and ``converging`` (a positive
    order fits the two changes); ``spread`` is the largest difference between the three over the finest value's
    magnitude, the measure left for an oscillating sequence."""

    values: tuple[float, float, float]     # finest first
    cells: tuple[float, float, float]      # cells per length, finest first
    order: float
    extrapolated: float
    gci_fine: float
    monotone: bool
    converging: bool
    spread: float

    def off_extrapolated(self, k: int) -> float:
        """Grid k's (0 the finest) relative distance from the extrapolated value, (value - extrapolated) /
        |extrapolated| (NaN without an extrapolation)."""
        return (self.values[k] - self.extrapolated) / abs(self.extrapolated) if self.extrapolated else math.nan


def three_grids(values, cells, safety: float = 1.25) -> ThreeGrids:
    """Roache's grid convergence index from three grids, with Celik et al.'s observed order for grids refined by
    unequal ratios (Celik, Ghia, Roache, Freitas, Coleman and Raad 2008, "Procedure for estimation and reporting
    of uncertainty due to discretization in CFD applications", J. Fluids Eng. 130, 078001; Roache 1998,
    "Verification and Validation in Computational Science and Engineering"): ``values`` phi_1, phi_2, phi_3 and
    ``cells`` (per unit length, so h = 1 / cells) from the finest grid to the coarsest.

    With r21 = h2 / h1, r32 = h3 / h2, e21 = phi2 - phi1 and e32 = phi3 - phi2 of one sign, the order p solves
    Celik et al.'s  p ln r21 = ln(e32 / e21) + ln((r21^p - 1) / (r32^p - 1)),  i.e. e32 / e21 = g(p) =
    r21^p (r32^p - 1) / (r21^p - 1), the ratio that phi = phi* + C h^p gives; g rises from ln r32 / ln r21 at
    p = 0, so a positive order exists only above that (``converging``), and it is found by bracketing (Brent) on
    0 < p <= 20; then phi_ext = (r21^p phi1 - phi2) / (r21^p - 1) and GCI_fine = safety |(phi1 - phi2) / phi1| /
    (r21^p - 1), safety 1.25 for three grids.  Where the changes alternate in sign (Celik et al.'s formula
    still returns a number, but an oscillating sequence has no asymptotic order to measure), one is zero, or no
    positive order fits, the order is NaN, and so are the extrapolation and the index."""
    phi = tuple(float(v) for v in values)
    n = tuple(float(c) for c in cells)
    if len(phi) != 3 or len(n) != 3:
        raise ValueError(f"three_grids: three values and three grids needed, got {len(phi)} and {len(n)}")
    if not (n[0] > n[1] > n[2] > 0):
        raise ValueError(f"three_grids: cells must fall from the finest grid to the coarsest, got {n}")
    if not all(math.isfinite(v) for v in phi):
        raise ValueError(f"three_grids: values must be finite, got {phi}")
    r21, r32 = n[0] / n[1], n[1] / n[2]
    e21, e32 = phi[1] - phi[0], phi[2] - phi[1]
    monotone = e21 * e32 >= 0.0
    spread = (max(phi) - min(phi)) / abs(phi[0]) if phi[0] else math.nan
    nan = math.nan
    if e21 == 0.0 or e32 == 0.0 or not monotone:
        return ThreeGrids(phi, n, nan, nan, nan, monotone, False, spread)
    log_ratio = math.log(e32 / e21)

    def residual(p: float) -> float:   # ln g(p) - ln(e32 / e21), g rising with p
        return p * math.log(r21) + math.log(math.expm1(p * math.log(r32)) / math.expm1(p * math.log(r21))) - log_ratio

    lo, hi = 1e-9, 20.0
    converging = residual(lo) < 0.0
    if not converging or residual(hi) <= 0.0:   # no positive order, or one beyond any a scheme has
        return ThreeGrids(phi, n, nan, nan, nan, monotone, converging, spread)
    from scipy.optimize import brentq

    p = brentq(residual, lo, hi, xtol=1e-14, rtol=1e-14)
    f = r21 ** p
    extrapolated = (f * phi[0] - phi[1]) / (f - 1.0)
    gci = safety * abs(e21 / phi[0]) / (f - 1.0) if phi[0] else nan
    return ThreeGrids(phi, n, p, extrapolated, gci, monotone, converging, spread)
