"""Up-scaling rules of thesis section 1.5 against the thesis's own tables.

Sources: thesis Table 1.1 (A_c), Table 1.2 (h, L_s), Table 3.6 (mu, J) - numbers printed in the thesis,
which this project did not write; targets 0.5 % and 1 % (three printed digits). The closed form of
Eq 1.2 and its span limit: docs/thesis_errata.md, "Up-scaling".
"""

import math

import pytest

from bridge.config import load_scenario
from bridge.errors import InputError
from bridge.upscaling import cable_area_for_span, extra_cross_beams, pylon_inertia_ratio, span_limit_m

TABLE_1_1 = {"great_belt": 0.410, "model_a": 0.566, "model_b": 1.237, "model_c": 3.037}
TABLE_1_2 = {"great_belt": (180.50, 535), "model_a": (222.22, 659), "model_b": (333.33, 988),
             "model_c": (444.44, 1318)}


@pytest.mark.parametrize("name", list(TABLE_1_1))
def test_table_1_1_cable_area(name):
    s = load_scenario(name)
    assert s.cable.area_m2 == pytest.approx(TABLE_1_1[name], rel=0.005)


@pytest.mark.parametrize("name", list(TABLE_1_2))
def test_table_1_2_sag_and_side_span(name):
    s = load_scenario(name)
    sag, side = TABLE_1_2[name]
    assert s.geometry.sag_m == pytest.approx(sag, rel=0.005)
    assert s.geometry.side_span_m == pytest.approx(side, rel=0.005)


@pytest.mark.parametrize("name, mu, j", [("great_belt", 21.5e3, 2.9e6), ("model_c", 64.5e3, 13.2e6)])
def test_table_3_6_mu_and_j(name, mu, j):
    s = load_scenario(name)
    assert s.deck_mass_per_length_kg_m == pytest.approx(mu, rel=0.01)
    assert s.deck_inertia_per_length_kg_m2_m == pytest.approx(j, rel=0.01)


def test_eq_1_2_closed_form_satisfies_the_stress_equation():
    """The closed form must solve Eq 1.2 itself: sigma_0 = g (mu_b + 2 A rho_c)(L0/h0) L / (8 * 2A)."""
    ref = load_scenario("great_belt")
    for span in (1800.0, 2500.0, 4500.0):
        a = cable_area_for_span(ref, span)
        g0 = ref.geometry
        sigma = 9.81 * (ref.girder.mass_per_length_kg_m + 2 * a * ref.cable.density_kg_m3) \
            * (g0.main_span_m / g0.sag_m) * span / 8 / (2 * a)
        assert sigma == pytest.approx(ref.cable.allowable_stress_Pa, rel=1e-12)


def test_span_limit_is_where_the_area_diverges():
    ref = load_scenario("great_belt")
    limit = span_limit_m(ref)
    assert 5100 < limit < 5300  # 5187 m for these data (docs/thesis_errata.md)
    assert cable_area_for_span(ref, 0.999 * limit) > 50 * ref.cable.area_m2
    with pytest.raises(InputError, match="geometry.main_span_m"):
        cable_area_for_span(ref, limit)


def test_pylon_inertia_eq_1_3_and_section_scaling():
    ref, c = load_scenario("great_belt"), load_scenario("model_c")
    ratio = pylon_inertia_ratio(ref, c.cable.mass_per_length_main_kg_m, 4000.0)
    expected = (ref.girder.mass_per_length_kg_m + 2 * c.cable.mass_per_length_main_kg_m) * 4000**3 / (
        (ref.girder.mass_per_length_kg_m + 2 * ref.cable.mass_per_length_main_kg_m) * 1624**3)
    assert ratio == pytest.approx(expected, rel=1e-12)
    for part in ("lower_leg", "upper_leg"):
        got = getattr(c.pylon, part).i_about_a_m4 / getattr(ref.pylon, part).i_about_a_m4
        assert got == pytest.approx(ratio, rel=1e-9)


def test_extra_cross_beams_follow_the_thesis_models():
    assert [extra_cross_beams(x) for x in (1624, 2000, 3000, 4000)] == [0, 0, 1, 2]
    assert [load_scenario(n).pylon.extra_cross_beams for n in ("model_a", "model_b", "model_c")] == [0, 1, 2]


def test_any_span_and_geometric_similarity():
    ref, s = load_scenario("great_belt"), load_scenario("great_belt", main_span_m=2500.0)
    k = 2500.0 / 1624.0
    assert s.name == "great_belt_L2500"
    assert s.geometry.pylon_height_m == pytest.approx(ref.geometry.pylon_height_m * k)
    assert s.geometry.sag_ratio == pytest.approx(ref.geometry.sag_ratio)
    assert math.isclose(s.cable.density_kg_m3, ref.cable.density_kg_m3)


def test_reported_pylon_inertia_ratio_is_the_applied_one_also_with_overrides():
    """The summary's I/I0 is the one the up-scaling applied, also when a sweep overrides reference inputs."""
    from bridge.cable import solve_cables
    from bridge.cable_stage import cable_summary

    for over in ({}, {"girder.mass_per_length_kg_m": 20000.0}):
        ref = load_scenario("great_belt", overrides=over)
        s = load_scenario("model_b", overrides=over)
        got = cable_summary(s, solve_cables(s))["scenario.pylon_leg_inertia_ratio"]
        assert got == pytest.approx(s.pylon.lower_leg.i_about_a_m4 / ref.pylon.lower_leg.i_about_a_m4, rel=1e-9)
    assert load_scenario("great_belt").pylon_inertia_ratio == 1.0
