"""Up-scaling a reference suspension bridge to another main span (thesis section 1.5).

Rules, each computed from the reference scenario and the target span L (never typed in):

* Cable area from equal allowable stress (Eq 1.1-1.2) with the reference's cable density
  rho_c = mu_c / A_c and sag ratio h0/L0.  Eq 1.2 is linear in A_c; its closed form is
  ``A_c = mu_b k / (2 (sigma_0 - rho_c k))`` with ``k = (L0/h0) g L / 8``.  It diverges as
  ``rho_c k -> sigma_0``, i.e. at ``L_limit = 8 sigma_0 h0 / (rho_c g L0)`` (about 5.2 km for the
  Great Belt): there the cable can no longer carry its own weight at the allowable stress.
* Cable masses (main and side) scale with the area.
* Geometric similarity (Table 1.2, "the ratio between the pylons height and the main span is kept"): sag,
  side span, pylon height and every level on the pylon (girder, cross beams) scale with L/L0.  The hanger
  spacing target stays 24 m (thesis 2.2: equal panels of about 24 m).
* Pylon sections from equal safety against Euler buckling (Eq 1.3):
  ``I/I0 = (mu_b + 2 mu_c) L^3 / ((mu_b + 2 mu_c0) L0^3)``.  ASSUMPTION (the thesis does not say how
  the box changes): every dimension a, b, t of each pylon box (legs and cross beams) is multiplied by
  ``(I/I0)^(1/4)``, which gives exactly that inertia ratio.
* Extra cross beams (Fig 1.1): the thesis adds one in Model B (3000 m) and two in Model C (4000 m), evenly
  spaced.  It states no rule; generalised here as one extra beam per full 1000 m of main span beyond
  2000 m (gives 0, 1, 2 for Models A, B, C).
* mu and J of Eq 4.7 follow from the scaled cable mass (properties of :class:`bridge.inputs.Scenario`).
"""

from __future__ import annotations

import math
from dataclasses import replace

from .errors import InputError, check_range
from .inputs import GRAVITY_M_S2, Geometry, Pylon, Scenario

__all__ = ["upscale", "cable_area_for_span", "span_limit_m", "pylon_inertia_ratio", "extra_cross_beams"]


def _k(reference: Scenario, main_span_m: float) -> float:
    g0 = reference.geometry
    return (g0.main_span_m / g0.sag_m) * GRAVITY_M_S2 * main_span_m / 8.0


def span_limit_m(reference: Scenario) -> float:
    """Main span at which Eq 1.2 has no positive cable area (rho_c k = sigma_0)."""
    g0, c0 = reference.geometry, reference.cable
    return 8.0 * c0.allowable_stress_Pa * g0.sag_m / (c0.density_kg_m3 * GRAVITY_M_S2 * g0.main_span_m)


def cable_area_for_span(reference: Scenario, main_span_m: float) -> float:
    """A_c of one cable from Eq 1.2 (closed form); the sag ratio and sigma_0 are the reference's."""
    limit = span_limit_m(reference)
    if main_span_m >= limit:
        raise InputError("geometry.main_span_m", main_span_m,
                         f"must be < {limit:.0f} m: at that span the cable area of Eq 1.2 diverges "
                         f"(the cable cannot carry its own weight at sigma_0 = "
                         f"{reference.cable.allowable_stress_Pa / 1e6:g} MPa)")
    k = _k(reference, main_span_m)
    c0 = reference.cable
    return reference.girder.mass_per_length_kg_m * k / (2.0 * (c0.allowable_stress_Pa - c0.density_kg_m3 * k))


def pylon_inertia_ratio(reference: Scenario, cable_mass_per_length_kg_m: float, main_span_m: float) -> float:
    """I/I0 of Eq 1.3."""
    mu_b = reference.girder.mass_per_length_kg_m
    mu_c0 = reference.cable.mass_per_length_main_kg_m
    return ((mu_b + 2 * cable_mass_per_length_kg_m) * main_span_m**3
            / ((mu_b + 2 * mu_c0) * reference.geometry.main_span_m**3))


def extra_cross_beams(main_span_m: float) -> int:
    """One extra pylon cross beam per full 1000 m of main span beyond 2000 m (thesis Fig 1.1, generalised)."""
    return max(0, math.floor((main_span_m - 2000.0) / 1000.0 + 1e-9))


def upscale(reference: Scenario, main_span_m: float) -> Scenario:
    """The reference bridge scaled to ``main_span_m`` by the rules in this module's docstring.

    ``main_span_m`` equal to the reference span returns the reference unchanged.
    """
    if reference.kind != "suspension_bridge":
        raise InputError("reference", reference.name, "must be a suspension_bridge scenario to up-scale")
    check_range("geometry.main_span_m", main_span_m, 100.0, None)
    g0, c0, p0 = reference.geometry, reference.cable, reference.pylon
    if math.isclose(main_span_m, g0.main_span_m, rel_tol=1e-12):
        return reference
    s = main_span_m / g0.main_span_m

    area = cable_area_for_span(reference, main_span_m)
    area_ratio = area / c0.area_m2
    cable = replace(c0, area_m2=area, mass_per_length_main_kg_m=c0.mass_per_length_main_kg_m * area_ratio,
                    mass_per_length_side_kg_m=c0.mass_per_length_side_kg_m * area_ratio)

    geometry = Geometry(
        main_span_m=main_span_m, side_span_m=g0.side_span_m * s, sag_m=g0.sag_m * s,
        hanger_spacing_target_m=g0.hanger_spacing_target_m, cable_plane_spacing_m=g0.cable_plane_spacing_m,
        girder_elevation_m=g0.girder_elevation_m * s, pylon_height_m=g0.pylon_height_m * s)

    inertia_ratio = pylon_inertia_ratio(reference, cable.mass_per_length_main_kg_m, main_span_m)
    f = inertia_ratio ** 0.25
    pylon = Pylon(
        lower_leg=p0.lower_leg.scaled(f), upper_leg=p0.upper_leg.scaled(f),
        lower_cross_beam=p0.lower_cross_beam.scaled(f), upper_cross_beam=p0.upper_cross_beam.scaled(f),
        lower_cross_beam_elevation_m=p0.lower_cross_beam_elevation_m * s,
        upper_cross_beam_elevation_m=p0.upper_cross_beam_elevation_m * s,
        extra_cross_beams=p0.extra_cross_beams + extra_cross_beams(main_span_m), material=p0.material)

    return replace(reference, name=f"{reference.name}_L{main_span_m:g}", geometry=geometry, cable=cable,
                   pylon=pylon, reference_name=reference.name, pylon_inertia_ratio=inertia_ratio,
                   description=f"{reference.name} up-scaled to main span {main_span_m:g} m")
