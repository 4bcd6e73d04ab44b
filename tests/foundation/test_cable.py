"""Cable statics (thesis chapter 2): closed forms, RK4 convergence order, thesis numbers.

Closed forms: a cable loaded uniformly per horizontal length is a parabola (Eq 2.4:
H = w L^2 / (8 h)); a cable under its own weight only is a catenary, y = (H/w)(cosh(w x/H) - 1).
Thesis numbers: Eq 1.1 and 3.3 (H ~ 3.85e8 N for both cables, parabolic), Eq 3.3 (f_1 ~ 0.12 Hz).
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from bridge.cable import integrate_rk4, solve_cables, solve_main_span, solve_side_span
from bridge.config import GRAVITY_M_S2 as G
from bridge.config import load_scenario
from bridge.errors import ConvergenceError

L, SAG = 1624.0, 180.5


def catenary_h(w: float) -> float:
    """H of a catenary of span L and sag SAG with weight w per arc length (N/m)."""
    return brentq(lambda h: h / w * (math.cosh(w * L / 2 / h) - 1) - SAG, 1e5, 1e12, xtol=1e-6, rtol=1e-15)


def test_parabola_limit_mu_c_to_zero():
    h, _, _, (x, y, _, _) = solve_main_span(L / 2, SAG, 7390.0, 0.0, 64, tolerance=1e-13)
    assert h == pytest.approx(G * 7390.0 * L**2 / (8 * SAG), rel=1e-12)  # Eq 2.4 exact for a parabola
    np.testing.assert_allclose(y, 4 * SAG * x**2 / L**2, atol=1e-9)


def test_catenary_limit_mu_b_to_zero():
    mu_c = 3360.0
    h, _, _, (x, y, _, s) = solve_main_span(L / 2, SAG, 0.0, mu_c, 400, tolerance=1e-13)
    h_exact = catenary_h(mu_c * G)
    assert h == pytest.approx(h_exact, rel=1e-9)
    a = h_exact / (mu_c * G)
    np.testing.assert_allclose(y, a * (np.cosh(x / a) - 1), rtol=0, atol=1e-6)
    assert s[-1] == pytest.approx(a * math.sinh(L / 2 / a), rel=1e-9)  # arc length


def test_rk4_fourth_order_on_the_catenary():
    """Error in H against the closed-form catenary falls as dx^4 (observed order from 3 refinements)."""
    mu_c = 3360.0
    h_exact = catenary_h(mu_c * G)
    steps = np.array([8, 16, 32, 64])
    err = [abs(solve_main_span(L / 2, SAG, 0.0, mu_c, n, tolerance=1e-14)[0] / h_exact - 1) for n in steps]
    slope = -np.polyfit(np.log(steps[1:]), np.log(err[1:]), 1)[0]
    assert 3.7 < slope < 4.4, (err, slope)


def test_side_span_shooting_hits_the_pylon_and_matches_a_parabola():
    w_b, h_force = 7390.0, 1.9e8
    alpha, _, res, (x, y, yp, _) = solve_side_span(h_force, 535.0, SAG, w_b, 0.0, 64)
    assert res < 1e-10 and y[-1] == pytest.approx(SAG, rel=1e-10)
    # closed form with y'' = + g w / H: alpha = h/L_s - g w L_s / (2 H)
    assert alpha == pytest.approx(SAG / 535.0 - G * w_b * 535.0 / (2 * h_force), rel=1e-10)


def test_great_belt_against_thesis_numbers():
    s = load_scenario("great_belt")
    c = solve_cables(s)
    assert c.horizontal_force_total_N == pytest.approx(3.85e8, rel=0.01)  # Eq 1.1, 3.3
    assert c.horizontal_force_per_cable_N == pytest.approx(1.94e8, rel=0.01)  # mu_b/2 per cable, thesis_errata.md
    assert c.horizontal_force_total_N > c.parabolic_estimate_total_N  # the arc is longer than the chord
    assert c.equilibrium_residual < 1e-6  # Eq 2.13
    assert c.main_residual < 1e-6
    assert c.first_vertical_frequency_estimate_hz == pytest.approx(0.12, abs=0.005)  # Eq 3.3
    # hanger geometry: shortest at mid-span, equal to the clearance between cable low point and girder
    assert c.hanger_length_m.min() == pytest.approx(s.geometry.cable_low_point_m - s.geometry.girder_elevation_m)
    assert np.all(np.diff(c.spans[1].z_m) > 0) and c.spans[1].z_m[0] == pytest.approx(535.0)


def test_equilibrium_residual_detects_a_wrong_load():
    """Eq 2.13 is a real check: carrying the full girder on each cable breaks it."""
    s = load_scenario("great_belt")
    c = solve_cables(s)
    weight_if_doubled = c.total_weight_N + G * s.girder.mass_per_length_kg_m * (1624 + 2 * 535)
    supports = 4 * (c.v_pylon_per_cable_N + c.v_anchor_per_cable_N)
    assert abs(supports - weight_if_doubled) / weight_if_doubled > 0.1


def test_non_convergence_reports_the_last_residual(monkeypatch):
    import bridge.cable as cable

    monkeypatch.setattr(cable, "MAX_ITERATIONS", 1)
    with pytest.raises(ConvergenceError, match="last residual"):
        cable.solve_main_span(L / 2, SAG, 7390.0, 3360.0, 16)


def test_integrator_rejects_zero_steps():
    with pytest.raises(ValueError):
        integrate_rk4(1e8, 1.0, 1.0, 10.0, 0)
