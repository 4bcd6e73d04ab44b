"""Transported scalars (bridge/cfd/transport.py, kernels/transport.py): the building block of the
k-omega SST model. Closed-form checks: a diffusing Gaussian carried by a uniform stream converges at
second order (uniform and stretched y), advection keeps a step bounded (TVD) while the unlimited
central scheme does not, a stiff sink keeps q positive, steady diffusion between two wall values is
exactly linear, zero-flux boundaries conserve the total, and advection relative to a moving grid
leaves q still when the grid moves with the flow; the wall distance is exact to the polygon's chords."""

import numpy as np
import pytest
import warp as wp

from bridge.cfd import BoundaryConditions, CartesianGrid, CFLMonitor, FlowConfig, Simulation, circle, stretched_faces
from bridge.cfd.transport import TransportedScalar, advance_pair, wall_distance

U, V = 1.0, 0.5


def _sim(grid, scheme="vanleer"):
    return Simulation(grid, FlowConfig(nu=1e-3, advection=scheme, threads=1,
                                       bc=BoundaryConditions(left="slip", right="slip")))


def _uniform_velocity(sim, u=U, v=V):
    return wp.full(sim.u.shape, u, dtype=wp.float64), wp.full(sim.v.shape, v, dtype=wp.float64)


def _gaussian(x, y, t, gamma, s0=0.25, x0=(1.5, 1.5)):
    """Exact solution of dq/dt + (U, V).grad q = gamma lap q from a Gaussian of width s0 at x0."""
    s2 = s0 ** 2 + 2 * gamma * t
    return s0 ** 2 / s2 * np.exp(-((x - x0[0] - U * t) ** 2 + (y - x0[1] - V * t) ** 2) / (2 * s2))


def _gaussian_error(n, stretched, gamma=0.01, t_end=1.0):
    h = 5.0 / n
    eta = np.linspace(0.0, 1.0, int(round(4 / h)) + 1)
    # stretched: a smooth map, so that halving h halves every cell (the spacing varies by +-24 %)
    y = 4.0 * eta + (0.3 * np.sin(np.pi * eta) if stretched else 0.0)
    grid = CartesianGrid(np.linspace(0.0, 5.0, n + 1), y)
    sim = _sim(grid)
    u, v = _uniform_velocity(sim)
    X, Y = np.meshgrid(grid.x_centres, grid.y_centres)
    q = TransportedScalar(sim, "q", initial=_gaussian(X, Y, 0.0, gamma), diffusivity=gamma)
    steps = int(np.ceil(t_end / q.stable_dt(u, v)))
    for _ in range(steps):
        q.advance(t_end / steps, u, v)
    return float(np.sum(np.abs(q.interior() - _gaussian(X, Y, t_end, gamma)) * grid.cell_areas()))


@pytest.mark.parametrize("stretched", [False, True], ids=["uniform", "stretched_y"])
def test_a_diffusing_gaussian_converges_at_second_order(stretched):
    """L1 error at t = 1 for h = 0.1, 0.05, 0.025 (2.5-10 cells per initial width); measured orders
    2.08 and 2.15 on the uniform grid. Stretched: y = 4 eta + 0.3 sin(pi eta) on a uniform eta."""
    e = [_gaussian_error(n, stretched) for n in (50, 100, 200)]
    orders = np.log2(np.array(e[:-1]) / np.array(e[1:]))
    assert orders.min() > 1.8, (e, orders)


def _step_profile(scheme, steps=60):
    grid = CartesianGrid.uniform(64, 48, (0.0, 4.0), (0.0, 3.0))
    sim = _sim(grid, scheme)
    u, v = _uniform_velocity(sim)
    X, Y = np.meshgrid(grid.x_centres, grid.y_centres)
    q = TransportedScalar(sim, "q", initial=((np.abs(X - 1.0) < 0.5) & (np.abs(Y - 1.0) < 0.5)).astype(float))
    dt = q.stable_dt(u, v)
    for _ in range(steps):
        q.advance(dt, u, v)
    return q.interior()


def test_advection_keeps_a_step_between_its_bounds():
    """van Leer (TVD): a 0/1 square carried diagonally stays within [0, 1]; the central scheme (no
    limiter) over- and undershoots, so the check can fail."""
    q = _step_profile("vanleer")
    assert q.min() >= -1e-12 and q.max() <= 1 + 1e-12, (q.min(), q.max())
    central = _step_profile("central")
    assert central.min() < -1e-3 or central.max() > 1 + 1e-3


def test_a_stiff_sink_keeps_q_positive():
    """S_i dt = 100: each step divides q by 1 + S_i dt (module doc), never changes its sign."""
    grid = CartesianGrid.uniform(16, 16, (0.0, 1.0), (0.0, 1.0))
    sim = _sim(grid)
    u, v = _uniform_velocity(sim, 0.0, 0.0)
    q = TransportedScalar(sim, "q", initial=2.0)
    q.set_coefficients(sink=1e4)
    for _ in range(3):
        q.advance(0.01, u, v)
    np.testing.assert_allclose(q.interior(), 2.0 / 101.0 ** 3, rtol=1e-12)


def test_steady_diffusion_between_two_wall_values_is_linear():
    """q = 1 on the left face, 0 on the right, no flow: the steady profile is q = 1 - x, which the
    second-order finite volumes hold exactly (to the iteration's convergence)."""
    grid = CartesianGrid.uniform(10, 4, (0.0, 1.0), (0.0, 0.4))
    sim = _sim(grid)
    u, v = _uniform_velocity(sim, 0.0, 0.0)
    q = TransportedScalar(sim, "q", sides={"left": ("value", 1.0), "right": ("value", 0.0)}, diffusivity=1.0)
    dt = q.stable_dt(u, v)
    for _ in range(int(3.0 / dt)):
        q.advance(dt, u, v)
    np.testing.assert_allclose(q.interior(), np.broadcast_to(1.0 - grid.x_centres, (4, 10)), atol=1e-8)


def test_zero_gradient_sides_conserve_the_total():
    grid = CartesianGrid(np.linspace(0.0, 2.0, 33), stretched_faces(0.0, 2.0, (0.5, 1.5), 2.0 / 32, 1.1))
    sim = _sim(grid)
    u, v = _uniform_velocity(sim, 0.0, 0.0)
    X, Y = np.meshgrid(grid.x_centres, grid.y_centres)
    q = TransportedScalar(sim, "q", initial=np.exp(-((X - 0.7) ** 2 + (Y - 1.2) ** 2) / 0.05),
                          diffusivity=0.05 * (1 + X))
    total = np.sum(q.interior() * grid.cell_areas())
    dt = q.stable_dt(u, v)
    for _ in range(200):
        q.advance(dt, u, v)
    assert abs(np.sum(q.interior() * grid.cell_areas()) / total - 1) < 1e-12


def test_a_grid_moving_with_the_flow_leaves_q_still():
    """Advection is relative to the grid (the overset body grid): a grid moving at the stream's
    velocity sees no advection at all; at rest it does."""
    grid = CartesianGrid.uniform(32, 32, (0.0, 2.0), (0.0, 2.0))
    sim = _sim(grid)
    u, v = _uniform_velocity(sim)
    X, Y = np.meshgrid(grid.x_centres, grid.y_centres)
    start = np.exp(-((X - 1.0) ** 2 + (Y - 1.0) ** 2) / 0.1)
    q = TransportedScalar(sim, "q", initial=start)
    sim.set_frame_velocity(U, V, 0.0)
    for _ in range(10):
        q.advance(0.01, u, v)
    np.testing.assert_allclose(q.interior(), start, atol=1e-14)
    # the time step's limit sees the same relative velocity: none here (no diffusivity: no limit at all)
    assert q.stable_dt(u, v) == np.inf
    sim.set_frame_velocity(0.0, 0.0, 0.0)
    q.advance(0.01, u, v)
    assert np.abs(q.interior() - start).max() > 1e-3
    assert np.isclose(q.stable_dt(u, v), sim.config.cfl / (U / grid.dx + V / grid.dy.min()))


def test_the_flows_time_step_limit_uses_the_velocity_relative_to_the_grid():
    """A grid moving with a uniform stream: nothing crosses its cells, so only the viscous limit is
    left; moving against it, the cells see twice the stream (the absolute velocity, used until
    2026-12-02, saw once: a step twice too long for the convective limit)."""
    grid = CartesianGrid.uniform(32, 32, (0.0, 2.0), (0.0, 2.0))
    sim = Simulation(grid, FlowConfig(nu=1e-3, threads=1, bc=BoundaryConditions(u_inf=U)))  # in- and outflow
    sim.set_state(u=U, v=0.0)
    cfg, h = sim.config, grid.dx
    viscous = cfg.nu / (cfg.fourier * h * h)
    sim.set_frame_velocity(U, 0.0, 0.0)
    assert np.isclose(sim.stable_dt(), 1.0 / viscous)
    sim.set_frame_velocity(-U, 0.0, 0.0)
    assert np.isclose(sim.stable_dt(), 1.0 / (2 * U / h / cfg.cfl + viscous))
    sim.set_frame_velocity(0.0, 0.0, 0.0)
    assert np.isclose(sim.stable_dt(), 1.0 / (U / h / cfg.cfl + viscous))
    # the CFL monitor reads the same relative velocity: zero on a grid that moves with the stream
    sim.last_dt = 0.01
    for frame, courant in ((U, 0.0), (-U, 2 * U * 0.01 / h), (0.0, U * 0.01 / h)):
        sim.set_frame_velocity(frame, 0.0, 0.0)
        monitor = CFLMonitor(every=1)
        monitor(sim)
        assert np.isclose(monitor.history[-1][1], courant, atol=1e-12)


def test_wall_distance_is_exact_to_the_polygons_chords():
    """A circle of radius 0.5 (512 sides) at (1, 0.8) turned by 0.3 rad, and the bottom side of the
    box as a wall: the distance is min(|r - 0.5|, y) to within the chords' sagitta (1e-5)."""
    grid = CartesianGrid(np.linspace(0.0, 2.0, 41), stretched_faces(0.0, 2.0, (0.5, 1.5), 0.05, 1.1))
    d = wall_distance(grid, [circle(1.0, 512)], pose=(1.0, 0.8, 0.3), walls=("bottom",))
    X, Y = np.meshgrid(grid.x_centres, grid.y_centres)
    exact = np.minimum(np.abs(np.hypot(X - 1.0, Y - 0.8) - 0.5), Y)
    np.testing.assert_allclose(d, exact, atol=1e-5)
    assert np.isinf(wall_distance(grid)).all()


def test_bad_input_is_refused_by_name():
    sim = _sim(CartesianGrid.uniform(8, 8, (0.0, 1.0), (0.0, 1.0)))
    with pytest.raises(ValueError, match="k.sides"):
        TransportedScalar(sim, "k", sides={"front": ("gradient",)})
    with pytest.raises(ValueError, match=r"k.sides\['left'\]"):
        TransportedScalar(sim, "k", sides={"left": ("value",)})
    q = TransportedScalar(sim, "k")
    with pytest.raises(ValueError, match="k.sink"):
        q.set_coefficients(sink=-1.0)
    with pytest.raises(ValueError, match="walls"):
        wall_distance(sim.grid, walls=("front",))


def test_two_scalars_in_one_sweep_match_each_alone():
    """``advance_pair`` (k and omega in one kernel) gives bit for bit what two ``advance`` calls give."""
    grid = CartesianGrid(np.linspace(0.0, 2.0, 41), stretched_faces(0.0, 1.0, (0.3, 0.7), 0.05, 1.1))
    X, Y = np.meshgrid(grid.x_centres, grid.y_centres)
    results = []
    for together in (False, True):
        sim = _sim(grid)
        u, v = _uniform_velocity(sim)
        a = TransportedScalar(sim, "a", sides={"left": ("value", 1.0)}, initial=np.exp(-((X - 0.5) ** 2) / 0.02),
                              diffusivity=0.01 * (1 + Y))
        b = TransportedScalar(sim, "b", initial=1.0 + X * Y, diffusivity=0.002)
        b.set_coefficients(source=0.3 * X, sink=2.0)
        for _ in range(5):
            if together:
                advance_pair(a, b, 0.005, u, v)
            else:
                a.advance(0.005, u, v)
                b.advance(0.005, u, v)
        results.append((a.interior(), b.interior()))
    np.testing.assert_array_equal(results[0][0], results[1][0])
    np.testing.assert_array_equal(results[0][1], results[1][1])
