"""Frequency response functions from forced-motion records (bridge/aero/frequency_response.py, issue 16,
"Extraction"; docs/aero.md).

Synthetic records with known amplitudes and phases: uneven time steps (the CFD's dt varies), white
noise, a slow drift, several frequencies.  References: the thesis, Eq 5.3-5.14 with its errata
(docs/thesis_errata.md: Eq 5.4 means H_pu = i w H_pudot; the arccos of Eq 5.12 loses the sign of the
phase); Theodorsen (1935), NACA Report 496, as bridge.flutter.aerodynamics.Theodorsen gives it; the
quasi-steady lateral FRFs of bridge.flutter.aerodynamics.QuasiSteady.
"""

import numpy as np
import pytest

from bridge.aero import (
    FrequencyResponse,
    displacement_frf,
    distortion,
    forced_motion_response,
    frf_table,
    harmonic_fit,
    normalised_frf,
    rate_frf,
    speed_independent_table,
    tabulate,
    thesis_extraction,
)
from bridge.errors import InputError
from bridge.flutter.aerodynamics import QuasiSteady, Theodorsen
from bridge.flutter.derivatives import FRF, FRF_NAMES, derivatives_from_frf

RHO, V, B = 1.225, 50.0, 31.0            # thesis 5.2.4, 5.3; B of the Great Belt deck
W = 0.8                                  # rad/s (Omega = W B / V ~ 0.5, thesis 5.3)
T = 2 * np.pi / W
X = 1.3 * np.exp(-0.7j)                  # the amplitude to recover


def uneven_times(rng, n_periods: float, per_period: int = 200, period: float = T) -> np.ndarray:
    """Sample times over n_periods with steps varying by a factor of about 4 (smooth plus random)."""
    n = int(1.5 * n_periods * per_period)
    steps = period / per_period * (1.0 + 0.6 * np.sin(0.37 * np.arange(n)) + 0.5 * rng.random(n))
    t = np.cumsum(steps)
    return t[t <= n_periods * period]


def harmonic(amplitude, omega, t):
    return np.real(amplitude * np.exp(1j * omega * t))


# --- harmonic fit -----------------------------------------------------------------------------------


def test_fit_recovers_the_amplitude_under_noise_and_a_slow_drift():
    rng = np.random.default_rng(1)
    t = uneven_times(rng, 10.4)
    sigma = 0.1 * abs(X)
    drift = 0.04 * t + 0.2 * np.sin(2 * np.pi * t / (50 * T))          # linear + slow (5 windows long)
    y = 0.5 + harmonic(X, W, t) + drift + sigma * rng.standard_normal(t.size)
    fit = harmonic_fit(t, y, W)
    assert fit.periods == 10
    n = np.count_nonzero(t >= fit.window[0])
    # white noise: var(Re X) + var(Im X) = 4 sigma^2 / N for N samples; 4 of those standard deviations
    tolerance = 4 * sigma * np.sqrt(4 / n)
    assert abs(fit.amplitudes[0] - X) < tolerance
    assert abs(fit.amplitudes[0] - X) < 4 * abs(fit.stderr[0])
    # control: without the drift term the linear drift biases the sine part by c_1 T / pi (docs/aero.md)
    no_drift = harmonic_fit(t, y, W, drift=False)
    assert abs(no_drift.amplitudes[0] - X) > 2 * tolerance
    assert abs(no_drift.amplitudes[0].imag - X.imag) == pytest.approx(0.04 * T / np.pi, rel=0.25)


def test_the_drift_does_not_amplify_noise_on_short_windows():
    """Regression: the drift was a column of the fit, and over one period t - t_mid is correlated 0.78 with
    the sine, so noise went into the sine part 1.6 times amplified (a CFD record fitted over one period
    came out 17 % low).  Now the drift is the line through the period means: one period gets none, and
    over two the estimate scatters like the fit without a drift term."""
    W_, T_ = 1.5, 2 * np.pi / 1.5
    for periods, worst in ((1, 1.0 + 1e-12), (2, 1.25)):
        with_drift, without = [], []
        for seed in range(200):
            rng = np.random.default_rng(seed)
            t = np.sort(rng.uniform(0.0, periods * T_, 60 * periods))
            t = np.concatenate(([0.0], t, [periods * T_]))
            y = np.sin(W_ * t) + 0.2 * rng.standard_normal(t.size)
            with_drift.append(harmonic_fit(t, y, W_).amplitudes[0])
            without.append(harmonic_fit(t, y, W_, drift=False).amplitudes[0])
        spread = [np.sqrt(np.mean(np.abs(np.array(e) + 1j) ** 2)) for e in (with_drift, without)]
        assert spread[0] <= worst * spread[1], (periods, spread)


def test_the_forced_motion_window_holds_every_period_after_the_discarded_ones():
    """Regression: the mask started after the first sample of the window and ended before the run's last
    one, so the fit often lost a period (the standard preset fitted 1 of its 2).  Records end as run_case
    ends them: at the first step at or past the end time; 100 of them with random uneven steps."""
    from bridge.aero.forced_motion import ForcedCase, ForceRecord, whole_periods
    from bridge.aero.presets import QUALITY

    for name in ("standard", "tiny"):
        q = QUALITY[name]
        case = ForcedCase.thesis("pitch", 0.785)
        fitted = q.run.periods - q.run.discard_periods
        for seed in range(100):
            t = np.cumsum(np.random.default_rng(seed).uniform(0.005, 0.015, 8000))
            t = t[: int(np.searchsorted(t, case.end_time(q))) + 1]
            rec = ForceRecord(t=t, lift=np.sin(0.785 * t), drag=0 * t, moment=0 * t, motion=np.sin(0.785 * t))
            sel = whole_periods(rec, case, q)
            assert harmonic_fit(t[sel], rec.lift[sel], 0.785).periods == fitted, (name, seed)


def test_reported_standard_error_matches_the_scatter_over_200_seeds():
    sigma = 0.2
    estimates, errors = [], []
    for seed in range(200):
        rng = np.random.default_rng(seed)
        t = uneven_times(rng, 10.3)
        y = 0.5 + 0.03 * t + harmonic(X, W, t) + sigma * rng.standard_normal(t.size)
        fit = harmonic_fit(t, y, W)
        estimates.append(fit.amplitudes[0])
        errors.append(fit.stderr[0])
    err, se = np.array(estimates) - X, np.array(errors)
    for part in (np.real, np.imag):
        assert np.mean(np.abs(part(err)) < 3 * part(se)) >= 0.95
        assert np.std(part(err)) == pytest.approx(np.mean(part(se)), rel=0.3)
    # and both near the white-noise value sqrt(2 / N) sigma per part (N ~ 1740 samples in the window)
    assert np.mean(se.real) == pytest.approx(sigma * np.sqrt(2 / 1740), rel=0.3)


@pytest.mark.parametrize("multiples, fundamental", [((1, 2, 3), None), ((2, 3, 5), W)])
def test_three_sines_are_recovered_term_by_term(multiples, fundamental):
    rng = np.random.default_rng(7)
    omegas = W * np.array(multiples, dtype=float)
    amplitudes = np.array([1.0, 0.6, 0.3]) * np.exp(1j * np.radians([-40.0, 75.0, 160.0]))
    t = uneven_times(rng, 8.6, per_period=400)
    clean = 2.0 + sum(harmonic(a, w, t) for a, w in zip(amplitudes, omegas, strict=True))
    fit = harmonic_fit(t, clean, omegas, fundamental=fundamental)
    assert fit.periods == 8
    np.testing.assert_allclose(fit.amplitudes, amplitudes, rtol=0, atol=1e-10)
    sigma = 0.1
    noisy = harmonic_fit(t, clean + sigma * rng.standard_normal(t.size), omegas, fundamental=fundamental)
    n = np.count_nonzero(t >= noisy.window[0])
    assert np.all(np.abs(noisy.amplitudes - amplitudes) < 4 * sigma * np.sqrt(4 / n))
    assert np.all(np.abs(noisy.amplitudes - amplitudes) < 4 * np.abs(noisy.stderr))


@pytest.mark.parametrize("eps", [0.0, 0.05, 0.2])
def test_the_distortion_of_a_quadratic_response_to_two_sines_is_the_closed_form(eps):
    """x = sin(w0 t) + sin(2 w0 t), load y = x + eps x^2: x^2 = 1 - cos(2a)/2 - cos(4a)/2 + cos(a) - cos(3a)
    (a = w0 t), so the moved lines carry amplitudes sqrt(1 + eps^2) and sqrt(1 + eps^2/4), the others (3 and 4
    w0) eps and eps/2: distortion = eps sqrt(5/8) / sqrt(1 + 5 eps^2/8).  Uneven steps, four periods."""
    rng = np.random.default_rng(3)
    t = uneven_times(rng, 4.3)
    x = np.sin(W * t) + np.sin(2 * W * t)
    got = distortion(t, x + eps * x**2, [W, 2 * W], W)
    expected = eps * np.sqrt(5 / 8) / np.sqrt(1 + 5 * eps**2 / 8)
    assert got == pytest.approx(expected, rel=1e-3, abs=1e-6)


def test_frequencies_that_are_not_multiples_of_the_fundamental_are_refused():
    t = np.linspace(0.0, 10 * T, 2001)
    with pytest.raises(InputError, match="whole multiples"):
        harmonic_fit(t, np.sin(W * t), [W, 1.5 * W])
    fit = harmonic_fit(t, np.sin(W * t) + np.sin(1.5 * W * t), [W, 1.5 * W], fundamental=0.5 * W)
    assert fit.periods == 5
    np.testing.assert_allclose(fit.amplitudes, [-1j, -1j], atol=1e-10)


def test_only_whole_periods_at_the_end_of_the_window_are_used():
    rng = np.random.default_rng(3)
    t = uneven_times(rng, 7.4)
    start = t[-1] - 7 * T
    # a transient that ends two samples before the last 7 whole periods begin
    transient = np.where(t < t[np.searchsorted(t, start) - 2], 50.0 * np.exp(-t), 0.0)
    fit = harmonic_fit(t, harmonic(X, W, t) + transient, W)
    assert fit.periods == 7
    assert fit.window == pytest.approx((start, t[-1]), abs=1e-12)
    assert abs(fit.amplitudes[0] - X) < 1e-12
    assert harmonic_fit(t, harmonic(X, W, t), W, periods=3).periods == 3
    with pytest.raises(InputError, match="periods"):
        harmonic_fit(t, harmonic(X, W, t), W, periods=8)
    with pytest.raises(InputError, match="at least one period"):
        harmonic_fit(t[t < 0.9 * T], harmonic(X, W, t[t < 0.9 * T]), W)


def test_an_unmodelled_harmonic_does_not_leak_when_the_steps_follow_the_motion():
    """The CFD's dt follows the body's speed: steps that vary at 2 w.  The quadrature weights keep the
    fit orthogonal to 3 w; an unweighted least-squares fit (the control) is not."""
    t = [0.0]
    while t[-1] < 8.3 * T:
        t.append(t[-1] + T / 150 * (1.0 + 0.8 * np.cos(2 * W * t[-1] + 0.4)))
    t = np.array(t)
    y = harmonic(X, W, t) + 0.5 * np.cos(3 * W * t + 1.0)
    fit = harmonic_fit(t, y, W)
    assert abs(fit.amplitudes[0] - X) < 5e-3
    m = t >= fit.window[0]
    design = np.stack([np.ones(m.sum()), t[m] - t[m].mean(), np.cos(W * t[m]), np.sin(W * t[m])], axis=1)
    a, b = np.linalg.lstsq(design, y[m], rcond=None)[0][2:]
    assert abs(a - 1j * b - X) > 0.05


# --- the thesis's extraction (Eq 5.9-5.14) ---------------------------------------------------------


@pytest.mark.parametrize("psi", [0.0, 0.9])
@pytest.mark.parametrize("phase_deg", [40.0, -40.0])
def test_thesis_extraction_keeps_the_sign_the_arccos_loses(phase_deg, psi):
    """Load Pi = |H| cos(w t - psi - phi) against the motion rate udot_0 cos(w t - psi): phase lag phi."""
    rng = np.random.default_rng(11)
    t = uneven_times(rng, 6.7, per_period=300)
    phi, H, udot0 = np.radians(phase_deg), 4.1e3, 0.4
    rate = udot0 * np.cos(W * t - psi)
    load = 250.0 + udot0 * H * np.cos(W * t - psi - phi)
    out = thesis_extraction(t, load, rate, W, norm=udot0)
    true = H * np.exp(-1j * phi)                                        # Eq 5.5
    assert out.periods == 6
    assert out.mean == pytest.approx(250.0, rel=1e-6)
    assert out.phase == pytest.approx(phi, abs=1e-5)                    # signed
    assert out.phase_thesis == pytest.approx(abs(phi), abs=1e-5)        # arccos: unsigned
    assert out.frf == pytest.approx(true, rel=1e-5)
    if phi > 0:
        assert out.frf_thesis == pytest.approx(true, rel=1e-5)
    else:                                                                # the thesis gets the conjugate
        assert out.frf_thesis == pytest.approx(np.conj(true), rel=1e-5)
        assert abs(out.frf_thesis - true) == pytest.approx(2 * H * np.sin(abs(phi)), rel=1e-5)
    # agrees with the harmonic fit: H_udot = P_0 / Udot_0 (amplitude and |phase|)
    fit_h = harmonic_fit(t, load, W).amplitudes[0] / harmonic_fit(t, rate, W).amplitudes[0]
    assert out.amplitude == pytest.approx(abs(fit_h), rel=1e-5)
    assert out.phase_thesis == pytest.approx(abs(-np.angle(fit_h)), abs=1e-5)
    assert out.phase == pytest.approx(-np.angle(fit_h), abs=1e-5)
    # norm defaults to the motion rate's amplitude
    assert thesis_extraction(t, load, rate, W).frf == pytest.approx(out.frf, rel=1e-5)


def test_the_rms_amplitude_of_eq_5_13_holds_the_power_of_other_harmonics():
    t = np.linspace(0.0, 6 * T, 3601)
    load = np.cos(W * t - 0.3) + 0.3 * np.cos(3 * W * t)
    rate = np.cos(W * t)
    assert thesis_extraction(t, load, rate, W, norm=1.0).amplitude == pytest.approx(np.sqrt(1 + 0.3**2), rel=1e-6)
    fit = harmonic_fit(t, load, [W])
    assert abs(fit.amplitudes[0]) == pytest.approx(1.0, rel=1e-9)


# --- conversions: Eq 5.3-5.8 and 4.37 --------------------------------------------------------------


def test_eq_5_4_as_corrected_h_pu_is_i_w_h_pudot():
    P0, U0, w = 3.0 - 2.0j, 0.2 * np.exp(0.4j), 0.8
    H_rate = rate_frf(P0, U0, w)                                        # Eq 5.3: p_0 / udot_0
    assert H_rate == pytest.approx(P0 / (1j * w * U0), rel=1e-14)
    H = displacement_frf(H_rate, w)
    assert H == pytest.approx(P0 / U0, rel=1e-14)                       # p_0 = H_pu u_0
    assert abs(H) == pytest.approx(w * abs(H_rate), rel=1e-14)          # Eq 5.7
    phi_rate, phi = -np.angle(H_rate), -np.angle(H)                     # phase lags, Eq 5.5-5.6
    assert np.angle(np.exp(1j * (phi - (phi_rate - np.pi / 2)))) == pytest.approx(0.0, abs=1e-14)
    # misreadings of the printed "H_pu = i w H_pu": none gives p_0 / u_0
    for wrong in (H_rate, H_rate / (1j * w), -1j * w * H_rate):
        assert abs(wrong - P0 / U0) > 0.1 * abs(P0 / U0)


def test_normalisation_of_eq_4_37():
    q = 0.5 * RHO * V**2
    assert normalised_frf(q, "lift", "heave", V, B, RHO) == pytest.approx(1.0)
    assert normalised_frf(q * B, "lift", "pitch", V, B, RHO) == pytest.approx(1.0)
    assert normalised_frf(q * B, "moment", "heave", V, B, RHO) == pytest.approx(1.0)
    assert normalised_frf(q * B**2, "moment", "pitch", V, B, RHO) == pytest.approx(1.0)
    assert normalised_frf(q, "drag", "sway", V, B, RHO) == pytest.approx(1.0)
    with pytest.raises(InputError, match="dof"):
        normalised_frf(q, "lift", "roll", V, B, RHO)


def theodorsen_runs(omega_reduced, speed, rng, noise=0.0, drag_model=None):
    """A heave and a pitch record of Theodorsen's thin plate (thesis velocity amplitudes 0.4 m/s and
    0.028 rad/s, motion x_0 sin w t), loads from Eq 4.37; optional quasi-steady drag."""
    w = omega_reduced * speed / B
    period = 2 * np.pi / w
    h = Theodorsen().frf(omega_reduced, speed)
    qs = drag_model.frf(omega_reduced, speed) if drag_model is not None else None
    q = 0.5 * RHO * speed**2
    t = uneven_times(rng, 6.5, per_period=300, period=period)
    e = np.exp(1j * w * t)
    runs = []
    for dof, x0, lift, moment, drag in (
            ("heave", -1j * 0.4 / w, q * h.h_pu, q * B * h.h_mu, None if qs is None else q * qs.h_qu),
            ("pitch", -1j * 0.028 / w, q * B * h.h_ptheta, q * B**2 * h.h_mtheta,
             None if qs is None else q * B * qs.h_qtheta)):
        loads = {"lift": 3e3 + np.real(lift * x0 * e), "moment": -1e4 + np.real(moment * x0 * e)}
        if drag is not None:
            loads["drag"] = 2e3 + np.real(drag * x0 * e)
        if noise:
            loads = {k: v + noise * np.std(v) * rng.standard_normal(t.size) for k, v in loads.items()}
        runs.append(forced_motion_response(t, np.real(x0 * e), w, dof=dof, speed_m_s=speed, deck_width_m=B,
                                           air_density_kg_m3=RHO, **loads)[0])
    return runs


@pytest.mark.parametrize("omega_reduced", [0.5, 1.6])
def test_theodorsen_round_trip_to_h_xy_and_scanlan_derivatives(omega_reduced):
    heave, pitch = theodorsen_runs(omega_reduced, V, np.random.default_rng(5))
    h = Theodorsen().frf(omega_reduced, V)
    assert heave.reduced_frequency == pytest.approx(omega_reduced, rel=1e-12)
    assert heave.provides == ("h_pu", "h_mu") and pitch.provides == ("h_ptheta", "h_mtheta")
    for r in (heave, pitch):
        for n in r.provides:
            assert abs(getattr(r.frf, n) / getattr(h, n) - 1) < 1e-6
    # Scanlan's derivatives (H1*..H4*, A1*..A4*) of the merged runs
    merged = FRF(h_pu=heave.frf.h_pu, h_mu=heave.frf.h_mu, h_ptheta=pitch.frf.h_ptheta, h_mtheta=pitch.frf.h_mtheta)
    got, want = derivatives_from_frf(omega_reduced, merged), derivatives_from_frf(omega_reduced, h)
    for name in ("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4"):
        assert getattr(got, name) == pytest.approx(getattr(want, name), rel=1e-6, abs=1e-9)
    assert heave.derivatives.H1 == pytest.approx(want.H1, rel=1e-6)
    assert pitch.derivatives.A2 == pytest.approx(want.A2, rel=1e-6)
    # the dimensional FRFs: H_pu = p_0 / u_0 = i w H_pudot (Eq 5.4 corrected)
    w = heave.angular_frequency
    assert heave.dimensional()["h_pu"] == pytest.approx(1j * w * heave.rate()["h_pu"], rel=1e-12)
    assert heave.dimensional()["h_pu"] == pytest.approx(0.5 * RHO * V**2 * h.h_pu, rel=1e-6)
    # control: Eq 5.4 misread as H_pu = H_pudot does not give Theodorsen's h_pu back
    misread = normalised_frf(heave.rate()["h_pu"], "lift", "heave", V, B, RHO)
    assert abs(misread / h.h_pu - 1) > 0.1


def test_the_thesis_path_gives_theodorsen_too():
    omega_reduced = 0.5
    w = omega_reduced * V / B
    h = Theodorsen().frf(omega_reduced, V)
    t = uneven_times(np.random.default_rng(2), 6.5, per_period=300, period=2 * np.pi / w)
    u0 = -1j * 0.4 / w
    udot = np.real(1j * w * u0 * np.exp(1j * w * t))
    p = 3e3 + np.real(0.5 * RHO * V**2 * h.h_pu * u0 * np.exp(1j * w * t))
    out = thesis_extraction(t, p, udot, w, norm=0.4)
    assert out.amplitude == pytest.approx(4.15e3, rel=0.01)          # ~4.1e3 N s/m^2 (docs/thesis_errata.md)
    h_pu = normalised_frf(displacement_frf(out.frf, w), "lift", "heave", V, B, RHO)
    assert abs(h_pu / h.h_pu - 1) < 1e-5
    # the plate's lift leads the heave velocity (phi ~ -175 deg): the arccos value is far off
    h_thesis = normalised_frf(displacement_frf(out.frf_thesis, w), "lift", "heave", V, B, RHO)
    assert out.phase < 0 and abs(h_thesis / h.h_pu - 1) > 0.1


def test_lateral_frfs_from_a_drag_record_and_a_sway_run():
    qs = QuasiSteady(lift_coefficient=0.1, lift_slope_per_rad=5.0, drag_coefficient=0.08,
                     moment_coefficient=0.02, moment_slope_per_rad=1.2, drag_slope_per_rad=0.3)
    Om = 0.8
    heave, pitch = theodorsen_runs(Om, V, np.random.default_rng(8), drag_model=qs)
    want = qs.frf(Om, V)
    assert heave.provides == ("h_pu", "h_mu", "h_qu") and pitch.provides == ("h_ptheta", "h_mtheta", "h_qtheta")
    assert abs(heave.frf.h_qu / want.h_qu - 1) < 1e-6
    assert abs(pitch.frf.h_qtheta / want.h_qtheta - 1) < 1e-6
    # a sway run measures h_pr, h_qr, h_mr
    w = Om * V / B
    t = np.linspace(0.0, 5 * 2 * np.pi / w, 2501)
    r0, e, q = 0.3, np.exp(1j * w * t), 0.5 * RHO * V**2
    sway, = forced_motion_response(t, np.real(r0 * e), w, dof="sway", speed_m_s=V, deck_width_m=B,
                                   air_density_kg_m3=RHO, lift=np.real(q * want.h_pr * r0 * e),
                                   drag=600.0 + np.real(q * want.h_qr * r0 * e),
                                   moment=np.real(q * B * want.h_mr * r0 * e))
    assert sway.provides == ("h_pr", "h_qr", "h_mr")
    for n in sway.provides:
        assert abs(getattr(sway.frf, n) / getattr(want, n) - 1) < 1e-6
    d = derivatives_from_frf(Om, want)
    assert sway.derivatives.P1 == pytest.approx(d.P1, rel=1e-6)
    assert heave.derivatives.P5 == pytest.approx(d.P5, rel=1e-6)


def test_standard_errors_of_h_and_of_the_derivatives():
    heave, pitch = theodorsen_runs(0.5, V, np.random.default_rng(9), noise=0.05)
    h = Theodorsen().frf(0.5, V)
    K2 = 0.25
    for r in (heave, pitch):
        for n in r.provides:
            se = getattr(r.stderr, n)
            assert se.real > 0 and se.imag > 0
            err = getattr(r.frf, n) - getattr(h, n)
            assert abs(err.real) < 4 * se.real and abs(err.imag) < 4 * se.imag
    assert heave.derivative_stderr.H1 == pytest.approx(heave.stderr.h_pu.imag / K2, rel=1e-12)
    assert heave.derivative_stderr.H4 == pytest.approx(heave.stderr.h_pu.real / K2, rel=1e-12)
    assert pitch.derivative_stderr.A2 == pytest.approx(pitch.stderr.h_mtheta.imag / K2, rel=1e-12)
    assert heave.derivative_stderr.A2 == 0.0                              # not measured by a heave run


# --- FrequencyResponse and the table ---------------------------------------------------------------


def test_frequency_response_validates_its_fields():
    zero = FRF(*(0j for _ in FRF_NAMES))
    good = dict(reduced_frequency=0.5, speed_m_s=V, dof="heave", frf=zero, stderr=zero, provides=("h_mu", "h_pu"),
                periods=3, deck_width_m=B)
    assert FrequencyResponse(**good).provides == ("h_pu", "h_mu")        # FRF order
    for bad, match in ((dict(dof="roll"), "dof"), (dict(provides=("h_ptheta",)), "provides"),
                       (dict(reduced_frequency=0.0), "reduced_frequency"), (dict(periods=0), "periods")):
        with pytest.raises(InputError, match=match):
            FrequencyResponse(**{**good, **bad})


def test_table_from_heave_and_pitch_runs_at_several_reduced_frequencies_and_speeds():
    rng = np.random.default_rng(4)
    omegas, speeds = (0.4, 0.9, 1.5), (30.0, 60.0)
    responses = [r for Om in omegas for s in speeds for r in theodorsen_runs(Om, s, rng)]
    rng.shuffle(responses)
    table = frf_table(responses, source="synthetic")
    np.testing.assert_allclose(table.omega, omegas, rtol=1e-12)
    np.testing.assert_allclose(table.speed, speeds)
    Om, Vg = np.meshgrid(omegas, speeds, indexing="ij")
    got, want = table.frf(Om, Vg), Theodorsen().frf(Om, Vg)
    for n in ("h_pu", "h_ptheta", "h_mu", "h_mtheta"):
        np.testing.assert_allclose(getattr(got, n), getattr(want, n), rtol=1e-6)
    grid = tabulate(responses)
    assert grid.provides == ("h_pu", "h_ptheta", "h_mu", "h_mtheta") and grid.values.h_pu.shape == (3, 2)

    one_speed = [r for r in responses if r.speed_m_s == 30.0]
    with pytest.raises(InputError, match="speed_independent_table"):
        frf_table(one_speed)
    flat = speed_independent_table(one_speed, (20.0, 90.0))
    np.testing.assert_allclose(flat.speed, [20.0, 90.0])
    a, b = flat.frf(0.9, 20.0), flat.frf(0.9, 75.0)                   # constant in V
    assert a.h_mtheta == pytest.approx(Theodorsen().frf(0.9, 30.0).h_mtheta, rel=1e-6)
    for n in ("h_pu", "h_ptheta", "h_mu", "h_mtheta"):
        assert getattr(a, n) == pytest.approx(getattr(b, n), rel=1e-14)
    with pytest.raises(InputError, match="frf_table"):
        speed_independent_table(responses, (20.0, 90.0))

    heave_only = [r for r in responses if r.dof == "heave"]
    with pytest.raises(InputError, match="h_ptheta"):
        frf_table(heave_only)
    with pytest.raises(InputError, match="twice"):
        frf_table(responses + responses[:1])
