"""The free-vibration check's parts, each against a closed form (bridge/aero/free_vibration.py):
the coupled step against the exact damped oscillator (order 2), the coupling with loads linear in the motion
against the eigenvalues of the same system, and the matrix-pencil fit against a known two-mode signal."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bridge.aero.free_vibration import AeroelasticFlow, ReleaseCase, SpringSection, damped_modes, least_damped, onset
from bridge.errors import InputError
from bridge.flutter.section import SectionModel


class LinearLoads:
    """A stand-in flow whose loads are linear in the body's state at the end of each step:
    (F_y, M_z) = A @ (y, theta, y', theta')."""

    def __init__(self, motion, A, bias=(0.0, 0.0)):
        self.motion, self.A, self.bias = motion, np.asarray(A, dtype=float), np.asarray(bias, dtype=float)
        self.t, self.n_steps = 0.0, 0
        self.total_force = np.zeros(3)

    def stable_dt(self):
        return 0.05

    def step(self, dt):
        self.t += dt
        self.n_steps += 1
        x, y, th = self.motion.pose(self.t)
        _, vy, om = self.motion.velocity(self.t)
        fy, mz = self.A @ np.array([y, th, vy, om]) + self.bias
        self.total_force = np.array([0.0, fy, mz])
        return dt


def run_free(structure, A, dt, t_end, twist=0.01):
    case = ReleaseCase(twist_rad=twist, hold=0.0)
    motion = case.motion()
    flow = AeroelasticFlow(LinearLoads(motion, A), motion, structure)
    flow.step(dt)   # the release needs one load on record
    while flow.t < t_end - 1e-12:
        flow.step(dt)
    return np.array(flow.history)


def exact_pitch(structure, t, twist):
    w, z = structure.pitch_omega, structure.pitch_damping
    wd = w * math.sqrt(1 - z * z)
    return twist * np.exp(-z * w * t) * (np.cos(wd * t) + z * w / wd * np.sin(wd * t))


def test_still_air_decay_is_the_exact_oscillator_to_second_order():
    s = SpringSection(mass_ratio=20.0, inertia_ratio=2.0, heave_omega=0.3, pitch_omega=0.8, pitch_damping=0.02)
    errors = []
    for dt in (0.2, 0.1, 0.05):
        h = run_free(s, np.zeros((2, 4)), dt, 40.0)
        t, th = h[:, 0] - dt, h[:, 2]   # released after the first step, at t = dt
        errors.append(np.abs(th - exact_pitch(s, t, 0.01)).max())
    order = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(order > 1.9), (errors, order)
    # the trapezoidal rule's phase error, (w dt)^2 / 12 per radian (Hughes 1987, sec. 9.3), over 40 time units
    w_dt = s.pitch_omega * 0.05
    assert errors[-1] < 1.5 * 0.01 * w_dt ** 2 / 12 * s.pitch_omega * 40


def test_coupled_growth_rate_is_the_linear_systems_eigenvalue():
    """Loads linear in the state (lift and moment from twist and rates, a quasi-steady-like model strong
    enough to couple the two modes) make a linear 4x4 system; the staggered coupling and the fit must
    give its least damped eigenvalue."""
    s = SpringSection(mass_ratio=10.0, inertia_ratio=1.0, heave_omega=0.5, pitch_omega=0.8)
    A = np.array([[-0.5, 2.0, -1.2, 0.0],      # F_y from y, theta, y', theta'
                  [0.0, -0.15, 0.25, 0.05]])   # M_z
    mass = np.diag([s.mass_ratio, s.inertia_ratio])
    K = np.diag([s.mass_ratio * s.heave_omega ** 2, s.inertia_ratio * s.pitch_omega ** 2]) - A[:, :2]
    C = -A[:, 2:]
    state = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(mass, K), -np.linalg.solve(mass, C)]])
    lam = np.linalg.eigvals(state)
    lam = lam[lam.imag > 0]
    expect = lam[np.argmax(lam.real)]
    h = run_free(s, A, 0.02, 120.0)
    fitted = least_damped(damped_modes(h[:, 0], h[:, 1:3].T))
    assert fitted.sigma == pytest.approx(expect.real, abs=2e-3 * abs(expect))
    assert fitted.omega == pytest.approx(expect.imag, rel=1e-3)


def test_preloaded_springs_oscillate_about_the_held_pose():
    """A steady wind load (lift and moment) held during the hold and preloaded into the springs: the section,
    released level with a pitch rate, swings about zero as theta = rate / w sin(w t); without the preload it
    swings about the static deflection M / (iota w^2)."""
    s = SpringSection(mass_ratio=10.0, inertia_ratio=1.0, heave_omega=0.5, pitch_omega=0.8)
    bias, rate = (0.3, 0.05), 0.01
    for preload, centre in ((True, 0.0), (False, 0.05 / 0.64)):
        case = ReleaseCase(twist_rad=0.0, hold=2.0, kick_rate=rate, preload=preload)
        flow = case.flow(LinearLoads(case.motion(), np.zeros((2, 4)), bias), s)
        while flow.t < 40.0 - 1e-12:
            flow.step(0.02)
        t, th = np.array(flow.history)[:, [0, 2]].T
        if preload:
            expect = rate / 0.8 * np.sin(0.8 * (t - 2.0))
            # the trapezoidal rule's phase error (as above)
            assert np.abs(th - expect).max() < 1.5 * rate / 0.8 * (0.8 * 0.02) ** 2 / 12 * 0.8 * 38
        else:
            assert 0.5 * (th.max() + th.min()) == pytest.approx(centre, rel=1e-3)


def test_matrix_pencil_recovers_two_modes_and_an_offset():
    t = np.sort(np.random.default_rng(1).uniform(0, 60, 3000))
    y = 0.3 + 1.0 * np.exp(-0.02 * t) * np.cos(0.5 * t + 0.3) + 0.4 * np.exp(0.01 * t) * np.cos(1.3 * t)
    th = -0.1 + 0.2 * np.exp(-0.02 * t) * np.sin(0.5 * t) + 0.8 * np.exp(0.01 * t) * np.cos(1.3 * t + 1.0)
    modes = damped_modes(t, np.array([y, th]))
    assert [m.omega for m in modes] == pytest.approx([0.5, 1.3], rel=1e-4)
    assert [m.sigma for m in modes] == pytest.approx([-0.02, 0.01], abs=1e-4)
    assert modes[0].amplitudes == pytest.approx((1.0, 0.2), rel=2e-3)
    assert least_damped(modes).omega == pytest.approx(1.3, rel=1e-4)


def test_onset_between_the_bracketing_speeds():
    assert onset([60, 70, 80], [-0.02, -0.01, 0.01]) == pytest.approx(75.0)
    assert onset([80, 60, 70], [0.01, -0.02, -0.01]) == pytest.approx(75.0)
    assert onset([60, 70], [-0.02, -0.01]) is None


def test_section_in_cfd_units():
    sec = SectionModel(mass_per_length_kg_m=43295.0, inertia_per_length_kg_m2_m=4773282.0, heave_frequency_hz=0.12,
                       pitch_frequency_hz=0.30, deck_width_m=30.0)
    s = SpringSection.at_speed(sec, 100.0, 1.225)
    assert s.mass_ratio == pytest.approx(43295.0 / (1.225 * 900))
    assert s.pitch_omega == pytest.approx(2 * math.pi * 0.30 * 30 / 100)
    with pytest.raises(InputError, match="speed_m_s"):
        SpringSection.at_speed(sec, -1.0, 1.225)


def test_forced_runs_about_a_mean_angle():
    """[aero] mean_angle_deg tilts both forced runs nose up (clockwise in the CFD frame) about the same axis; the
    recorded displacement stays the oscillation alone; a tilt beyond 10 degrees is refused by name."""
    from bridge.aero.forced_motion import ForcedCase
    from bridge.aero.options import AeroOptions

    a0 = math.radians(1.0)
    pitch = ForcedCase("pitch", (0.5,), (0.02,), mean_angle=a0)
    heave = ForcedCase("heave", (0.5,), (0.01,), mean_angle=a0)
    t = 1.3
    assert pitch.motion().pose(t)[2] == pytest.approx(-a0 - 0.02 * math.sin(0.5 * t))
    assert heave.motion().pose(t) == pytest.approx((0.0, 0.01 * math.sin(0.5 * t), -a0))
    assert pitch.excursion(0.5) == pytest.approx(0.02 * 0.5 + math.sin(a0) * 0.5)
    assert AeroOptions(mean_angle_deg=1.0).mean_angle_deg == 1.0
    with pytest.raises(InputError, match="aero.mean_angle_deg"):
        AeroOptions(mean_angle_deg=12.0)


def test_the_body_fitted_grid_sees_a_push_at_a_time_it_has_already_asked_for():
    """FreeMotion's path at the current time changes when the structure pushes its next step (the release's
    kick, and each step's new Hermite segment); the O-grid keeps its frame velocity and relative fluxes per time,
    so it must see the push (it keys them on the motion's revision)."""
    from bridge.aero.free_vibration import FreeMotion
    from bridge.cfd.curvilinear import CurvilinearFlow, CurvilinearGrid, polar_grid

    motion = FreeMotion((0.0, 0.0, 0.0), release=0.01)
    flow = CurvilinearFlow(CurvilinearGrid(*polar_grid(0.5, 4.0, 16, 0.05, 1.2)), 0.01, motion)
    flow.set_uniform_flow(1.0, 0.0)
    flow.step(0.02)
    t = flow.t
    assert flow.frame_velocity(t) == (0.0, 0.0, 0.0)
    kick = np.array([0.0, 0.0, 0.3])
    motion.push((t, t + 0.02, np.zeros(3), kick, np.zeros(3), kick))
    assert flow.frame_velocity(t)[2] == pytest.approx(0.3)
