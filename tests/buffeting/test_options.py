"""The [buffeting] table: defaults, errors that name the key, and where the stage sits in the pipeline (planned
only when asked for or when the table exists; its options in its cache key and nobody else's)."""

from dataclasses import replace

import pytest

from bridge.buffeting.options import BuffetingOptions
from bridge.config import load_scenario, with_aerodynamics
from bridge.errors import InputError
from bridge.pipeline import default_stages, plan_stages, stage_keys

STATIC = {"lift_coefficient": 0.0, "lift_slope_per_rad": 5.0, "drag_coefficient": 0.08, "moment_coefficient": 0.0,
          "moment_slope_per_rad": 1.2}


def test_defaults_and_their_derived_values():
    o = BuffetingOptions.from_mapping({}, "buffeting")
    t = o.turbulence
    assert (o.spectrum, o.admittance, o.self_excited, o.speed_steps) == ("kaimal", "sears", True, 10)
    assert (t.intensity_u, t.iw, t.length_scale_u_m, t.lw, t.decay_u, t.decay_w) == (0.11, 0.055, 180.0, 15.0, 10.0,
                                                                                        6.5)
    o = BuffetingOptions.from_mapping({"turbulence_intensity_w": 0.07, "length_scale_w_m": 20.0,
                                       "static_coefficients": {**STATIC, "drag_slope_per_rad": -0.2},
                                       "admittance": "table", "admittance_reduced_frequency": [0, 1],
                                       "admittance_squared": [1, 0.2]}, "buffeting")
    assert o.turbulence.iw == 0.07 and o.turbulence.lw == 20.0 and o.static_coefficients.drag_slope_per_rad == -0.2
    assert o.admittance_model.squared_at(0.5) == pytest.approx(0.6)


@pytest.mark.parametrize("bad, key, allowed", [
    ({"turbulence_intensity_u": 1.5}, "buffeting.turbulence_intensity_u", "<= 1"),
    ({"spectrum": "davenport"}, "buffeting.spectrum", "kaimal, von_karman"),
    ({"coherence_decay_w": -1}, "buffeting.coherence_decay_w", ">= 0"),
    ({"gust_factor": 2.0}, "buffeting.gust_factor", "unknown key"),
    ({"admittance": "table", "admittance_reduced_frequency": [0, 1], "admittance_squared": [1]},
     "buffeting.admittance_squared", "one per admittance_reduced_frequency"),
    ({"admittance_reduced_frequency": [0, 1]}, "buffeting.admittance_reduced_frequency", "only with"),
    ({"static_coefficients": {k: v for k, v in STATIC.items() if k != "moment_slope_per_rad"}},
     "buffeting.static_coefficients.moment_slope_per_rad", "missing"),
    ({"static_coefficients": {**STATIC, "drag_coefficient": -0.1}}, "buffeting.static_coefficients.drag_coefficient",
     ">= 0"),
    ({"speed_steps": 1}, "buffeting.speed_steps", "integer >= 2"),
    ({"min_speed_m_s": 30.0, "max_speed_m_s": 20.0}, "buffeting.max_speed_m_s", "> 30"),
    ({"self_excited": "yes"}, "buffeting.self_excited", "true or false"),
    ({"frequency_steps": 50}, "buffeting.frequency_steps", ">= 101"),
])
def test_a_bad_value_names_its_key_and_what_is_allowed(bad, key, allowed):
    with pytest.raises(InputError) as err:
        BuffetingOptions.from_mapping(bad, "buffeting")
    assert err.value.key == key and allowed in err.value.allowed, err.value


def test_a_scenario_table_plans_the_stage_and_keys_only_it(tmp_path):
    path = tmp_path / "windy.toml"
    path.write_text('reference = "great_belt"\nmain_span_m = 1624.0\n[flutter]\naerodynamics = "theodorsen"\n'
                    "[buffeting]\nturbulence_intensity_u = 0.14\n")
    windy = load_scenario(path)
    assert windy.buffeting.turbulence_intensity_u == 0.14
    plain = with_aerodynamics(load_scenario("great_belt"), "theodorsen")
    assert "buffeting" in default_stages(windy) and "buffeting" not in default_stages(plain)
    assert plan_stages(plain, ["buffeting"]) == ("cable", "fem", "flutter", "buffeting")
    a, b = stage_keys(plain, ["buffeting"]), stage_keys(replace(plain, buffeting=windy.buffeting), ["buffeting"])
    assert [s for s in a if a[s] != b[s]] == ["buffeting"]          # the FEM and flutter results are reused
    bad = tmp_path / "bad.toml"
    bad.write_text('reference = "great_belt"\nmain_span_m = 1624.0\n[buffeting]\nspectrum = "davenport"\n')
    with pytest.raises(InputError) as err:
        load_scenario(bad)
    assert err.value.key == "buffeting.spectrum"
    with pytest.raises(InputError) as err:                  # modes without shapes along a deck: not this stage
        plan_stages(load_scenario("thin_plate_section"), ["buffeting"])
    assert err.value.key == "--stages" and "buffeting" in str(err.value)
