"""Multimode p-k flutter: agreement with the determinant method, decoupled modes, static divergence.

Sources: the thesis Eq 4.9, 4.23-4.29; Theodorsen (1935), NACA Report 496; the divergence speed of a plate
with the moment about mid-chord follows from the static moment slope pi/2 (potential flow).
"""

import numpy as np
import pytest
from conftest import RHO, plate_section, selberg_speed

from bridge.flutter.aerodynamics import Theodorsen
from bridge.flutter.determinant import solve_pair
from bridge.flutter.modal import ModalModel
from bridge.flutter.multimode import aeroelastic_eigenvalues, pk_sweep


@pytest.mark.parametrize("frequency_ratio, mass_ratio, radius_ratio, damping", [
    (0.3, 20.0, 0.6, 0.0), (0.4, 50.0, 0.7, 0.005), (0.5, 100.0, 0.8, 0.01), (0.45, 30.0, 0.75, 0.02)])
def test_two_mode_pk_agrees_with_determinant(frequency_ratio, mass_ratio, radius_ratio, damping):
    section = plate_section(frequency_ratio, mass_ratio, radius_ratio, damping=damping)
    vmax = 2 * selberg_speed(section)
    det = solve_pair(section, Theodorsen(), RHO, vmax, n_speed=60)
    pk = pk_sweep(section, Theodorsen(), RHO, vmax, n_speed=40)
    assert det.flutter and pk.flutter
    assert abs(pk.critical_speed_m_s / det.critical_speed_m_s - 1) < 0.005
    assert abs(pk.frequency_hz_at_flutter / det.frequency_hz - 1) < 0.005
    # below V_c every mode is damped; the sweep starts from the structural frequencies
    below = pk.speed_m_s < pk.critical_speed_m_s
    assert np.all(pk.damping_ratio[below] > 0)
    np.testing.assert_allclose(pk.frequency_hz[0], section.frequencies_hz, rtol=0.05)


def test_an_uncoupled_extra_mode_does_not_change_the_critical_speed():
    # S-V2 has no aerodynamic coupling to S-V1 or S-T1 (uu[0,1] = ut[1,2] = 0): the 3-mode p-k result
    # must be the two-mode determinant result of (S-V1, S-T1).
    uu = np.diag([0.345, 0.3, 0.0])
    tt = np.diag([0.0, 0.0, 0.161])
    ut = np.zeros((3, 3))
    ut[0, 2] = 0.2
    model = ModalModel(labels=("S-V1", "S-V2", "S-T1"), kinds=("vertical", "vertical", "torsional"),
                       symmetries=("S",) * 3, frequencies_hz=np.array([0.12, 0.2, 0.3]),
                       damping_ratios=np.array([0.005, 0.005, 0.005]), uu=uu, ut=ut, tt=tt,
                       mass_per_length_kg_m=23_000.0, inertia_per_length_kg_m2_m=2.5e6, deck_width_m=31.0,
                       deck_length_m=2694.0)
    det = solve_pair(model.subset([0, 2]), Theodorsen(), RHO, 200.0)
    pk = pk_sweep(model, Theodorsen(), RHO, 200.0, n_speed=50)
    assert det.flutter and pk.flutter and pk.unstable_mode in ("S-V1", "S-T1")
    assert abs(pk.critical_speed_m_s / det.critical_speed_m_s - 1) < 0.005
    # the extra heave mode is only damped by the air (Theodorsen's H1* < 0): above its structural value
    assert np.all(pk.damping_ratio[:, 1] > 0.005)


def test_torsional_divergence_is_reported_apart_from_flutter():
    # Weak coupling: no flutter, but static divergence where (1/2) rho V^2 B^2 (pi/2) a_kk L = J a_kk L w_T^2
    model = ModalModel.from_two_modes(bending_frequency_hz=0.1, torsion_frequency_hz=0.28, a_jj=0.308,
                                      a_kk=0.239, a_jk=0.038, mass_per_length_kg_m=23_000.0,
                                      inertia_per_length_kg_m2_m=2.5e6, deck_width_m=31.0, deck_length_m=2694.0)
    pk = pk_sweep(model, Theodorsen(), RHO, 150.0, n_speed=60)
    w_t = 2 * np.pi * 0.28
    V_d = np.sqrt(2 * 2.5e6 * w_t**2 / (RHO * 31.0**2 * np.pi / 2))
    assert not pk.flutter and np.isnan(pk.critical_speed_m_s)
    assert abs(pk.divergence_speed_m_s / V_d - 1) < 1e-3
    assert not solve_pair(model, Theodorsen(), RHO, 150.0).flutter


@pytest.mark.parametrize("frequencies_hz", [(0.12, 0.2767, 0.2782, 0.2842), (0.09, 0.27, 0.28, 0.285)])
def test_mode_tracking_through_close_frequencies(frequencies_hz):
    # Two uncoupled bending modes just below and above the torsional one (as S-V5, S-T1, SS-V5 of the
    # Great Belt FEM model).  Tracking by nearest eigenvalue follows the wrong branch here (it labelled
    # the first case's flutter mode "V5" and missed flutter in the second); tracking by the modal
    # assurance criterion must find the (V1, T1) determinant speed and name T1.
    uu = np.diag([0.3, 0.3, 0.0, 0.3])
    tt = np.diag([0.0, 0.0, 0.25, 0.0])
    ut = np.zeros((4, 4))
    ut[0, 2] = 0.25
    model = ModalModel(labels=("V1", "V5", "T1", "W5"), kinds=("vertical", "vertical", "torsional", "vertical"),
                       symmetries=("S",) * 4, frequencies_hz=np.array(frequencies_hz),
                       damping_ratios=np.full(4, 0.005), uu=uu, ut=ut, tt=tt, mass_per_length_kg_m=23_000.0,
                       inertia_per_length_kg_m2_m=2.5e6, deck_width_m=31.0, deck_length_m=2694.0)
    det = solve_pair(model.subset([0, 2]), Theodorsen(), RHO, 150.0)
    pk = pk_sweep(model, Theodorsen(), RHO, 150.0, n_speed=60)
    assert det.flutter and pk.flutter and pk.unstable_mode == "T1"
    assert abs(pk.critical_speed_m_s / det.critical_speed_m_s - 1) < 0.005


def test_iterating_one_mode_gives_its_full_call_result_and_no_others():
    """``modes=(r,)`` (used to refine one mode's damping crossing) returns mode r exactly as a call over
    all modes does, and the skipped modes as NaN and flagged, never as a solution."""
    model = ModalModel.from_two_modes(bending_frequency_hz=0.128, torsion_frequency_hz=0.294, a_jj=0.308,
                                      a_kk=0.239, a_jk=0.038, mass_per_length_kg_m=21.5e3,
                                      inertia_per_length_kg_m2_m=2.9e6, deck_width_m=31.0, deck_length_m=2694.0)
    guesses = 1j * model.angular_frequencies
    s_all, phi_all, off_all = aeroelastic_eigenvalues(model, Theodorsen(), RHO, 60.0, guesses, strict=False)
    s_one, phi_one, off_one = aeroelastic_eigenvalues(model, Theodorsen(), RHO, 60.0, guesses, modes=(1,))
    assert s_one[1] == s_all[1] and np.array_equal(phi_one[:, 1], phi_all[:, 1])
    assert not off_one[1] and not off_all[1]
    assert np.isnan(s_one[0]) and np.isnan(phi_one[:, 0]).all() and off_one[0]


def test_static_divergence_of_a_torsional_mode_matches_the_closed_form():
    """Static divergence without relying on p-k branch tracking: for a single torsional mode on a thin plate
    (h_mtheta(0) = pi/2 about mid-chord, Theodorsen 1935) J w_T^2 = (1/2) rho V^2 B^2 pi/2."""
    from bridge.flutter.aerodynamics import Theodorsen
    from bridge.flutter.multimode import static_divergence_speed

    m = ModalModel.from_two_modes(bending_frequency_hz=0.128, torsion_frequency_hz=0.294, a_jj=0.308, a_kk=0.239,
                                  a_jk=0.038, mass_per_length_kg_m=21.5e3, inertia_per_length_kg_m2_m=2.9e6,
                                  deck_width_m=31.0, deck_length_m=2694.0)
    rho, J, w = 1.225, 2.9e6, 2 * np.pi * 0.294
    single = m.subset([1])
    expected = np.sqrt(2 * J * w**2 / (rho * 31.0**2 * np.pi / 2))
    assert static_divergence_speed(single, Theodorsen(), rho, 300.0) == pytest.approx(expected, rel=1e-4)
    # the coupled pair diverges near that speed too, and the sweep reports it with gaps, never as flutter
    r = pk_sweep(m, Theodorsen(), rho, 150.0)
    assert not r.flutter
    assert r.divergence_speed_m_s == pytest.approx(expected, rel=0.02)
    # no two modes may follow one branch
    both = np.isfinite(r.frequency_hz).all(axis=1)
    assert not np.any(np.isclose(r.frequency_hz[both, 0], r.frequency_hz[both, 1], rtol=1e-9))
