"""Lateral motion in flutter: the 18-derivative aerodynamics, lateral modal integrals and lateral modes.

Checks (issue: flutter from measured and quasi-steady aerodynamics, lateral motion):
* with every lateral derivative zero, a 3-DOF section (heave, pitch, sway) has the 2-DOF flutter speed;
* quasi-steady heave galloping of a section against Den Hartog's closed form (Den Hartog, *Mechanical
  Vibrations*, 4th ed. 1956, ch. 7, galloping of iced wires: unstable when dC_L/dalpha + C_D < 0, onset
  at U = 4 m zeta w / (rho B |dC_L/dalpha + C_D|));
* a bridge with a lateral-torsional mode against an independent calculation written here: strip loads
  from Theodorsen's lift and moment in physical form (NACA Report 496) and the quasi-steady drag written
  out directly, integrated against mode shapes along the span, and det = 0 solved in (w, V) by fsolve.
"""

import numpy as np
import pytest
from scipy.integrate import simpson
from scipy.optimize import fsolve

from bridge.flutter.aerodynamics import QuasiSteady, Theodorsen, WithLateral, theodorsen_function
from bridge.flutter.derivatives import (
    DERIVATIVE_NAMES,
    LATERAL,
    FlutterDerivatives,
    derivatives_from_frf,
    frf_from_derivatives,
)
from bridge.flutter.determinant import dimensional_matrix, solve_pair
from bridge.flutter.modal import ModalModel
from bridge.flutter.multimode import pk_sweep

RHO = 1.225


def _section(lateral_hz=None, lateral_zeta=0.0):
    return ModalModel.section(mass_per_length_kg_m=25_000.0, inertia_per_length_kg_m2_m=2.8e6,
                              heave_frequency_hz=0.10, pitch_frequency_hz=0.27, deck_width_m=31.0,
                              heave_damping_ratio=0.005, pitch_damping_ratio=0.005,
                              lateral_frequency_hz=lateral_hz, lateral_damping_ratio=lateral_zeta)


def test_eighteen_derivatives_round_trip_and_lateral_block_signs():
    rng = np.random.default_rng(7)
    K = rng.uniform(0.1, 3.0, 11)
    d = FlutterDerivatives(*(rng.normal(size=11) for _ in DERIVATIVE_NAMES))
    back = derivatives_from_frf(K, frf_from_derivatives(K, d))
    for n in DERIVATIVE_NAMES:
        np.testing.assert_allclose(getattr(back, n), getattr(d, n), rtol=1e-13, atol=1e-13, err_msg=n)
    # one term by hand: D = (1/2) rho U^2 B K P1 pdot/U with p = r (both downwind) -> h_qr = i K^2 P1
    only_p1 = FlutterDerivatives(*([0.0] * 8), P1=np.array([2.0]))
    h = frf_from_derivatives(np.array([0.5]), only_p1)
    assert h.h_qr == pytest.approx(0.25j * 2.0) and h.h_pu == 0 and h.h_qu == 0


def test_quasi_steady_lateral_terms_are_the_linearised_relative_wind():
    """Finite-difference the nonlinear quasi-steady forces (relative wind, drag along it, lift across it)
    and compare with the nine FRFs at a low reduced frequency (where udot, rdot are small)."""
    qs = QuasiSteady(lift_coefficient=0.1, lift_slope_per_rad=4.0, drag_coefficient=0.08,
                     moment_coefficient=0.02, moment_slope_per_rad=1.1, drag_slope_per_rad=0.3)
    U = 40.0

    def loads(udot, rdot, theta):   # per (1/2) rho B; p up, q downwind, m nose-up per B
        ur, uv = U - rdot, -udot
        v2, gamma = ur**2 + uv**2, np.arctan2(uv, ur)
        a = theta + gamma
        cl, cd, cm = 0.1 + 4.0 * a, 0.08 + 0.3 * a, 0.02 + 1.1 * a
        lift, drag = v2 * cl, v2 * cd
        return np.array([drag * np.sin(gamma) + lift * np.cos(gamma),
                         drag * np.cos(gamma) - lift * np.sin(gamma), v2 * cm])

    eps = 1e-4
    du = (loads(eps, 0, 0) - loads(-eps, 0, 0)) / (2 * eps)      # d(load)/d(udot)
    dr = (loads(0, eps, 0) - loads(0, -eps, 0)) / (2 * eps)
    dt = (loads(0, 0, eps) - loads(0, 0, -eps)) / (2 * eps)
    # p = (1/2) rho U^2 h_pu u with udot = i w u: h_pu / (i Omega) = (d load / d udot) / U (loads per
    # (1/2) rho B; the moment per (1/2) rho B^2), and h_ptheta = (d load / d theta) / U^2
    Om = 0.3
    h = qs.frf(Om, U)
    np.testing.assert_allclose(np.array([h.h_pu, h.h_qu, h.h_mu]) / (1j * Om), du / U, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(np.array([h.h_pr, h.h_qr, h.h_mr]) / (1j * Om), dr / U, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(np.array([h.h_ptheta, h.h_qtheta, h.h_mtheta]), dt / U**2, rtol=1e-6)


def test_three_dof_section_without_lateral_aerodynamics_has_the_two_dof_speed():
    two = solve_pair(_section(), Theodorsen(), RHO, 150.0)
    three = solve_pair(_section(lateral_hz=0.06, lateral_zeta=0.01), Theodorsen(), RHO, 150.0)
    assert two.flutter and three.flutter
    assert three.critical_speed_m_s == pytest.approx(two.critical_speed_m_s, rel=1e-10)
    assert three.frequency_hz == pytest.approx(two.frequency_hz, rel=1e-10)
    # and through the p-k sweep with the sway mode included
    pk = pk_sweep(_section(lateral_hz=0.06, lateral_zeta=0.01), Theodorsen(), RHO, 150.0, lateral=True)
    assert pk.critical_speed_m_s == pytest.approx(two.critical_speed_m_s, rel=1e-7)


@pytest.mark.parametrize("zeta", [0.005, 0.02])
def test_heave_galloping_of_a_section_is_den_hartogs(zeta):
    """A section free in heave and sway (no pitch), quasi-steady with dC_L/dalpha + C_D < 0 and C_L = 0:
    the lateral motion feels drag but does not feed the lift (h_pr = 0), so the onset is Den Hartog's."""
    m, f_h, B = 20_000.0, 0.15, 20.0
    dcl, cd = -3.0, 0.9
    qs = QuasiSteady(lift_coefficient=0.0, lift_slope_per_rad=dcl, drag_coefficient=cd,
                     moment_coefficient=0.0, moment_slope_per_rad=0.0, drag_slope_per_rad=0.4)
    model = ModalModel(labels=("heave", "sway"), kinds=("vertical", "lateral"), symmetries=("S", "S"),
                       frequencies_hz=np.array([f_h, 0.05]), damping_ratios=np.array([zeta, 0.01]),
                       uu=np.diag([1.0, 0.0]), ut=np.zeros((2, 2)), tt=np.zeros((2, 2)),
                       rr=np.diag([0.0, 1.0]), ur=np.array([[0.0, 1.0], [0.0, 0.0]]), rt=np.zeros((2, 2)),
                       mass_per_length_kg_m=m, inertia_per_length_kg_m2_m=1.0, deck_width_m=B, deck_length_m=1.0)
    den_hartog = 4.0 * m * zeta * 2 * np.pi * f_h / (RHO * B * abs(dcl + cd))
    r = solve_pair(model, qs, RHO, 3 * den_hartog)
    assert r.flutter
    assert r.critical_speed_m_s == pytest.approx(den_hartog, rel=1e-8)
    assert r.frequency_hz == pytest.approx(f_h, rel=1e-8)
    pk = pk_sweep(model, qs, RHO, 3 * den_hartog, lateral=True)
    assert pk.unstable_mode == "heave" and pk.critical_speed_m_s == pytest.approx(den_hartog, rel=1e-6)
    # control: a stable slope (dC_L/dalpha + C_D > 0) never gallops
    stable = QuasiSteady(lift_coefficient=0.0, lift_slope_per_rad=3.0, drag_coefficient=cd,
                         moment_coefficient=0.0, moment_slope_per_rad=0.0)
    assert not solve_pair(model, stable, RHO, 3 * den_hartog).flutter


# ------------------------------------------------------------------ a bridge with a lateral-torsional mode
L_SPAN, B_DECK, MU, J = 1600.0, 30.0, 20_000.0, 2.5e6


def _shapes(z):
    """Three modes on a simply supported span: vertical U1, a torsional mode with a lateral part (the
    cable pendulum: R in m per rad of Theta), and a lateral mode with a little torsion."""
    s1, s2 = np.sin(np.pi * z / L_SPAN), np.sin(np.pi * z / L_SPAN)
    U = np.array([s1, 0 * z, 0 * z])
    R = np.array([0 * z, 2.0 * s2, s1])            # torsional mode sways 2 m per rad; lateral mode max 1
    T = np.array([0 * z, s2, -0.05 * s1])
    return U, R, T


def _project_model(freqs, zetas):
    z = np.linspace(0.0, L_SPAN, 2001)
    U, R, T = _shapes(z)
    w = np.full(z.size, z[1] - z[0])
    w[[0, -1]] *= 0.5

    def integ(a, b):
        return (a * w) @ b.T / L_SPAN

    return ModalModel(labels=("S-V1", "S-T1", "S-L1"), kinds=("vertical", "torsional", "lateral"),
                      symmetries=("S", "S", "S"), frequencies_hz=np.array(freqs), damping_ratios=np.array(zetas),
                      uu=integ(U, U), ut=integ(U, T), tt=integ(T, T), rr=integ(R, R), ur=integ(U, R),
                      rt=integ(R, T), mass_per_length_kg_m=MU, inertia_per_length_kg_m2_m=J,
                      deck_width_m=B_DECK, deck_length_m=L_SPAN)


def _independent_impedance(w, V, freqs, zetas, cl, dcl, cd, dcd, cm):
    """A_s - A_a in physical units, built without the project's FRFs or modal integrals: Theodorsen's
    lift and moment (h down, alpha nose-up, about mid-chord) plus quasi-steady drag, per unit length, for
    harmonic motion of each mode, integrated along the span by Simpson's rule against each mode."""
    z = np.linspace(0.0, L_SPAN, 801)
    U, R, T = _shapes(z)
    b = B_DECK / 2
    k = w * b / V
    C = complex(theodorsen_function(np.array([k]))[0])
    n = 3
    A = np.zeros((n, n), dtype=complex)
    for j in range(n):               # mode j moving with unit amplitude e^{i w t}
        h, a, r = -U[j], T[j], R[j]   # h down = -u
        hd, hdd, ad, add, rd = 1j * w * h, -w**2 * h, 1j * w * a, -w**2 * a, 1j * w * r
        circ = 2 * np.pi * RHO * V * b * C * (hd + V * a + 0.5 * b * ad)
        lift_up = np.pi * RHO * b**2 * (hdd + V * ad) + circ                              # Theodorsen, a = 0
        moment = np.pi * RHO * b**2 * (-0.5 * V * b * ad - b**2 / 8 * add) + b * 0.5 * circ   # nose-up
        # lateral terms written from the relative wind (U - rdot, -udot), drag along it, lift across it
        udot = -hd
        q = 0.5 * RHO * V**2 * B_DECK * (dcd * a + (cl - dcd) * udot / V - 2 * cd * rd / V)
        lift_up = lift_up + 0.5 * RHO * V**2 * B_DECK * (-2 * cl * rd / V)
        moment = moment + 0.5 * RHO * V**2 * B_DECK**2 * (-2 * cm * rd / V)
        for i in range(n):
            A[i, j] = simpson(lift_up * U[i] + q * R[i] + moment * T[i], x=z)
    # modal masses from the shapes (mu for both translations, J for rotation)
    m = np.array([simpson(MU * (U[i] ** 2 + R[i] ** 2) + J * T[i] ** 2, x=z) for i in range(n)])
    wi = 2 * np.pi * np.array(freqs)
    return np.diag(m * (wi**2 - w**2 + 2j * np.array(zetas) * wi * w)) - A


def test_bridge_with_a_lateral_torsional_mode_matches_an_independent_calculation():
    freqs, zetas = [0.10, 0.28, 0.06], [0.005, 0.003, 0.01]
    coeffs = dict(cl=0.05, dcl=5.0, cd=0.08, dcd=0.25, cm=0.01)
    qs = QuasiSteady(lift_coefficient=coeffs["cl"], lift_slope_per_rad=coeffs["dcl"],
                     drag_coefficient=coeffs["cd"], moment_coefficient=coeffs["cm"],
                     moment_slope_per_rad=1.2, drag_slope_per_rad=coeffs["dcd"])
    aero = WithLateral(Theodorsen(), qs)
    assert aero.filled == LATERAL
    model = _project_model(freqs, zetas)
    ours = solve_pair(model, aero, RHO, 200.0)
    assert ours.flutter

    # the project's physical matrix equals the independent one at an arbitrary point (to quadrature)
    w_test, V_test = 1.3, 55.0
    ref = _independent_impedance(w_test, V_test, freqs, zetas, **coeffs)
    np.testing.assert_allclose(dimensional_matrix(model, aero, RHO, w_test, V_test), ref,
                               rtol=1e-6, atol=1e-6 * np.abs(ref).max())

    def f(x):
        d = np.linalg.det(_independent_impedance(x[0], x[1], freqs, zetas, **coeffs))
        d /= abs(np.linalg.det(_independent_impedance(x[0], x[1], freqs, zetas, 0, 0, 0, 0, 0))) + 1e-300
        return [d.real, d.imag]

    w0 = 2 * np.pi * ours.frequency_hz * 1.02
    (w_c, V_c), info, ok, msg = fsolve(f, [w0, ours.critical_speed_m_s * 0.97], full_output=True, xtol=1e-12)
    assert ok == 1, msg
    assert V_c == pytest.approx(ours.critical_speed_m_s, rel=1e-6)
    assert w_c / (2 * np.pi) == pytest.approx(ours.frequency_hz, rel=1e-6)
    # the lateral part matters here: without the lateral terms the speed differs
    plain = solve_pair(model, Theodorsen(), RHO, 200.0)
    assert abs(plain.critical_speed_m_s / ours.critical_speed_m_s - 1) > 1e-3


def test_modal_scenarios_take_generalised_masses_directly(tmp_path):
    """kind = "modal" with the modal masses a modal test reports: the two-mode form and the full form give
    the flutter speed of the same model built from mu, J and the integrals (Eq 4.33) when the masses
    agree, and a different one when they do not."""
    from bridge.config import load_scenario
    from bridge.errors import InputError

    base = dict(bending_frequency_hz=0.1, torsion_frequency_hz=0.28, a_jj=0.308, a_kk=0.239, a_jk=0.2,
                mass_per_length_kg_m=23_000.0, inertia_per_length_kg_m2_m=2.5e6, deck_width_m=31.0,
                deck_length_m=2694.0, bending_damping_ratio=0.005, torsion_damping_ratio=0.003)
    eq_4_33 = ModalModel.from_mapping(base)
    m_j, m_k = eq_4_33.modal_masses
    given = ModalModel.from_mapping({**base, "bending_modal_mass_kg": m_j, "torsion_modal_mass_kg_m2": m_k})
    heavier = ModalModel.from_mapping({**base, "bending_modal_mass_kg": m_j, "torsion_modal_mass_kg_m2": 2 * m_k})
    v = [solve_pair(m, Theodorsen(), RHO, 300.0).critical_speed_m_s for m in (eq_4_33, given, heavier)]
    assert v[1] == pytest.approx(v[0], rel=1e-12) and v[2] > 1.1 * v[0]
    with pytest.raises(InputError, match="torsion_modal_mass_kg_m2"):
        ModalModel.from_mapping({**base, "bending_modal_mass_kg": m_j})
    # the full form, read from a scenario file, with generalised_masses and lateral integrals
    f = tmp_path / "tested_modes.toml"
    f.write_text('kind = "modal"\n[modal]\nlabels = ["S-V1", "S-T1"]\nkinds = ["vertical", "torsional"]\n'
                 'symmetries = ["S", "S"]\nfrequencies_hz = [0.1, 0.28]\ndamping_ratios = [0.005, 0.003]\n'
                 'uu = [[0.308, 0.0], [0.0, 0.0]]\nut = [[0.0, 0.2], [0.0, 0.0]]\ntt = [[0.0, 0.0], [0.0, 0.239]]\n'
                 'rr = [[0.0, 0.0], [0.0, 0.0]]\n'
                 f'generalised_masses = [{float(m_j)!r}, {float(2 * m_k)!r}]\nmass_per_length_kg_m = 23000.0\n'
                 'inertia_per_length_kg_m2_m = 2.5e6\ndeck_width_m = 31.0\ndeck_length_m = 2694.0\n')
    sc = load_scenario(f)
    assert solve_pair(sc.modal, Theodorsen(), RHO, 300.0).critical_speed_m_s == pytest.approx(v[2], rel=1e-12)
