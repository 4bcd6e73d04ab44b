"""Kernel-level checks: Warp step == NumPy reference step, projection divergence at round-off,
Poisson solver identity, signed distance to polygons. Run on cpu and (marker cuda) on a GPU."""

import numpy as np
import pytest
import warp as wp
from cfd_helpers import DEVICES

from bridge.cfd import CartesianGrid, FlowConfig, PoissonSolver, Simulation, circle, max_divergence, stretched_faces
from bridge.cfd.advection import SCHEMES
from bridge.cfd.launch import ROW0, RowLauncher
from bridge.cfd.precision import DTYPE, WP_DTYPE
from bridge.cfd.reference_numpy import NumpyFlow
from kernels import cfd as kc

GRIDS = {
    "uniform": lambda: CartesianGrid(np.linspace(0, 4, 41), np.linspace(-1, 1, 25)),
    "stretched": lambda: CartesianGrid(np.linspace(0, 4, 41), stretched_faces(-2, 2, (-0.5, 0.5), 0.1, 1.1)),
}


def _random_state(grid, seed=0):
    rng = np.random.default_rng(seed)
    ny, nx = grid.shape
    return (1 + 0.3 * rng.standard_normal((ny, nx + 1)), 0.3 * rng.standard_normal((ny + 1, nx)),
            rng.standard_normal((ny, nx)))


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("grid_kind", sorted(GRIDS))
@pytest.mark.parametrize("scheme", sorted(SCHEMES))
@pytest.mark.parametrize("pressure", ["full", "incremental"])
def test_warp_step_matches_numpy_reference(device, grid_kind, scheme, pressure):
    """Three full steps (predictor, inflow/outflow/slip boundaries, Poisson, projection) from a
    random state agree with the independent NumPy implementation to round-off, with a variable
    viscosity field (the eddy-viscosity plug-in) and both threads splitting the rows."""
    grid = GRIDS[grid_kind]()
    cfg = FlowConfig(nu=0.01, advection=scheme, pressure=pressure)
    sim = Simulation(grid, cfg, device=device)
    sim.set_state(*_random_state(grid))
    ref = NumpyFlow(grid, cfg)
    nu = 0.01 * (1 + np.random.default_rng(1).random(ref.nu.shape))
    ref.nu[...] = nu
    sim.set_viscosity(nu)
    for name in "uvp":
        getattr(ref, name)[...] = getattr(sim, name).numpy()
    for _ in range(3):
        sim.step(0.01)
        ref.step(0.01)
    for name in "uvp":
        a, b = getattr(sim, name).numpy(), getattr(ref, name)
        assert np.abs(a - b).max() <= 1e-11 * max(1.0, np.abs(b).max()), name
    assert sim.u.dtype == WP_DTYPE and ref.u.dtype == DTYPE


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("grid_kind", sorted(GRIDS))
def test_stable_dt_combines_the_cfl_and_viscous_limits(device, grid_kind):
    """1/dt = (max|u|/dx + max_j max_i |v|/dy_j)/cfl + nu_max/(fourier h_min^2) on a random state,
    written out with NumPy over the interior faces (the wall-normal faces at the bottom and top rows
    are zero; dy_j the distance between the cell centres on either side of v-face row j), stricter
    than either limit alone; non-finite fields fall back to the viscous limit; dt_max caps it."""
    grid = GRIDS[grid_kind]()
    ny, nx = grid.shape
    cfg = FlowConfig(nu=1e-4, cfl=0.4)
    sim = Simulation(grid, cfg, device=device)
    u, v, p = _random_state(grid, seed=4)
    u[ny // 2, 7] = -9.0  # the largest |u| is negative
    v[1:-1][2, 5] = -7.0  # the largest |v| is negative and not on the finest row
    sim.set_state(u, v, p)
    su, sv = sim.interior()[:2]
    dy = np.diff(grid.y_centres)  # between cell rows j-1 and j: v-face rows 1 .. ny-1
    rate = np.abs(su).max() / grid.dx + (np.abs(sv[1:-1]).max(axis=1) / dy).max()
    h2 = grid.min_spacing ** 2
    assert sim.stable_dt() == pytest.approx(1.0 / (rate / 0.4 + 1e-4 / (cfg.fourier * h2)), rel=1e-14)
    assert sim.stable_dt() < min(0.4 / rate, cfg.fourier * h2 / 1e-4)
    sim.set_viscosity(np.full((ny, nx), 50.0))  # nu_max enters the viscous rate
    assert sim.stable_dt() == pytest.approx(1.0 / (rate / 0.4 + 50.0 / (cfg.fourier * h2)), rel=1e-14)
    sim.u.assign(np.where(np.isnan(sim.u.numpy()), 0.0, np.nan))  # a diverged field
    assert sim.stable_dt() == pytest.approx(cfg.fourier * h2 / 50.0, rel=1e-14)
    capped = Simulation(grid, FlowConfig(nu=1e-4, cfl=0.4, dt_max=1e-9), device=device)
    capped.set_state(u, v, p)
    assert capped.stable_dt() == 1e-9


@pytest.mark.parametrize("device", DEVICES)
@pytest.mark.parametrize("grid_kind", sorted(GRIDS))
def test_divergence_after_projection_is_round_off(device, grid_kind):
    grid = GRIDS[grid_kind]()
    sim = Simulation(grid, FlowConfig(nu=0.01), device=device)
    sim.set_state(*_random_state(grid))
    before = max_divergence(sim)
    sim.step(0.01)
    after = max_divergence(sim)
    assert before > 1.0  # the random start is far from solenoidal
    assert after < 1e-12 * before * 1e2


@pytest.mark.parametrize("method,warp", [("dct2d", False), ("tridiag", False), ("tridiag", True)])
@pytest.mark.parametrize("grid_kind", sorted(GRIDS))
def test_poisson_solver_inverts_the_discrete_operator(grid_kind, method, warp):
    """Apply D G (written here independently with NumPy) to a solution and recover it, with every
    solve path: 2D DCT (uniform grids), DCT + Thomas in NumPy, DCT + Thomas in the Warp kernel."""
    grid = GRIDS[grid_kind]()
    if method == "dct2d" and not grid.y_uniform:
        with pytest.raises(ValueError, match="method"):
            PoissonSolver(grid, method=method)
        return
    ny, nx = grid.shape
    rng = np.random.default_rng(3)
    phi = rng.standard_normal((ny, nx))
    dx, dy = grid.dx, grid.dy
    yc = grid.y_centres
    gx = np.zeros((ny, nx + 1))
    gx[:, 1:-1] = np.diff(phi, axis=1) / dx
    gy = np.zeros((ny + 1, nx))
    gy[1:-1] = np.diff(phi, axis=0) / np.diff(yc)[:, None]
    lap = np.diff(gx, axis=1) / dx + np.diff(gy, axis=0) / dy[:, None]
    sol = PoissonSolver(grid, method=method, launcher=RowLauncher("cpu", 2) if warp else None).solve(lap)
    err = (sol - sol[0, 0]) - (phi - phi[0, 0])
    assert np.abs(err).max() < 1e-9


@pytest.mark.parametrize("device", DEVICES)
def test_signed_distance_of_a_polygon_circle(device):
    poly = circle(1.0, n=512)
    verts = wp.array(poly.vertices, dtype=wp.vec2d, device=device)
    nx, ny = 31, 21
    grid = CartesianGrid.uniform(nx, ny, (-1.5, 1.5), (-1.0, 1.0))
    yc = wp.array(grid.storage_y_centres(), dtype=wp.float64, device=device)
    phi = wp.zeros((ny, nx + 1), dtype=wp.float64, device=device)
    wp.launch(kc.ib_level_set, dim=ny, inputs=[verts, grid.x_faces[0], grid.dx, -2.0, yc,
                                               wp.vec3d(0.1, -0.05, 0.3), 2, 2, nx + 1, phi], device=device)
    X, Y = np.meshgrid(grid.x_faces - 0.1, grid.y_centres + 0.05)
    exact = np.hypot(X, Y) - 0.5
    assert np.abs(phi.numpy() - exact).max() < 5e-5


def test_polygon_properties_of_a_circle():
    p = circle(2.0, n=400)
    assert p.area == pytest.approx(np.pi, rel=1e-12)
    assert np.allclose(p.centroid, 0.0, atol=1e-12)
    assert p.polar_moment_centroid == pytest.approx(np.pi / 2, rel=1e-4)  # pi R^4 / 2, R = 1


def test_set_viscosity_checks_shape_and_sign():
    grid = GRIDS["uniform"]()
    sim = Simulation(grid, FlowConfig(nu=0.01))
    sim.set_viscosity(np.full(grid.shape, 0.03))
    assert sim.nu_max == pytest.approx(0.03) and np.allclose(sim.nu.numpy(), 0.03)
    with pytest.raises(ValueError, match="nu_eff"):
        sim.set_viscosity(np.zeros(grid.shape))
    with pytest.raises(ValueError, match="nu_eff"):
        sim.set_viscosity(np.ones((3, 3)))


@wp.kernel
def _scaled_rows(q: wp.array2d(dtype=wp.float64), value: wp.float64, row0: int):
    J = row0 + wp.tid()
    for I in range(q.shape[1]):
        q[J, I] = value * wp.float64(J + 1)


def test_recorded_launches_update_scalars_and_keep_row_chunks_apart():
    """The launcher replays recorded launches: a changed float argument must reach the kernel, and
    the two row chunks (same arrays, same size, run at the same time) must not share a record."""
    launcher = RowLauncher("cpu", 2)
    q = wp.zeros((8, 5), dtype=wp.float64, device="cpu")
    expected_rows = np.arange(1, 9, dtype=float)[:, None] * np.ones((1, 5))
    for value in (1.0, 2.5, 2.5, -3.0):
        launcher.rows(_scaled_rows, 8, 0, [q, value, ROW0], min_split=2)
        np.testing.assert_array_equal(q.numpy(), value * expected_rows)
    plain = RowLauncher("cpu", 2, record=False)
    r = wp.zeros((8, 5), dtype=wp.float64, device="cpu")
    plain.rows(_scaled_rows, 8, 0, [r, -3.0, ROW0], min_split=2)
    np.testing.assert_array_equal(r.numpy(), q.numpy())
    # NumPy integer row offsets are keyed by value too: one record per chunk, not one shared record
    launcher.forget()
    launcher.rows(_scaled_rows, 8, np.int64(0), [q, 4.0, ROW0], min_split=2)
    assert launcher.n_records == 2
    np.testing.assert_array_equal(q.numpy(), 4.0 * expected_rows)
    # more threads than rows: the empty chunks are skipped, not recorded
    RowLauncher("cpu", 3).rows(_scaled_rows, 2, 0, [q, 5.0, ROW0], min_split=1)
    np.testing.assert_array_equal(q.numpy()[:2], 5.0 * expected_rows[:2])
