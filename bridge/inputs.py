"""The inputs of one bridge as data: the scenario and its parts (thesis 1.4, 3.2, Tables 3.1-3.4), with their
derived quantities (mu and J of Eq 4.7, shear modulus, box-section properties), each computed, never stored
twice.  Read and checked from TOML by bridge.config; up-scaled by bridge.upscaling.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from .errors import InputError, check_range

if TYPE_CHECKING:   # the tables other packages read and check (bridge.config); types only, no import at run time
    from .aero.options import AeroOptions
    from .buffeting.options import BuffetingOptions
    from .cfd.sections import FlatPlate, PolygonSection, Rectangle, StreamlinedBox
    from .flutter.modal import ModalModel
    from .flutter.options import FlutterOptions
    from .flutter.section import SectionModel

__all__ = ["Material", "BoxSection", "Geometry", "Girder", "Cable", "Hanger", "Pylon", "DampingEntry", "Air",
           "Scenario", "GRAVITY_M_S2"]

GRAVITY_M_S2 = 9.81  # the thesis's value (Eq 1.2, 2.3)


@dataclass(frozen=True)
class Material:
    """Linear elastic isotropic material (thesis Table 3.1)."""

    name: str
    youngs_modulus_Pa: float
    poisson_ratio: float
    density_kg_m3: float

    def __post_init__(self) -> None:
        check_range(f"materials.{self.name}.youngs_modulus_Pa", self.youngs_modulus_Pa, 0.0, low_open=True)
        check_range(f"materials.{self.name}.poisson_ratio", self.poisson_ratio, 0.0, 0.5, high_open=True)
        check_range(f"materials.{self.name}.density_kg_m3", self.density_kg_m3, 0.0, low_open=True)

    @property
    def shear_modulus_Pa(self) -> float:
        return self.youngs_modulus_Pa / (2.0 * (1.0 + self.poisson_ratio))


@dataclass(frozen=True)
class BoxSection:
    """Thin-walled rectangular box, outer sides ``a`` x ``b``, wall ``t`` (thesis Table 3.2, Fig 3.2).

    ``a`` is taken along the bridge axis and ``b`` across it for legs; for cross beams ``a`` is the
    width (horizontal, along the bridge) and ``b`` the depth (vertical).  Torsion by Bredt's formula on
    the wall centre line.
    """

    a_m: float
    b_m: float
    t_m: float

    def __post_init__(self) -> None:
        check_range("section.a_m", self.a_m, 0.0, low_open=True)
        check_range("section.b_m", self.b_m, 0.0, low_open=True)
        if not (0.0 < self.t_m < 0.5 * min(self.a_m, self.b_m)):
            raise InputError("section.t_m", self.t_m, f"must be > 0 and < half the smaller side "
                             f"({0.5 * min(self.a_m, self.b_m):g} m)")

    @property
    def area_m2(self) -> float:
        return self.a_m * self.b_m - (self.a_m - 2 * self.t_m) * (self.b_m - 2 * self.t_m)

    @property
    def i_about_a_m4(self) -> float:
        """Second moment for bending with the neutral axis parallel to side ``a``: (a b^3 - a_i b_i^3)/12."""
        ai, bi = self.a_m - 2 * self.t_m, self.b_m - 2 * self.t_m
        return (self.a_m * self.b_m**3 - ai * bi**3) / 12.0

    @property
    def i_about_b_m4(self) -> float:
        """Second moment for bending with the neutral axis parallel to side ``b``."""
        ai, bi = self.a_m - 2 * self.t_m, self.b_m - 2 * self.t_m
        return (self.b_m * self.a_m**3 - bi * ai**3) / 12.0

    @property
    def torsion_constant_m4(self) -> float:
        """Bredt: J = 4 A_m^2 t / perimeter_m on the wall centre line."""
        am, bm = self.a_m - self.t_m, self.b_m - self.t_m
        return 4.0 * (am * bm) ** 2 * self.t_m / (2.0 * (am + bm))

    def scaled(self, factor: float) -> BoxSection:
        """All three dimensions times ``factor``: inertia scales as factor**4, area as factor**2."""
        return BoxSection(self.a_m * factor, self.b_m * factor, self.t_m * factor)


@dataclass(frozen=True)
class Geometry:
    """Spans, sag and levels (thesis 1.4, Table 1.2).  Elevations are above the pylon foundations.

    The deck is horizontal (thesis 3.1) at ``girder_elevation_m``; the cable low point at mid-span is
    ``pylon_height_m - sag_m``; the side-span anchors lie at that same level (Eq 2.10: y(L_s) = h).
    """

    main_span_m: float
    side_span_m: float
    sag_m: float
    hanger_spacing_target_m: float
    cable_plane_spacing_m: float
    girder_elevation_m: float
    pylon_height_m: float

    def __post_init__(self) -> None:
        check_range("geometry.main_span_m", self.main_span_m, 0.0, low_open=True)
        check_range("geometry.side_span_m", self.side_span_m, 0.0, low_open=True)
        check_range("geometry.sag_m", self.sag_m, 0.0, low_open=True)
        check_range("geometry.sag_ratio (sag_m / main_span_m)", self.sag_m / self.main_span_m, 1 / 20, 1 / 5)
        check_range("geometry.hanger_spacing_target_m", self.hanger_spacing_target_m, 0.0,
                    self.main_span_m / 4, low_open=True)
        check_range("geometry.cable_plane_spacing_m", self.cable_plane_spacing_m, 0.0, low_open=True)
        check_range("geometry.girder_elevation_m", self.girder_elevation_m, 0.0, low_open=True)
        if self.cable_low_point_m <= self.girder_elevation_m:
            raise InputError("geometry.pylon_height_m", self.pylon_height_m,
                             f"must exceed girder_elevation_m + sag_m = "
                             f"{self.girder_elevation_m + self.sag_m:g} (cable above the deck at mid-span)")

    @property
    def cable_low_point_m(self) -> float:
        return self.pylon_height_m - self.sag_m

    @property
    def sag_ratio(self) -> float:
        return self.sag_m / self.main_span_m

    @property
    def total_length_m(self) -> float:
        """Deck length L of Eq 4.5/4.34: main span plus both side spans."""
        return self.main_span_m + 2.0 * self.side_span_m


@dataclass(frozen=True)
class Girder:
    """Bridge girder (thesis Table 3.3).  i_vertical = I_yy (weak axis, vertical bending), i_lateral = I_xx,
    torsion_constant = I_zz (St Venant), mass_moment_of_inertia = J_b (Eq 3.1)."""

    area_m2: float
    i_vertical_m4: float
    i_lateral_m4: float
    torsion_constant_m4: float
    mass_per_length_kg_m: float
    mass_moment_of_inertia_kg_m2_m: float
    width_m: float
    material: str


@dataclass(frozen=True)
class Cable:
    """One main cable (thesis 1.4, 3.2.1).  ``allowable_stress_Pa`` is sigma_0 of Eq 1.1, the design rule
    the up-scaling keeps (Eq 1.2)."""

    area_m2: float
    mass_per_length_main_kg_m: float
    mass_per_length_side_kg_m: float
    allowable_stress_Pa: float
    material: str

    @property
    def density_kg_m3(self) -> float:
        """rho_c = mu_c / A_c: the cable's effective density (wires, wrapping, clamps)."""
        return self.mass_per_length_main_kg_m / self.area_m2


@dataclass(frozen=True)
class Hanger:
    """Hanger pair modelled as one (thesis 3.2.2): area of both together."""

    area_m2: float
    density_kg_m3: float
    material: str


@dataclass(frozen=True)
class Pylon:
    """Concrete pylon: two vertical legs in the cable planes, joined by cross beams (thesis 3.2.3, Table 3.2).

    Lower leg section from foundation to girder level, upper leg section above it.  ``extra_cross_beams``
    are added evenly between the lower and upper cross beams in up-scaled models (thesis 1.5, Fig 1.1).
    """

    lower_leg: BoxSection
    upper_leg: BoxSection
    lower_cross_beam: BoxSection
    upper_cross_beam: BoxSection
    lower_cross_beam_elevation_m: float
    upper_cross_beam_elevation_m: float
    extra_cross_beams: int
    material: str

    @property
    def cross_beam_elevations_m(self) -> tuple[float, ...]:
        """All cross-beam levels, bottom to top, extra beams evenly spaced between lower and upper."""
        lo, hi, n = self.lower_cross_beam_elevation_m, self.upper_cross_beam_elevation_m, self.extra_cross_beams
        return tuple(lo + (hi - lo) * i / (n + 1) for i in range(n + 2))


@dataclass(frozen=True)
class DampingEntry:
    """One row of thesis Table 3.4: measured mode, its symmetry, frequency and damping ratio."""

    symmetry: str
    frequency_hz: float
    ratio: float


@dataclass(frozen=True)
class Air:
    density_kg_m3: float = 1.225
    kinematic_viscosity_m2_s: float = 1.48e-5


@dataclass(frozen=True)
class Scenario:
    """All inputs of one run.  ``reference_name``/``scale`` say how an up-scaled bridge was made."""

    name: str
    kind: str
    description: str
    geometry: Geometry | None = None
    girder: Girder | None = None
    cable: Cable | None = None
    hanger: Hanger | None = None
    pylon: Pylon | None = None
    materials: Mapping[str, Material] = field(default_factory=dict)
    damping: tuple[DampingEntry, ...] = ()
    air: Air = Air()
    reference_name: str | None = None
    pylon_inertia_ratio: float = 1.0  # I/I0 of Eq 1.3 applied when this bridge was up-scaled (1: not up-scaled)
    source_path: str | None = None
    flutter: FlutterOptions | None = None   # the [flutter] table
    section: SectionModel | None = None     # the [section] table (kind == "section")
    modal: ModalModel | None = None         # the [modal] table: modes given directly
    deck_section: FlatPlate | Rectangle | StreamlinedBox | PolygonSection | None = None   # [deck_section], aero stage
    aero: AeroOptions | None = None         # the [aero] table
    buffeting: BuffetingOptions | None = None   # the [buffeting] table

    # Eq 4.7 ------------------------------------------------------------------------------------------
    @property
    def deck_mass_per_length_kg_m(self) -> float:
        """mu = mu_b + 2 mu_c (Eq 4.7 context, Table 3.6): girder plus both main cables."""
        return self.girder.mass_per_length_kg_m + 2.0 * self.cable.mass_per_length_main_kg_m

    @property
    def deck_inertia_per_length_kg_m2_m(self) -> float:
        """J = J_b + (B^2/2) mu_c (Eq 4.7), B the distance between the cable planes."""
        b = self.geometry.cable_plane_spacing_m
        return self.girder.mass_moment_of_inertia_kg_m2_m + 0.5 * b * b * self.cable.mass_per_length_main_kg_m

    def material(self, name: str) -> Material:
        return self.materials[name]
