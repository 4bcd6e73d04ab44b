"""Options of the ``aero`` stage: the ``[aero]`` table of a scenario file.

Keys (all optional):
    quality               "tiny" | "quick" | "standard" | "fine": grid, time step, Reynolds number and
                          periods of bridge.aero.forced_motion.QUALITY (default "quick"; --quality on the
                          command line wins; --quick means "tiny")
    cells_per_chord       the body grid's cells per chord instead of the preset's (8-2000; default 0: the
                          preset's): the same preset on another grid, to see how far a result moves with the
                          grid (the background and, on "body_fitted", the O-grid's nodes around follow it); no
                          grid study covers a changed grid, and the headline says so; "tiny" (--quick) keeps
                          its own grid
    reduced_velocities    U/(fB) of the forced-motion runs (default 4, 6, 8, 10, 12, 16; at least 2):
                          the flutter search may use reduced frequencies K = 2 pi / (U/(fB)) only inside
    heave_rate            heave velocity amplitude over the wind speed, udot_0 / V (default the thesis's
                          0.4 / 50 = 0.008, thesis 5.3)
    pitch_rate            rotation-rate amplitude thetadot_0 B / V (default the thesis's 0.028 * 31 / 50)
    checkpoint_every      steps between checkpoints of a running case (default 2000)
    excitation            "single": one heave and one pitch run per reduced velocity (default); "multi": one
                          heave and one pitch run moving at all of them at once (a sum of sines,
                          bridge.aero.forced_motion.ForcedCase.multi_frequency); the reduced velocities must
                          then be the largest one over whole numbers (e.g. 16, 8, 5.333, 4); a run whose
                          loads are not linear in the motion is flagged in a warning (the Great Belt deck in
                          pitch is not: docs/aero.md)
    grid                  "overset" (default): the section in a fine grid that moves with it over a coarser
                          fixed background (bridge/cfd/overset.py; no face of the body changes class as it
                          moves); "single": one grid, the section an immersed body moving on it (with "sst"
                          its forces jitter as the faces change class: docs/cfd.md, "Immersed boundary");
                          "body_fitted": an O-grid graded from the section's wall over the same background
                          (bridge/cfd/body_fitted.py; one outline only so far; with "sst" the wall
                          resolved, the presets' first cell at y+ ~ 1, whatever sst_walls says; a tool's
                          larger first cell takes Spalding's wall function: docs/cfd.md, "Body-fitted
                          grid")
    turbulence            "sst" (default): the k-omega SST model (2003 variant) with Spalding's wall function on
                          the section, at the deck's Reynolds number Re = wind_speed_m_s B / nu_air ([air]
                          kinematic viscosity), on either grid (bridge/cfd/turbulence.py, docs/cfd.md);
                          "laminar": the preset's low Reynolds number, no turbulence model
    sst_walls             with turbulence = "sst", the section's walls: "equilibrium" (default): Spalding's
                          wall function everywhere, with the log layer's own production of k, so that the
                          layer is turbulent from the section's front, as a deck's at Re 1e8 is
                          (docs/cfd.md, "Turbulence model and walls"); "function": the same wall
                          function with the model's production of k, which leaves a layer that meets the
                          section with the freestream's k laminar over much of it; "blended": the wall
                          function where the layer next to the wall is turbulent (its eddy viscosity at
                          least half the law's), the no-slip linear profile where it is not, so that a
                          laminar layer can separate at a corner (under study: docs/cfd.md)
    wind_speed_m_s        the wind speed that sets the Reynolds number with turbulence = "sst" (default the
                          thesis's 50 m/s: Re = 1.05e8 for the Great Belt's 31 m); the derivatives are
                          per unit wind speed either way
    mean_angle_deg        the incidence (degrees, nose-up) about which the section is moved in the forced runs
                          (default 0; -10 to 10): derivatives about a mean angle of attack, such as the static
                          twist a deck flutters about (docs/flutter.md, "The CFD's own check: free vibration")
    static_angles_deg     angles of attack (degrees, nose-up) at which the section is held still for its
                          static coefficients C_D, C_L, C_M, their slopes and the Strouhal number
                          (default -2, 0, 2; [] skips them); with aerodynamics = "cfd" they supply the
                          lateral (drag, sway) terms of the flutter model (bridge/aero/static.py)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from bridge.aero.presets import GRIDS, QUALITY, USER_SST_WALLS, check_flow_model
from bridge.errors import InputError, check_range, check_table

__all__ = ["AeroOptions"]


@dataclass(frozen=True)
class AeroOptions:
    """Validated ``[aero]`` table (module docstring)."""

    quality: str = "quick"
    reduced_velocities: tuple[float, ...] = (4.0, 6.0, 8.0, 10.0, 12.0, 16.0)
    heave_rate: float = 0.4 / 50.0
    pitch_rate: float = 0.028 * 31.0 / 50.0
    checkpoint_every: int = 2000
    static_angles_deg: tuple[float, ...] = (-2.0, 0.0, 2.0)
    excitation: str = "single"
    grid: str = "overset"
    turbulence: str = "sst"
    wind_speed_m_s: float = 50.0
    sst_walls: str = "equilibrium"
    mean_angle_deg: float = 0.0
    cells_per_chord: int = 0

    def __post_init__(self):
        check_flow_model(self.turbulence, self.sst_walls, USER_SST_WALLS)
        check_range("aero.wind_speed_m_s", self.wind_speed_m_s, 0.0, 200.0, low_open=True)

        if self.grid not in GRIDS:
            raise InputError("aero.grid", self.grid, f"one of {', '.join(GRIDS)}")

        cells = self.cells_per_chord
        if isinstance(cells, bool) or not isinstance(cells, int) or (cells != 0 and not 8 <= cells <= 2000):
            raise InputError("aero.cells_per_chord", cells, "an integer from 8 to 2000, or 0 (the preset's)")
        if self.quality not in QUALITY:
            raise InputError("aero.quality", self.quality, f"one of {', '.join(QUALITY)}")
        values = self.reduced_velocities
        if isinstance(values, (str, bytes)) or not isinstance(values, (list, tuple)):
            raise InputError("aero.reduced_velocities", values, "a list of at least 2 numbers U/(fB)")
        # each value's range first: a list of one bad value is answered about the value, not the list's length
        rv = tuple(sorted(check_range(f"aero.reduced_velocities[{i}]", v, 0.5, 200.0) for i, v in enumerate(values)))
        if len(rv) < 2:
            raise InputError("aero.reduced_velocities", values, "a list of at least 2 numbers U/(fB)")
        if len(set(rv)) != len(rv):
            raise InputError("aero.reduced_velocities", values, "distinct values")
        object.__setattr__(self, "reduced_velocities", rv)
        if self.excitation not in ("single", "multi"):
            raise InputError("aero.excitation", self.excitation, "one of single, multi")
        if self.excitation == "multi":
            top = rv[-1]
            ratios = [top / v for v in rv]
            if any(abs(r - round(r)) > 1e-3 * r for r in ratios):
                raise InputError("aero.reduced_velocities", values,
                                 f"with excitation = \"multi\": the largest ({top:g}) over whole numbers, e.g. "
                                 + ", ".join(f"{top / m:.4g}" for m in range(1, 5)))
            # the frequencies are taken as exact multiples of the lowest (the whole periods need it)
            rv = tuple(top / round(top / v) for v in rv)
            if len(set(rv)) != len(rv):
                raise InputError("aero.reduced_velocities", values, "distinct values after rounding to the "
                                 f"largest ({top:g}) over whole numbers")
            object.__setattr__(self, "reduced_velocities", rv)
        object.__setattr__(self, "mean_angle_deg", check_range("aero.mean_angle_deg", self.mean_angle_deg, -10.0, 10.0))
        check_range("aero.heave_rate", self.heave_rate, 0.0, 0.2, low_open=True)
        check_range("aero.pitch_rate", self.pitch_rate, 0.0, 0.2, low_open=True)
        if isinstance(self.checkpoint_every, bool) or not isinstance(self.checkpoint_every, int) \
                or self.checkpoint_every < 10:
            raise InputError("aero.checkpoint_every", self.checkpoint_every, "an integer >= 10")
        angles = self.static_angles_deg
        need = "a list of angles in degrees: none, or at least 2 (the slopes need two)"
        if isinstance(angles, (str, bytes)) or not isinstance(angles, (list, tuple)):
            raise InputError("aero.static_angles_deg", angles, need)
        angles = tuple(sorted(check_range(f"aero.static_angles_deg[{i}]", a, -30.0, 30.0)
                              for i, a in enumerate(angles)))
        if len(angles) == 1:
            raise InputError("aero.static_angles_deg", self.static_angles_deg, need)
        if len(set(angles)) != len(angles):
            raise InputError("aero.static_angles_deg", self.static_angles_deg, "distinct values")
        object.__setattr__(self, "static_angles_deg", angles)

    @classmethod
    def from_mapping(cls, mapping: Mapping[str, Any], where: str = "aero") -> AeroOptions:
        check_table(where, mapping, cls.__dataclass_fields__)
        values = dict(mapping)
        for key in ("reduced_velocities", "static_angles_deg"):
            if key in values and isinstance(values[key], list):
                values[key] = tuple(values[key])
        return cls(**values)
