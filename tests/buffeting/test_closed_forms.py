"""The buffeting stage's parts against closed forms: one mode in white noise, the coherence double integral,
the spectra's variances and Sears's function.

One mode: a linear oscillator of modal mass m, stiffness k = m w_n^2 and damping ratio zeta under a force of
constant one-sided spectrum S_0 per Hz has the variance

    sigma^2 = int_0^inf S_0 |H(f)|^2 df = pi f_n S_0 / (4 zeta k^2)

exactly (Crandall and Mark 1963, *Random Vibration in Mechanical Systems*, sec. 2.6; the resonant part of
Davenport 1962, Proc. ICE 23: 389-408).  With quasi-steady self-excited forces a vertical mode feels
h_pu = -i Omega (C_L' + C_D), a pure viscous damping (bridge.flutter.aerodynamics.QuasiSteady), so the same
formula holds with zeta + rho V B L uu (C_L' + C_D) / (4 m w_n).  White turbulence with full spanwise
coherence gives the white modal force S_0 = ((1/2) rho V B)^2 [(2 C_L)^2 S_u + (C_L' + C_D)^2 S_w] (int U dx)^2.
"""

import numpy as np
import pytest
from scipy.integrate import quad

from bridge.buffeting.admittance import Admittance, sears_function
from bridge.buffeting.loads import DeckModes, SpanIntegrals, span_integral
from bridge.buffeting.response import buffeting_response, frequency_grid
from bridge.buffeting.wind import KAIMAL_A_U, KAIMAL_A_W, Turbulence, kaimal_spectrum, von_karman_spectrum
from bridge.flutter.aerodynamics import QuasiSteady
from bridge.flutter.modal import ModalModel

L, B, MU, RHO = 1000.0, 30.0, 2.0e4, 1.25
COEFFICIENTS = QuasiSteady(lift_coefficient=0.1, lift_slope_per_rad=5.0, drag_coefficient=0.1,
                           moment_coefficient=0.0, moment_slope_per_rad=1.0)


class WhiteNoise:
    """Constant one-sided spectra of u and w with full spanwise coherence (decays 0)."""

    decay_u = decay_w = 0.0

    def __init__(self, su: float, sw: float):
        self.su, self.sw = su, sw

    def spectra(self, f, speed):
        return np.full(f.shape, self.su), np.full(f.shape, self.sw)


def one_vertical_mode(fn: float, zeta: float) -> tuple[ModalModel, DeckModes]:
    z = np.linspace(0.0, L, 201)
    U = np.sin(np.pi * z / L)[None, :]
    modes = DeckModes(("V1",), z, U, 0 * U, 0 * U, L / 2)
    model = ModalModel(labels=("V1",), kinds=("vertical",), symmetries=("S",), frequencies_hz=[fn],
                       damping_ratios=[zeta], mass_per_length_kg_m=MU, inertia_per_length_kg_m2_m=1e6,
                       deck_width_m=B, deck_length_m=L, **modes.integrals(L))
    return model, modes


@pytest.mark.parametrize("self_excited", [True, False])
def test_one_mode_in_white_noise_has_the_closed_form_variance(self_excited):
    fn, zeta, V, su, sw = 0.2, 0.005, 30.0, 3.0, 2.0
    model, modes = one_vertical_mode(fn, zeta)
    f = frequency_grid(10 * fn, 4001)
    r = buffeting_response(model, modes, COEFFICIENTS, RHO, COEFFICIENTS, WhiteNoise(su, sw), Admittance("none"),
                           [V], f, self_excited=self_excited)
    c = COEFFICIENTS
    s0 = (0.5 * RHO * V * B) ** 2 * ((2 * c.lift_coefficient) ** 2 * su
                                    + (c.lift_slope_per_rad + c.drag_coefficient) ** 2 * sw) * (2 * L / np.pi) ** 2
    m = MU * L / 2
    wn = 2 * np.pi * fn
    total = zeta + (RHO * V * B * L * 0.5 * (c.lift_slope_per_rad + c.drag_coefficient) / (4 * m * wn)
                    if self_excited else 0.0)
    sigma = np.sqrt(np.pi * fn * s0 / (4 * total * (m * wn**2) ** 2))
    assert r.rms_midspan[0, 0] == pytest.approx(sigma, rel=0.01)
    assert r.rms_midspan[0, 0] == pytest.approx(sigma, rel=1e-3)      # what it is: the tail beyond 10 f_n
    assert r.rms_midspan[0, 1] == 0.0 and r.rms_midspan[0, 2] == 0.0
    # the control: the structural damping alone would be far outside the band with the self-excited forces
    if self_excited:
        assert abs(r.rms_midspan[0, 0] / np.sqrt(np.pi * fn * s0 / (4 * zeta * (m * wn**2) ** 2)) - 1) > 0.5


def test_coherence_double_integral_of_a_constant_shape_is_exact():
    # int_0^L int_0^L exp(-a |x - y|) dx dy = 2 L / a - 2 (1 - exp(-a L)) / a^2, for any stations
    z = np.concatenate([[0.0], np.sort(np.random.default_rng(3).uniform(0.0, L, 150)), [L]])
    a = np.array([0.0, 1e-4, 1e-2, 0.3, 5.0])
    J = span_integral(z, np.ones((1, z.size)), a)[:, 0, 0]
    exact = np.where(a > 0, 2 * L / np.where(a > 0, a, 1) - 2 * -np.expm1(-a * L) / np.where(a > 0, a, 1) ** 2, L**2)
    np.testing.assert_allclose(J, exact, rtol=1e-12)
    # lumping the kernel on the nodes (the trapezoidal rule of exp(-a |z_k - z_l|)) is far off at a w > 1
    w = np.gradient(z)
    lumped = w @ np.exp(-5.0 * np.abs(z[:, None] - z[None, :])) @ w
    assert abs(lumped / exact[-1] - 1) > 0.5


def test_tabulated_span_integrals_match_the_direct_sums():
    z = np.linspace(0.0, L, 301)
    psi = np.array([np.sin(n * np.pi * z / L) for n in (1, 2, 3)] + [np.cos(np.pi * z / L)])
    table = SpanIntegrals(z, psi, a_max=1.0)
    a = np.concatenate([[0.0], np.geomspace(1e-6, 1.0, 17), [1.0]])
    direct = span_integral(z, psi, a)
    np.testing.assert_allclose(table(a), direct, rtol=0, atol=1e-6 * np.abs(direct).max())
    np.testing.assert_allclose(direct, np.swapaxes(direct, 1, 2))


@pytest.mark.parametrize("spectrum", ["kaimal", "von_karman"])
def test_spectra_integrate_to_the_variances(spectrum):
    V = 30.0
    t = Turbulence(spectrum=spectrum, intensity_u=0.12, length_scale_u_m=150.0)
    assert t.iw == pytest.approx(0.06) and t.lw == pytest.approx(12.5)
    for k, (sigma, scale) in enumerate(((0.12 * V, 150.0), (0.06 * V, 12.5))):
        var = quad(lambda f, k=k: t.spectra(np.array([f]), V)[k][0], 0.0, np.inf, limit=400)[0]
        assert var == pytest.approx(sigma**2, rel=1e-8 if spectrum == "kaimal" else 2e-3)
        s0 = t.spectra(np.array([0.0]), V)[k][0]
        A = (KAIMAL_A_U, KAIMAL_A_W)[k] if spectrum == "kaimal" else 4.0
        assert s0 == pytest.approx(sigma**2 * A * scale / V, rel=1e-12)
    # the -5/3 law of the inertial subrange: f S(f) ~ f^(-2/3) at high frequency
    f = np.array([100.0, 1000.0])
    for s in (kaimal_spectrum(f, 1.0, 150.0, V, KAIMAL_A_U), von_karman_spectrum(f, 1.0, 150.0, V, "u")):
        assert np.log(s[1] / s[0]) / np.log(10.0) == pytest.approx(-5.0 / 3.0, abs=1e-3)


def test_sears_function_and_liepmanns_approximation():
    assert sears_function(0.0) == pytest.approx(1.0)
    k = 200.0                     # |phi|^2 -> 1 / (2 pi k) far above the gust's chord length
    assert abs(sears_function(k)) ** 2 * 2 * np.pi * k == pytest.approx(1.0, rel=0.01)
    x = np.linspace(0.0, 5.0, 501)                         # f B / V
    exact, liepmann = Admittance("sears").squared_at(x), Admittance("liepmann").squared_at(x)
    assert np.all(np.diff(exact) < 0) and np.max(np.abs(exact - liepmann)) < 0.09
    table = Admittance("table", (0.0, 0.1, 1.0), (1.0, 0.5, 0.1))
    np.testing.assert_allclose(table.squared_at(np.array([0.05, 0.55, 3.0])), [0.75, 0.3, 0.1])
