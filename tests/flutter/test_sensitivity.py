"""One derivative scaled (bridge.flutter.derivatives.scale_derivative) and tools/flutter_sensitivity.py."""

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from bridge.config import load_scenario
from bridge.flutter.aerodynamics import Theodorsen
from bridge.flutter.derivatives import derivatives_from_frf, scale_derivative
from bridge.flutter.determinant import governing, solve_pair

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "cfd"))
from cfd_helpers import load_tool  # noqa: E402

EIGHT = ("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4")


@pytest.mark.parametrize("name", EIGHT)
def test_scaling_one_derivative_leaves_the_other_seven_as_they_were(name):
    K = np.array([0.3, 0.8, 1.6])
    h = Theodorsen().frf(K, 1.0)
    before = derivatives_from_frf(K, h)
    after = derivatives_from_frf(K, scale_derivative(h, name, 1.7))
    for other in EIGHT:
        expected = 1.7 * getattr(before, other) if other == name else getattr(before, other)
        np.testing.assert_allclose(getattr(after, other), expected, rtol=1e-13, atol=1e-15, err_msg=other)


def test_an_unknown_derivative_is_refused():
    with pytest.raises(ValueError, match="B7"):
        scale_derivative(Theodorsen().frf(0.5, 1.0), "B7", 2.0)


def test_the_elasticity_of_a_power_law_is_its_exponent():
    tool = load_tool("flutter_sensitivity")
    factors = [0.5, 0.8, 1.25, 1.5]
    assert tool.elasticity(factors, [100.0 * f**0.3 for f in factors], 100.0) == pytest.approx(0.3, rel=1e-12)
    assert tool.elasticity([1.5], [100.0 * 1.5**-0.2], 100.0) == pytest.approx(-0.2, rel=1e-12)


def test_all_eight_derivatives_times_f_flutter_as_the_air_density_times_f(tmp_path, capsys):
    """The aerodynamic forces are (1/2) rho V^2 h_xy: every derivative times f is the air times f. The
    tool's --together on the 2-DOF thin plate section against the flutter solver with rho x 1.3 (and the
    unscaled plate at its documented 114.48 m/s)."""
    tool = load_tool("flutter_sensitivity")
    out = tmp_path / "s.json"
    rc = tool.main(["thin_plate_section", "--derivatives", "A2", "--factors", "0.8", "1.25", "--cache",
                    str(tmp_path / "cache"), "--out", str(out), "--together", *(f"{n}=1.3" for n in EIGHT)])
    assert rc == 0
    result = json.loads(out.read_text())
    assert result["unscaled"]["critical_speed_m_s"] == pytest.approx(114.48, abs=0.01)
    sc = load_scenario("thin_plate_section")
    modal, fopts = sc.section.modal_model(), sc.flutter
    gov = governing([solve_pair(modal.subset(p), Theodorsen(), 1.3 * 1.225, fopts.max_speed_m_s,
                                min_speed_m_s=fopts.min_speed_m_s, n_speed=fopts.speed_steps)
                     for p in modal.pairs(fopts.pairs)])
    assert result["together"]["critical_speed_m_s"] == pytest.approx(gov.critical_speed_m_s, rel=1e-8)
    assert result["together"]["critical_speed_m_s"] < 0.95 * result["unscaled"]["critical_speed_m_s"]
    a2 = result["derivatives"][0]
    assert a2["derivative"] == "A2" and [r["factor"] for r in a2["runs"]] == [0.8, 1.25]
    # more torsional damping, later flutter
    assert a2["runs"][0]["critical_speed_m_s"] < result["unscaled"]["critical_speed_m_s"] \
        < a2["runs"][1]["critical_speed_m_s"]
    assert math.isfinite(a2["elasticity"]) and a2["elasticity"] > 0


@pytest.mark.parametrize("args, field", [(["--factors", "1"], "--factors"), (["--derivatives", "P1"], "--derivatives"),
                                         (["--together", "A2=x"], "--together"),
                                         (["--together", "A2=-11"], "--together")])
def test_bad_input_names_the_option_and_writes_nothing(tmp_path, capsys, args, field):
    tool = load_tool("flutter_sensitivity")
    with pytest.raises(SystemExit) as exc:
        tool.main(["thin_plate_section", "--out", str(tmp_path / "s.json"), *args])
    assert exc.value.code == 2
    assert field in capsys.readouterr().err
    assert not (tmp_path / "s.json").exists()


def test_together_takes_a_negative_factor_a_derivative_whose_sign_differs(tmp_path):
    """H2* of a deck may change sign between grids (docs/aero.md); the plate's V_c with H2* x -1 is the
    flutter solver's with that model."""
    tool = load_tool("flutter_sensitivity")
    out = tmp_path / "s.json"
    assert tool.main(["thin_plate_section", "--derivatives", "A2", "--factors", "1.25", "--cache",
                      str(tmp_path / "cache"), "--out", str(out), "--together", "H2=-1"]) == 0
    result = json.loads(out.read_text())
    assert result["together"]["factors"] == {"H2": -1.0}
    sc = load_scenario("thin_plate_section")
    modal, fopts = sc.section.modal_model(), sc.flutter
    gov = governing([solve_pair(modal.subset(p), tool.Scaled(Theodorsen(), "H2", -1.0), 1.225, fopts.max_speed_m_s,
                                min_speed_m_s=fopts.min_speed_m_s, n_speed=fopts.speed_steps)
                     for p in modal.pairs(fopts.pairs)])
    assert result["together"]["critical_speed_m_s"] == pytest.approx(gov.critical_speed_m_s, rel=1e-8)
    assert result["together"]["critical_speed_m_s"] != pytest.approx(result["unscaled"]["critical_speed_m_s"],
                                                                    rel=1e-3)
