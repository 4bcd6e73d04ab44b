"""Static coefficients and the Strouhal number of a section held still (bridge/aero/static.py).

Closed forms: the spectral peak of a known sine on uneven samples; a symmetric section's odd and even
coefficients; thin-aerofoil theory's lift and moment slopes (2 pi and pi/2 about mid-chord; Glauert,
*The elements of aerofoil and airscrew theory*, 1926) at a coarse grid with a loose tolerance.  Published
data: the circular cylinder at Re = 100 (Williamson 1989, St = 0.164) in the slow set."""

import dataclasses
import math

import numpy as np
import pytest

from bridge.aero.forced_motion import ForceRecord, StaticCase, run_case
from bridge.aero.options import AeroOptions
from bridge.aero.presets import QUALITY, section_polygons
from bridge.aero.static import (
    chordwise_loading,
    shedding_frequency,
    static_coefficients,
    thin_plate_loading,
    window_mean,
)
from bridge.cfd.sections import FlatPlate
from bridge.errors import InputError


def test_the_shedding_frequency_of_a_known_sine_on_uneven_steps():
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.01, 0.03, 3000))           # about 60 time units, uneven
    f0 = 0.2371
    x = 0.3 + 0.01 * t + 0.05 * np.sin(2 * np.pi * f0 * t + 0.4) + 0.002 * rng.standard_normal(t.size)
    f, rms = shedding_frequency(t, x)
    assert f == pytest.approx(f0, rel=2e-3)
    assert rms == pytest.approx(0.05 / math.sqrt(2), rel=0.05)
    # a steady record (a constant and a drift only) has no shedding frequency
    f, rms = shedding_frequency(t, 0.3 + 0.01 * t)
    assert math.isnan(f) and rms < 1e-10
    # a record of 1.5 periods cannot resolve its frequency
    short = t[t < 1.5 / f0]
    f, rms = shedding_frequency(short, np.sin(2 * np.pi * f0 * short))
    assert math.isnan(f) and rms > 0.1


def test_the_window_mean_weights_uneven_steps():
    t = np.array([0.0, 0.1, 1.0, 1.1, 2.0])
    x = 2.0 * t
    assert window_mean(t, x, 0.0) == pytest.approx(2.0)   # mean of a line over [0, 2]
    assert window_mean(t, x, 1.0, 2.0) == pytest.approx(3.0)


def test_fits_give_the_line_through_the_angles():
    angles = np.array([-2.0, 0.0, 2.0])
    a = np.radians(angles)
    recs = []
    for alpha in a:
        t = np.linspace(0.0, 10.0, 201)
        one = np.ones_like(t)
        recs.append(ForceRecord(t=t, lift=0.5 * (0.1 + 5.0 * alpha) * one, drag=0.5 * (0.2 + 0.3 * alpha) * one,
                                moment=0.5 * (-0.01 + 1.2 * alpha) * one, motion=alpha * one))
    st = static_coefficients(recs, angles, depth_over_chord=0.1)
    assert st.fit(st.lift) == pytest.approx((0.1, 5.0))
    qs = st.quasi_steady()
    assert (qs.lift_coefficient, qs.lift_slope_per_rad) == pytest.approx((0.1, 5.0))
    assert (qs.drag_coefficient, qs.drag_slope_per_rad) == pytest.approx((0.2, 0.3))
    assert (qs.moment_coefficient, qs.moment_slope_per_rad) == pytest.approx((-0.01, 1.2))
    assert np.all(np.isnan(st.strouhal)) and np.allclose(st.settling, 0.0)


def test_static_angles_are_checked():
    assert AeroOptions(static_angles_deg=()).static_angles_deg == ()
    assert AeroOptions(static_angles_deg=(3, -1)).static_angles_deg == (-1.0, 3.0)
    for bad, word in (((1.0,),  "at least 2"), ((0.0, 0.0), "distinct"), ((0.0, 45.0), "<= 30"),
                      ("0, 2", "a list")):
        with pytest.raises(InputError, match=word):
            AeroOptions(static_angles_deg=bad)


# a coarse but resolving grid for a 4 % plate: 24 cells per chord, dy = dx / 4 (the plate 4 cells thick)
COARSE = QUALITY["tiny"].with_(name="coarse", cells_per_chord=24, dy_over_dx=0.25, upstream=1.0,
                             downstream=4.0, half_height=1.5, core_half_height=0.1, reynolds=1000.0,
                             static_duration=12.0)


@pytest.mark.slow  # ~40 s (three static runs): runs in CI with -m slow
def test_a_thin_plate_held_still_has_thin_aerofoil_slopes_and_symmetry():
    """Plate 4 % thick at -2, 0, 2 degrees, Re 1000, 24 cells per chord, 12 chords of run: C_L odd and C_D
    even in the angle (the grid is symmetric), dC_L/dalpha within 20 % of 2 pi (viscosity, the finite
    wake, the short run and Wagner's lag all lower it) and the aerodynamic centre near the quarter chord:
    dC_M/dalpha (about mid-chord) over dC_L/dalpha within 0.25 +- 0.05."""
    poly = section_polygons(FlatPlate(1.0, 0.04))[0]
    angles = (-2.0, 0.0, 2.0)
    recs = [run_case(poly, StaticCase(a, grid_angle_deg=2.0), COARSE) for a in angles]
    st = static_coefficients(recs, angles, 0.04)
    assert abs(st.lift[1]) < 1e-3 and abs(st.moment[1]) < 1e-4
    assert st.lift[0] == pytest.approx(-st.lift[2], rel=1e-3)
    assert st.drag[0] == pytest.approx(st.drag[2], rel=1e-3)
    _, dcl = st.fit(st.lift)
    _, dcm = st.fit(st.moment)
    assert 0.8 * 2 * np.pi < dcl < 1.05 * 2 * np.pi, dcl
    assert 0.20 < dcm / dcl < 0.30, (dcm, dcl)


def test_the_static_group_report_and_lateral_model(tmp_path):
    """results.h5 /aero/static as docs/results.md lists it (every dataset with unit and description), the
    report's wording for a steady and an unresolved wake, and the flutter model: the CFD table completed by
    the static runs' lateral terms, which a scenario's [flutter.quasi_steady] does not replace (it completes a
    CFD table without static runs)."""
    import h5py

    from bridge.aero.stage import static_report, write_static_h5
    from bridge.flutter.aerodynamics import Theodorsen, WithLateral
    from bridge.flutter.options import FlutterOptions

    st = dataclasses.replace(
        static_coefficients([ForceRecord(t=np.linspace(0, 10, 101), lift=np.full(101, a), drag=np.full(101, 0.1),
                                         moment=np.full(101, a / 4), motion=np.zeros(101)) for a in (-0.1, 0.0, 0.1)],
                            (-2.0, 0.0, 2.0), 0.1),
        lift_rms=np.array([0.0, 0.0, 0.05]))
    with h5py.File(tmp_path / "r.h5", "w") as h5:
        write_static_h5(h5.create_group("static"), st)
    with h5py.File(tmp_path / "r.h5", "r") as h5:
        g = h5["static"]
        names = []
        g.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert {"angle_of_attack", "drag_coefficient", "lift_coefficient", "moment_coefficient", "lift_rms",
                "shedding_frequency", "strouhal_on_depth", "settling", "fit/lift_slope",
                "fit/drag_at_zero"} <= set(names)
        for n in names:
            assert g[n].attrs["unit"] is not None and g[n].attrs["description"], n
        assert g["fit/lift_slope"][()] == pytest.approx(0.2 / np.radians(2.0))   # C_L = 2 x the CFD lift
        assert g.attrs["depth_over_chord"] == 0.1
    text = "\n".join(static_report(st))
    assert "| steady |" in text and "unresolved" in text
    static_qs = st.quasi_steady()
    cfd = WithLateral(Theodorsen(), static_qs)
    assert FlutterOptions(aerodynamics="cfd").aerodynamic_model(cfd=cfd).lateral is static_qs
    own = FlutterOptions.from_mapping({"aerodynamics": "cfd", "quasi_steady": {
        "lift_coefficient": 0.0, "lift_slope_per_rad": 5.0, "drag_coefficient": 0.3, "moment_coefficient": 0.0,
        "moment_slope_per_rad": 1.0}})
    assert own.aerodynamic_model(cfd=cfd) is cfd   # the deck's own static coefficients stay
    model = own.aerodynamic_model(cfd=cfd.base)     # a CFD table without static runs: completed by the scenario's
    assert model.base is cfd.base and model.lateral.drag_coefficient == 0.3


def test_the_thin_plates_loading_integrates_to_thin_aerofoil_theory():
    """Delta C_p = 4 alpha sqrt((1 - x) / x) (Katz and Plotkin, Low-Speed Aerodynamics, 2001, 5.3): its strips
    add up to 2 pi alpha, and samples of it give pi alpha / 2 about the mid-chord (the quarter-chord centre)."""
    alpha = math.radians(3.0)
    edges = (0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0)
    strips = [thin_plate_loading(alpha, a, b) for a, b in zip(edges[:-1], edges[1:], strict=True)]
    assert sum(strips) == pytest.approx(2 * math.pi * alpha, rel=1e-12)
    assert strips[0] / sum(strips) == pytest.approx(0.282, abs=1e-3)      # the leading edge's share (module doc)
    # midpoint samples in x = (1 - cos th) / 2, where the loading is smooth: dx = sin(th) / 2 dth
    n = 4000
    th = (np.arange(n) + 0.5) * math.pi / n
    x = 0.5 * (1 - np.cos(th))
    width = 0.5 * np.sin(th) * math.pi / n
    got = chordwise_loading(x, 4 * alpha * np.sqrt((1 - x) / x), width, alpha, edges)
    assert got.lift == pytest.approx(2 * math.pi * alpha, rel=1e-5)
    assert got.moment == pytest.approx(math.pi * alpha / 2, rel=1e-5)
    assert got.centre_of_pressure == pytest.approx(0.25, abs=1e-5)
    one_sample = np.max(4 * alpha * np.sqrt((1 - x) / x) * width)   # a sample near a strip's edge counts on one side
    assert got.strips == pytest.approx(got.potential, abs=one_sample)
    # a uniform loading of 1: each strip its width, the centre of pressure at the mid-chord
    x = (np.arange(100) + 0.5) / 100
    flat = chordwise_loading(x, np.ones(100), np.full(100, 0.01), alpha, edges)
    assert flat.strips == pytest.approx(np.diff(edges))
    assert flat.centre_of_pressure == pytest.approx(0.5)
    with pytest.raises(ValueError, match="edges"):
        chordwise_loading(x, np.ones(100), np.full(100, 0.01), alpha, (0.1, 1.0))
    with pytest.raises(ValueError, match="strip"):
        thin_plate_loading(alpha, 0.5, 1.2)


def test_run_case_shows_the_flow_to_an_observer_after_every_step():
    q = QUALITY["tiny"].with_(static_duration=1.0)
    seen = []
    rec = run_case(section_polygons(FlatPlate(1.0, 0.1)), StaticCase(2.0), q, observe=lambda flow: seen.append(flow.t))
    assert len(seen) == rec.steps and seen == pytest.approx(list(rec.t))
