"""Two-mode determinant method: the reduced form, the erratum of Eq 4.40/4.43, Selberg's formula, no-flutter
results and input that must be refused.

Sources: the thesis, Eq 4.9, 4.26-4.29, 4.39-4.44, 5.15-5.21; Theodorsen (1935), NACA Report 496;
Selberg (1961), see docs/reference_cases.md (about 5 %); Scanlan and Tomko (1971) for the derivative form.
"""

import csv

import numpy as np
import pytest
from conftest import RHO, plate_section, selberg_speed

from bridge.errors import InputError
from bridge.flutter.aerodynamics import DerivativeTable, FRFTable, Theodorsen
from bridge.flutter.derivatives import derivatives_from_frf
from bridge.flutter.determinant import (
    determinant,
    dimensional_matrix,
    governing,
    reduced_matrix,
    solve_pair,
    solve_pairs,
)
from bridge.flutter.modal import ModalModel


def bridge_pair(**kw) -> ModalModel:
    """A two-mode bridge (a_jj, a_kk, a_jk of Model C, thesis Table 3.6) with damping."""
    args = dict(bending_frequency_hz=0.12, torsion_frequency_hz=0.3, a_jj=0.345, a_kk=0.161, a_jk=0.178,
                mass_per_length_kg_m=23_000.0, inertia_per_length_kg_m2_m=2.5e6, deck_width_m=31.0,
                deck_length_m=2694.0, bending_damping_ratio=0.008, torsion_damping_ratio=0.012)
    args.update(kw)
    return ModalModel.from_two_modes(**args)


def test_structural_term_follows_from_the_modal_equation():
    # Eq 4.9 applied to q = e^{i w t} (derivatives by central differences in t) gives A_j(w) q of Eq 4.28.
    model = bridge_pair()
    t, dt = 0.37, 1e-4
    for w in (0.3, 0.9, 2.5):
        def q(s, w=w):
            return np.exp(1j * w * s)

        qd = (q(t + dt) - q(t - dt)) / (2 * dt)
        qdd = (q(t + dt) - 2 * q(t) + q(t - dt)) / dt**2
        m, wj, z = model.modal_masses, model.angular_frequencies, model.damping_ratios
        lhs = m * (qdd + 2 * z * wj * qd + wj**2 * q(t)) / q(t)
        A_s = np.diagonal(dimensional_matrix(model, Theodorsen(), 0.0, w, 40.0))   # no air: A_a = 0
        np.testing.assert_allclose(A_s, lhs, rtol=1e-6)


def test_reduced_form_equals_dimensional_determinant_up_to_a_positive_factor():
    # det(A_s - A_a) = (V^2/B^2)^2 m_j m_k det(a_s - a_a): row i of the dimensional matrix is
    # V^2 m_i / B^2 times row i of the reduced one.  Checked at random (w, V).
    model, aero = bridge_pair(), Theodorsen()
    rng = np.random.default_rng(7)
    w, V = rng.uniform(0.2, 3.0, 50), rng.uniform(5.0, 120.0, 50)
    B = model.deck_width_m
    dim = determinant(dimensional_matrix(model, aero, RHO, w, V))
    red = determinant(reduced_matrix(model, aero, RHO, w * B / V, V))
    np.testing.assert_allclose(dim, (V / B) ** 4 * np.prod(model.modal_masses) * red, rtol=1e-11)
    # the printed Eq 4.43 is not: the ratio is not even a constant
    bad = determinant(reduced_matrix(model, aero, RHO, w * B / V, V, structural_form="thesis_eq_4_43"))
    ratio = dim / ((V / B) ** 4 * np.prod(model.modal_masses) * bad)
    assert np.max(np.abs(ratio - 1.0)) > 0.5


def test_erratum_form_gives_a_different_or_no_flutter_speed():
    section = plate_section(0.4, 50.0, 0.7)
    right = solve_pair(section, Theodorsen(), RHO, 3 * selberg_speed(section))
    wrong = solve_pair(section, Theodorsen(), RHO, 3 * selberg_speed(section), structural_form="thesis_eq_4_43")
    assert right.flutter and abs(right.critical_speed_m_s / selberg_speed(section) - 1) < 0.05
    assert not wrong.flutter or abs(wrong.critical_speed_m_s / right.critical_speed_m_s - 1) > 0.2


@pytest.mark.parametrize("frequency_ratio", [0.3, 0.4, 0.5])
@pytest.mark.parametrize("mass_ratio", [20.0, 50.0, 100.0])
@pytest.mark.parametrize("radius_ratio", [0.6, 0.7, 0.8])
def test_thin_plate_flutter_speed_within_5_percent_of_selberg(frequency_ratio, mass_ratio, radius_ratio):
    section = plate_section(frequency_ratio, mass_ratio, radius_ratio)
    U_s = selberg_speed(section)
    r = solve_pair(section, Theodorsen(), RHO, 3 * U_s)
    assert r.flutter
    assert abs(r.critical_speed_m_s / U_s - 1) < 0.05, (r.critical_speed_m_s, U_s)
    # the solution satisfies Eq 4.29 and the frequency lies between heave and pitch frequencies
    assert r.residual < 1e-9
    f_h, f_a = section.frequencies_hz
    assert f_h < r.frequency_hz < f_a
    assert np.isclose(r.reduced_frequency, 2 * np.pi * r.frequency_hz * section.deck_width_m / r.critical_speed_m_s)


def test_no_flutter_below_the_maximum_speed_is_a_result_not_an_error():
    section = plate_section(0.4, 50.0, 0.7)
    U_s = selberg_speed(section)
    r = solve_pair(section, Theodorsen(), RHO, 0.8 * U_s)
    assert not r.flutter and np.isnan(r.critical_speed_m_s)
    assert r.max_speed_searched_m_s == pytest.approx(0.8 * U_s)
    # without aerodynamic coupling (a_jk = 0) a Theodorsen plate has no two-mode flutter at all
    decoupled = bridge_pair(a_jk=0.0)
    assert not solve_pair(decoupled, Theodorsen(), RHO, 300.0).flutter


def test_more_coupling_means_lower_critical_speed_and_governing_pair_is_the_lowest():
    weak, strong = bridge_pair(a_jk=0.16), bridge_pair(a_jk=0.2)
    v_weak = solve_pair(weak, Theodorsen(), RHO, 300.0).critical_speed_m_s
    v_strong = solve_pair(strong, Theodorsen(), RHO, 300.0).critical_speed_m_s
    assert v_strong < v_weak
    # three symmetric bending modes with one torsional mode: every pair solved, the lowest governs
    uu = np.diag([0.345, 0.3, 0.28, 0.0])
    tt = np.diag([0.0, 0.0, 0.0, 0.161])
    ut = np.zeros((4, 4))
    ut[:3, 3] = [0.178, 0.05, 0.12]
    model = ModalModel(labels=("S-V1", "S-V2", "S-V3", "S-T1"), kinds=("vertical",) * 3 + ("torsional",),
                       symmetries=("S",) * 4, frequencies_hz=np.array([0.12, 0.18, 0.24, 0.3]),
                       damping_ratios=np.full(4, 0.01), uu=uu, ut=ut, tt=tt, mass_per_length_kg_m=23_000.0,
                       inertia_per_length_kg_m2_m=2.5e6, deck_width_m=31.0, deck_length_m=2694.0)
    results = solve_pairs(model, Theodorsen(), RHO, 300.0, which="thesis")
    assert [r.pair for r in results] == [("S-V1", "S-T1"), ("S-V2", "S-T1"), ("S-V3", "S-T1")]
    speeds = [r.critical_speed_m_s if r.flutter else np.inf for r in results]
    assert governing(results).critical_speed_m_s == min(speeds)


def test_negative_damping_and_missing_modes_are_refused():
    with pytest.raises(InputError, match="bending_damping_ratio"):   # named as the user gave it
        bridge_pair(bending_damping_ratio=-0.01)
    with pytest.raises(InputError, match="torsion_frequency_hz"):
        bridge_pair(torsion_frequency_hz=0.0)
    with pytest.raises(InputError, match="uu"):
        ModalModel(labels=("a", "b"), kinds=("vertical", "torsional"), symmetries=("S", "S"),
                   frequencies_hz=np.ones(2), damping_ratios=np.zeros(2), uu=np.eye(3), ut=np.zeros((2, 2)),
                   tt=np.eye(2), mass_per_length_kg_m=1.0, inertia_per_length_kg_m2_m=1.0, deck_width_m=1.0,
                   deck_length_m=1.0)
    only_bending = ModalModel(labels=("S-V1", "SS-V1"), kinds=("vertical", "vertical"), symmetries=("S", "SS"),
                              frequencies_hz=np.array([0.1, 0.15]), damping_ratios=np.zeros(2),
                              uu=np.diag([0.3, 0.3]), ut=np.zeros((2, 2)), tt=np.zeros((2, 2)),
                              mass_per_length_kg_m=1.0, inertia_per_length_kg_m2_m=1.0, deck_width_m=1.0,
                              deck_length_m=1.0)
    with pytest.raises(InputError, match="torsional"):
        only_bending.pairs("all")


def _theodorsen_table(omega, speed):
    Om, V = np.meshgrid(omega, speed, indexing="ij")
    return FRFTable(omega, speed, Theodorsen().frf(Om, V))


def test_table_aerodynamics_give_the_closed_form_speed_and_refuse_to_extrapolate():
    section = plate_section(0.4, 50.0, 0.7)
    direct = solve_pair(section, Theodorsen(), RHO, 200.0, min_speed_m_s=20.0)
    # 200 x 2 grid; Theodorsen is independent of V, so linear interpolation in V is exact
    table = _theodorsen_table(np.linspace(0.05, 12.0, 400), np.array([10.0, 250.0]))
    tab = solve_pair(section, table, RHO, 200.0, min_speed_m_s=20.0)
    assert tab.flutter and abs(tab.critical_speed_m_s / direct.critical_speed_m_s - 1) < 0.005
    # V beyond the table
    with pytest.raises(InputError, match="max_speed_m_s"):
        solve_pair(section, _theodorsen_table(np.linspace(0.05, 12.0, 50), np.array([10.0, 80.0])), RHO, 200.0)
    # Omega range that misses the flutter frequency: "no root in the covered range", not "no flutter"
    # (and not an error that would stop the other pairs; tests/flutter/test_tables.py)
    missed = solve_pair(section, _theodorsen_table(np.linspace(2.0, 12.0, 50), np.array([10.0, 250.0])), RHO,
                        200.0, min_speed_m_s=20.0)
    assert not missed.flutter and missed.no_root_in_covered_range and missed.covered_omega_range == (2.0, 12.0)


def test_theodorsen_through_scanlan_csv_gives_the_same_critical_speed(tmp_path):
    section = plate_section(0.35, 40.0, 0.65)
    direct = solve_pair(section, Theodorsen(), RHO, 3 * selberg_speed(section))
    K = np.linspace(0.05, 12.0, 240)
    d = derivatives_from_frf(K, Theodorsen().frf(K, 1.0))
    path = tmp_path / "theodorsen_derivatives.csv"
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        fh.write("# Theodorsen flat plate, Scanlan convention (h, L down), mid-chord\n")
        fh.write("# convention: vertical=down lift=down pitch=nose_up reference_length=B\n")
        w.writerow(["reduced_velocity", "H1*", "H2*", "H3*", "H4*", "A1*", "A2*", "A3*", "A4*"])
        for i in range(K.size):
            w.writerow([repr(float(2 * np.pi / K[i]))] + [repr(float(getattr(d, n)[i])) for n in d._fields[:8]])
    table = DerivativeTable.from_csv(path)
    via_csv = solve_pair(section, table, RHO, 3 * selberg_speed(section), min_speed_m_s=0.2 * direct.critical_speed_m_s)
    assert via_csv.flutter
    assert abs(via_csv.critical_speed_m_s / direct.critical_speed_m_s - 1) < 1e-3
    assert abs(via_csv.frequency_hz / direct.frequency_hz - 1) < 1e-3
    with pytest.raises(InputError, match="reduced_frequency"):
        table.frf(20.0, 50.0)


def test_lateral_modes_are_accepted_but_left_out_of_pairs():
    # the FEM may hand over lateral modes with no vertical/torsional component; they form no pair
    uu = np.diag([0.0, 0.3, 0.0])
    tt = np.diag([0.0, 0.0, 0.25])
    ut = np.zeros((3, 3))
    ut[1, 2] = 0.2
    model = ModalModel(labels=("S-L1", "S-V1", "S-T1"), kinds=("lateral", "vertical", "torsional"),
                       symmetries=("S",) * 3, frequencies_hz=np.array([0.05, 0.1, 0.28]),
                       damping_ratios=np.zeros(3), uu=uu, ut=ut, tt=tt, mass_per_length_kg_m=23_000.0,
                       inertia_per_length_kg_m2_m=2.5e6, deck_width_m=31.0, deck_length_m=2694.0)
    assert model.pairs("all") == [(1, 2)]
    with pytest.raises(InputError, match="uu/tt"):
        ModalModel(labels=("S-V1", "S-T1"), kinds=("vertical", "torsional"), symmetries=("S", "S"),
                   frequencies_hz=np.array([0.1, 0.28]), damping_ratios=np.zeros(2), uu=np.zeros((2, 2)),
                   ut=np.zeros((2, 2)), tt=np.diag([0.0, 0.25]), mass_per_length_kg_m=1.0,
                   inertia_per_length_kg_m2_m=1.0, deck_width_m=1.0, deck_length_m=1.0)
