"""Overset pair (bridge/cfd/overset.py): the transfer is exact where it must be (interpolation of
cubics, stream-function faces, zero net flux through the body grid's boundary), a body grid moving
through uniform flow leaves it uniform, and the flow past a body does not depend on the frame
(Galilean invariance), which the moving-frame terms of the predictor must get right."""

import numpy as np
import pytest

from bridge.cfd import (
    BoundaryConditions,
    CartesianGrid,
    FlowConfig,
    HarmonicMotion,
    Simulation,
    Stationary,
    UniformTranslation,
    circle,
    stretched_faces,
)
from bridge.cfd.grids import GHOST
from bridge.cfd.overset import CornerInterpolator, OversetPair, stream_function

BACKGROUND = CartesianGrid.uniform(96, 48, (-4.0, 8.0), (-3.0, 3.0))
BODY_GRID = CartesianGrid.uniform(48, 24, (-1.5, 1.5), (-0.75, 0.75))


def test_corner_interpolation_is_exact_for_cubics_on_a_stretched_lattice():
    y = stretched_faces(-2.0, 2.0, (-0.5, 0.5), 0.1, 1.1)
    x = np.linspace(-1.0, 3.0, 41)
    X, Y = np.meshgrid(x, y)
    f = lambda a, b: 1 + a - 2 * b + a * a * b - 0.5 * b ** 3 + a ** 3 * b ** 2  # noqa: E731  cubic in each
    rng = np.random.default_rng(0)
    px, py = rng.uniform(-1.0, 3.0, 200), rng.uniform(-2.0, 2.0, 200)
    got = CornerInterpolator(x, y)(f(X, Y), px, py)
    assert np.max(np.abs(got - f(px, py))) < 1e-11
    # and not of a quartic (the check can fail)
    got4 = CornerInterpolator(x, y)(X ** 4, px, py)
    assert np.max(np.abs(got4 - px ** 4)) > 1e-8


def test_stream_function_differences_give_back_the_faces():
    """Any projected (divergence-free) field: psi differences reproduce every interior face."""
    sim = Simulation(BACKGROUND, FlowConfig(nu=0.01))
    rng = np.random.default_rng(1)
    ny, nx = BACKGROUND.ny, BACKGROUND.nx
    sim.set_state(u=1.0 + 0.1 * rng.standard_normal((ny, nx + 1)), v=0.1 * rng.standard_normal((ny + 1, nx)))
    sim.step(1e-3)   # a projection makes it divergence-free
    u, v, _ = sim.interior()
    psi = stream_function(sim)
    hy = BACKGROUND.dy
    assert np.allclose((psi[1:, :] - psi[:-1, :]) / hy[:, None], u, atol=1e-12)
    assert np.allclose(-(psi[:, 1:] - psi[:, :-1]) / BACKGROUND.dx, v, atol=1e-12)


def _pair(motion, polygon=None, u_inf=1.0):
    pair = OversetPair(BACKGROUND, BODY_GRID, FlowConfig(nu=0.01, bc=BoundaryConditions(u_inf=u_inf)), motion,
                       polygon=polygon)
    pair.set_uniform_flow(u_inf)
    return pair


def _freestream_error(amplitude, dt, t_end=1.0):
    motion = HarmonicMotion(0.0, 0.0, amplitude, omega=2.0)
    pair = _pair(motion)
    for _ in range(int(round(t_end / dt))):
        pair.step(dt)
    u, v, _ = pair.background.interior()
    ub, vb, _ = pair.body.interior()
    th = motion.pose(pair.t)[2]
    return max(np.abs(u - 1).max(), np.abs(v).max(), np.abs(ub - np.cos(th)).max(), np.abs(vb + np.sin(th)).max())


def test_a_heaving_body_grid_leaves_uniform_flow_uniform():
    """Heave: translation only, exact to round-off (measured 1e-14)."""
    assert _freestream_error((0.0, 0.2, 0.0), 0.02) < 1e-12


def test_a_pitching_body_grid_leaves_uniform_flow_uniform_to_second_order_in_dt():
    """Pitch (0.15 rad): the turning axes change u_b in time; the error is the time discretisation's
    (measured 8.6e-4 / 2.2e-4 at dt = 0.02 / 0.01: ratio 4.0)."""
    coarse, fine = _freestream_error((0.0, 0.0, 0.15), 0.02), _freestream_error((0.0, 0.0, 0.15), 0.01)
    assert fine < 1e-3 and coarse / fine > 3.5, (coarse, fine)


def test_no_net_flux_through_the_body_grids_boundary():
    """The boundary faces come from differences of the background's psi: they telescope to zero net
    flux around the closed boundary (round-off), whatever the flow."""
    pair = _pair(HarmonicMotion(0.0, 0.0, (0.0, 0.2, 0.15), omega=2.0), polygon=circle(0.4))
    for _ in range(20):
        pair.step()
    g, gb = GHOST, BODY_GRID
    u, v = pair.body.u.numpy(), pair.body.v.numpy()
    h = gb.dx
    net = h * (u[g:g + gb.ny, g + gb.nx].sum() - u[g:g + gb.ny, g].sum()
               + v[g + gb.ny, g:g + gb.nx].sum() - v[g, g:g + gb.nx].sum())
    through = h * np.abs(u[g:g + gb.ny, g]).sum()
    assert abs(net) < 1e-12 * through, (net, through)


def _drag_history(motion, u_inf, t_end=2.0):
    bg = CartesianGrid.uniform(96, 48, (-6.0, 10.0), (-4.0, 4.0))
    body = CartesianGrid.uniform(36, 36, (-1.5, 1.5), (-1.5, 1.5))
    pair = OversetPair(bg, body, FlowConfig(nu=0.05, bc=BoundaryConditions(u_inf=u_inf)), motion,
                       polygon=circle(1.0, 128))
    pair.set_uniform_flow(u_inf)
    t, fx = [], []
    while pair.t < t_end - 1e-9:
        pair.step(min(0.01, t_end - pair.t))
        t.append(pair.t)
        fx.append(pair.last_force[0])
    return np.array(t), np.array(fx)


def test_galilean_a_body_moving_with_its_grid_feels_the_force_of_a_fixed_body():
    """Cylinder (Re 20 on the relative speed) started impulsively: held still in a stream of 1, or
    moving at -0.5 with its grid through a stream of 0.5. The relative flow is the same, so is the
    drag history (within 1 %, the issue's target; measured at D/20, t = 1-4: 0.03-0.14 %, growing
    later as the moving body nears the inflow boundary). With the moving-frame terms of the
    predictor switched off the two differ by 41 %."""
    t_a, fa = _drag_history(Stationary(0.0, 0.0), 1.0)
    t_b, fb = _drag_history(UniformTranslation(0.0, 0.0, -0.5, 0.0), 0.5)
    assert np.allclose(t_a, t_b)
    late = t_a > 0.5   # past the impulsive start's first steps
    rel = np.abs(fb[late] / fa[late] - 1)
    assert rel.max() < 0.01, rel.max()


def test_a_deck_close_to_the_body_grids_edge_stays_stable():
    """A box deck (chord 2, 10 % deep, sharp tips) held still in a stream of 1 at Re 100, its tips
    0.25 chord from the body grid's edge (D/32 over D/16). With the hole compensated by the
    background's own pressure this diverged before t = 1 (the hole's pressure integrated the
    coupling's mismatch, overset.py); with the body grid's pressure the symmetric deck keeps a lift
    near zero (measured |F_y| <= 0.013 over t = 1-1.5; the single grid at D/32: <= 0.007)."""
    from bridge.cfd import BoundaryConditions as BC
    from bridge.cfd import box_deck

    bg = CartesianGrid.uniform(256, 128, (-4.0, 12.0), (-4.0, 4.0))
    body = CartesianGrid.uniform(96, 39, (-1.5, 1.5), (-39 / 64, 39 / 64))
    cfg = FlowConfig(nu=0.01, threads=1, bc=BC(left="inflow", right="outflow", bottom="slip", top="slip"))
    pair = OversetPair(bg, body, cfg, Stationary(0.0, 0.0), polygon=box_deck(2.0, 0.2, 0.2))
    pair.set_uniform_flow(1.0)
    lift = []
    for _ in range(150):
        pair.step(0.01)
        lift.append(pair.last_force[1])
    late = np.abs(lift[100:])
    assert np.isfinite(late).all() and late.max() < 0.05, late.max()


def _added_mass_coefficient(n, nu=0.02, steps_per_period=400):
    """In-phase force coefficient of a cylinder x = A sin(w t), A = D/20, f = 1, in a closed 8D slip
    box at rest, over the second period (tests/cfd/test_cfd_bodies.py's case): the cylinder in a body
    grid of 2.5 D at h = D/n over a background of h = 2 D/n."""
    from bridge.cfd import BoundaryConditions as BC

    bg = CartesianGrid.uniform(4 * n, 4 * n, (-4.0, 4.0), (-4.0, 4.0))
    body = CartesianGrid.uniform(int(2.5 * n), int(2.5 * n), (-1.25, 1.25), (-1.25, 1.25))
    amp, omega = 0.05, 2 * np.pi
    pair = OversetPair(bg, body, FlowConfig(nu=nu, bc=BC(left="slip", right="slip", bottom="slip", top="slip")),
                       HarmonicMotion(0.0, 0.0, (amp, 0.0, 0.0), omega), polygon=circle(1.0))
    pair.set_uniform_flow(0.0)
    dt = 1.0 / steps_per_period
    t, f = [], []
    for _ in range(2 * steps_per_period):
        pair.step(dt)
        t.append(pair.t)
        f.append(pair.last_force[0])
    t, f = np.array(t), np.array(f)
    sel = t > 1.0
    basis = np.column_stack([np.sin(omega * t[sel]), np.cos(omega * t[sel])])
    (a_sin, _), *_ = np.linalg.lstsq(basis, f[sel], rcond=None)
    return a_sin / (np.pi / 4 * amp * omega ** 2)


@pytest.mark.slow  # ~60 s: runs in CI with -m slow
def test_added_mass_converges_on_the_overset_pair():
    """The oscillating cylinder of the single-grid test (Stokes 1851 / Wang 1968: C_m = 1.320 unbounded,
    about 1.35 in the closed 8D box) with the body and its grid moving together over the background.
    Measured: 1.502 / 1.403 / 1.368 at D/16 / 32 / 64: observed order 1.50, extrapolated 1.349 (the
    single grid: 1.546 / 1.412 / 1.370, order 1.67, 1.351). Asserted as for the single grid: order
    above 1.3 and the limit within 4 % of 1.35 (at 16 / 24 / 32 the overset values are not yet in the
    asymptotic range: 1.502 / 1.444 / 1.403 give an order near 0.1, so the doubling sequence is used)."""
    n = np.array([16, 32, 64])
    c = np.array([_added_mass_coefficient(k) for k in n])
    assert np.all(np.diff(c) < 0), c
    p = np.log2((c[0] - c[1]) / (c[1] - c[2]))
    c_inf = c[2] - (c[1] - c[2]) / (2 ** p - 1)
    assert p > 1.3, (p, c)
    assert abs(c_inf / 1.35 - 1) < 0.04, (c_inf, p, c)
