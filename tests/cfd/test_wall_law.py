"""Spalding's law of the wall (kernels/wall_law.py): the Warp inversions against the closed form.

Reference: Spalding (1961), J. Appl. Mech. 28: 455-458 - u+ = y+ in the sublayer and the log law
u+ = ln(y+) / 0.41 + 5.0 above it (the TMR constants).
"""

import numpy as np
import pytest
import warp as wp

from bridge.cfd.grids import GHOST
from kernels import wall_law as wl
from kernels.cfd import square_to_wall

KAPPA, B = 0.41, 5.0


def yplus(up):
    z = KAPPA * up
    return up + np.exp(-KAPPA * B) * (np.exp(z) - 1 - z - z ** 2 / 2 - z ** 3 / 6)


@wp.kernel
def _invert(yp: wp.array(dtype=wp.float64), re_y: wp.array(dtype=wp.float64),
            up: wp.array(dtype=wp.float64), up_friction: wp.array(dtype=wp.float64)):
    i = wp.tid()
    up[i] = wl.spalding_uplus(yp[i])
    up_friction[i] = wl.friction_uplus(re_y[i])


@wp.kernel
def _ratio(speed: wp.array(dtype=wp.float64), y_ref: wp.array(dtype=wp.float64), y: wp.array(dtype=wp.float64),
           nu: wp.float64, out: wp.array(dtype=wp.float64)):
    i = wp.tid()
    out[i] = wl.wall_law_ratio(speed[i], y_ref[i], y[i], nu)


def _run(kernel, n, inputs, outputs):
    arrays = [wp.array(np.asarray(a, float), dtype=wp.float64, device="cpu") if isinstance(a, np.ndarray) else a
              for a in inputs]
    outs = [wp.zeros(n, dtype=wp.float64, device="cpu") for _ in range(outputs)]
    wp.launch(kernel, dim=n, inputs=arrays + outs, device="cpu")
    return [o.numpy() for o in outs]


def test_the_inversions_recover_the_closed_form_from_the_sublayer_to_y_plus_1e7():
    up = np.concatenate([np.linspace(1e-4, 1.0, 7), np.linspace(2, 40, 39)])
    yp = yplus(up)
    assert yp.max() > 1e6
    got, got_friction = _run(_invert, up.size, [yp, up * yp], 2)
    np.testing.assert_allclose(got, up, rtol=1e-11)
    np.testing.assert_allclose(got_friction, up, rtol=1e-11)


def test_the_limits_are_the_linear_profile_and_the_log_law():
    yp = np.array([1e-3, 0.1, 1e3, 1e4, 1e5])
    got, _ = _run(_invert, yp.size, [yp, yp], 2)
    np.testing.assert_allclose(got[:2], yp[:2], rtol=1e-3)
    np.testing.assert_allclose(got[2:], np.log(yp[2:]) / KAPPA + B, atol=0.05)


def test_the_ratio_follows_the_profile_and_is_linear_in_the_sublayer():
    nu, u_tau = 1e-5, 0.05
    y_ref = np.array([2e-3, 1e-2, 5e-5, 1e-4])      # y+ 10, 50, 0.25, 0.5
    y = 0.3 * y_ref
    up_ref = np.interp(y_ref * u_tau / nu, yplus(np.linspace(0, 40, 400001)), np.linspace(0, 40, 400001))
    up_y = np.interp(y * u_tau / nu, yplus(np.linspace(0, 40, 400001)), np.linspace(0, 40, 400001))
    (got,) = _run(_ratio, 4, [u_tau * up_ref, y_ref, y, nu], 1)
    np.testing.assert_allclose(got, up_y / up_ref, rtol=1e-6)
    np.testing.assert_allclose(got[2:], 0.3, rtol=2e-3)   # the sublayer: linear
    assert got[1] > 0.5                                   # the log layer: far fuller than linear


# --- the immersed boundary's wall function and the SST model's wall cells ---------------------------

def _slab_flow(u_tau=0.05, nu=1e-5, wall_y=0.0213):
    """A horizontal slab (top at ``wall_y``) in a grid with cells 4e-3 high (y+ 20 per cell), u set to
    Spalding's profile above it; returns the simulation, its body and the profile."""
    from bridge.cfd import CartesianGrid, FlowConfig, Polygon, Simulation, Stationary

    grid = CartesianGrid(np.linspace(0.0, 0.4, 41), np.linspace(0.0, 0.2, 51))
    sim = Simulation(grid, FlowConfig(nu=nu, threads=1))
    body = sim.add_body(Polygon(np.array([[0.1, -0.05], [0.3, -0.05], [0.3, wall_y], [0.1, wall_y]])), Stationary())
    ups = np.linspace(0.0, 40.0, 400001)

    def profile(y):
        return u_tau * np.interp(np.maximum(y - wall_y, 0.0) * u_tau / nu, yplus(ups), ups)

    sim.u.numpy()[:, :] = profile(grid.storage_y_centres())[:, None]
    return sim, body, profile


def _forced_u(sim, body, wall_function):
    body.set_wall_function(sim.config.nu if wall_function else None)
    body.update(0.0)
    before = sim.u.numpy().copy()
    body.apply(sim.u, sim.v, 0)
    box = body.boxes[0]
    st = box["state"].numpy()
    j, i = np.nonzero(st == 2)
    J, I = j + box["j0"], i + box["i0"]
    return J, I, before, sim.u.numpy()


def test_the_wall_function_reconstructs_a_law_of_the_wall_profile_exactly():
    """Faces next to a flat immersed wall, given Spalding's profile above them, get the profile's value
    back (to the root-finder's round-off), where the linear profile of the laminar forcing is far off:
    the forced face at y+ ~ 5-25 lies between the sublayer and the log layer."""
    sim, body, profile = _slab_flow()
    J, I, before, after = _forced_u(sim, body, wall_function=True)
    top = J[(I > GHOST_COLS[0]) & (I < GHOST_COLS[1])]   # the faces above the top, away from the ends
    cols = I[(I > GHOST_COLS[0]) & (I < GHOST_COLS[1])]
    assert top.size > 5
    np.testing.assert_allclose(after[top, cols], before[top, cols], rtol=1e-9)
    sim2, body2, _ = _slab_flow()
    J2, I2, before2, after2 = _forced_u(sim2, body2, wall_function=False)
    assert np.max(np.abs(after2[top, cols] / before2[top, cols] - 1)) > 0.1


GHOST_COLS = (GHOST + 13, GHOST + 27)   # storage columns of u-faces at x = 0.13-0.27, inside the slab (0.1-0.3)


@wp.kernel
def _eddy(speed: wp.array(dtype=wp.float64), y: wp.array(dtype=wp.float64), nu: wp.float64,
          out: wp.array(dtype=wp.float64)):
    i = wp.tid()
    out[i] = wl.wall_law_eddy_viscosity(speed[i], y[i], nu)


def test_the_laws_eddy_viscosity_is_nu_times_dyplus_duplus_less_one_and_kappa_u_tau_y_in_the_log_layer():
    nu, u_tau = 1e-5, 0.05
    up = np.array([0.25, 2.0, 12.0, 25.0, 30.0])
    yp = yplus(up)
    z = KAPPA * up
    slope = 1 + np.exp(-KAPPA * B) * KAPPA * (np.exp(z) - 1 - z - z ** 2 / 2)     # d y+ / d u+ of the closed form
    (got,) = _run(_eddy, up.size, [u_tau * up, yp * nu / u_tau, nu], 1)
    np.testing.assert_allclose(got, nu * (slope - 1), rtol=1e-9)
    assert got[0] < 1e-4 * nu                                                 # the sublayer: none
    np.testing.assert_allclose(got[3:], KAPPA * u_tau * yp[3:] * nu / u_tau, rtol=0.02)   # log layer: kappa u_tau y


def test_the_blended_wall_function_is_linear_without_eddy_viscosity_and_the_law_with_the_laws_own():
    """The blended wall function (``set_wall_function(nu, nu_eff)``) on the slab: the target is the linear
    profile's where the reference face has no eddy viscosity, Spalding's where it has at least half the law's
    nu (dy+/du+ - 1) there, and halfway where it has a quarter (the weight min(1, 2 nu_t / nu_t,law))."""
    nu, u_tau = 1e-5, 0.05
    targets = {}
    for name, wall_function in (("linear", False), ("law", True)):
        sim, body, _ = _slab_flow()
        J, I, _, after = _forced_u(sim, body, wall_function=wall_function)
        keep = (I > GHOST_COLS[0]) & (I < GHOST_COLS[1])
        top, cols = J[keep], I[keep]
        targets[name] = after[top, cols]
    rows = set(top.tolist())
    assert len(rows) == 1 and np.all(np.abs(targets["law"] / targets["linear"] - 1) > 0.1)
    sim, body, profile = _slab_flow()
    y_ref = sim.grid.storage_y_centres()[top[0] + 1]          # the reference face, one row up
    up_ref = profile(y_ref) / u_tau
    z = KAPPA * up_ref
    law = nu * np.exp(-KAPPA * B) * KAPPA * (np.exp(z) - 1 - z - z ** 2 / 2)
    for share, want in ((0.0, targets["linear"]), (0.25, 0.5 * (targets["linear"] + targets["law"])),
                        (0.5, targets["law"]), (3.0, targets["law"])):
        sim, body, _ = _slab_flow()
        sim.nu.fill_(nu + share * law)
        body.set_wall_function(nu, sim.nu)
        body.update(0.0)
        body.apply(sim.u, sim.v, 0)
        np.testing.assert_allclose(sim.u.numpy()[top, cols], want, rtol=1e-9, err_msg=f"share {share}")


def test_the_sst_wall_cells_hold_omega_at_the_blended_wall_value_and_k_free_of_wall_flux():
    """After one step of the model on the slab: fluid cells within a cell of the wall hold omega =
    sqrt(omega_vis^2 + omega_log^2) of their k and distance, take nu_t = k / omega, and produce k at
    the log layer's rate u_tau^2 beta*^(1/4) sqrt(k) / (kappa d) with u_tau of the profile; cells
    inside next to the fluid hold the means of their fluid neighbours' k and omega with the wall
    function (no flux into the wall, and not the thousandfold nu_t of k over Menter's omega), k = 0 for
    a resolved wall."""
    from bridge.cfd.turbulence import KOmegaSST

    sim, body, _ = _slab_flow(nu=1e-6)   # the first fluid cells at y+ 35
    nu = sim.config.nu
    model = KOmegaSST(sim, 1e-3, 10.0, body_walls="function")
    model.advance(1e-4)   # a first step to give k some variation near the wall
    k0 = model.k.interior().copy()
    w0 = model.omega.interior().copy()
    model.advance(1e-4)
    g, grid = GHOST, sim.grid
    yc = grid.y_centres
    k, w = model.k.interior(), model.omega.interior()
    d_row = yc - 0.0213
    cols = slice(12, 28)   # cells with centres inside the slab's x range, away from its ends
    first = int(np.nonzero(d_row > 0)[0][0])          # the first fluid row; its centre is within one cell (4e-3)
    assert 0 < d_row[first] <= 4e-3 < d_row[first + 1]
    kk, d = k0[first, cols], d_row[first]   # the hold uses the step's starting k
    expect = np.sqrt((6 * nu / (0.075 * d * d)) ** 2 + (np.sqrt(kk) / (0.09 ** 0.25 * 0.41 * d)) ** 2)
    np.testing.assert_allclose(w[first, cols], expect, rtol=1e-6)
    # their eddy viscosity is k / omega, not cut by the limiter a1 k / (S F2) on a strain rate that spans the wall
    np.testing.assert_allclose(sim.nu.numpy()[g + first, g:g + grid.nx][cols] - nu, kk / expect, rtol=1e-9)
    assert 0.05 * d / nu > 10.8
    production = 0.05 ** 2 * 0.09 ** 0.25 * np.sqrt(kk) / (0.41 * d)
    np.testing.assert_allclose(model.k.source.numpy()[g + first, g:g + grid.nx][cols], production, rtol=1e-4)
    np.testing.assert_allclose(k[first - 1, cols], k0[first, cols], rtol=1e-12)   # the solid row under it
    np.testing.assert_allclose(w[first - 1, cols], w0[first, cols], rtol=1e-12)
    assert np.all(w[first - 1, cols] > 0.1 * expect)   # Menter's value would be 1e-2 of it here
    assert np.all(np.isfinite(sim.nu.numpy()[g:g + grid.ny, g:g + grid.nx]))
    sim2, _, _ = _slab_flow(nu=1e-6)
    model2 = KOmegaSST(sim2, 1e-3, 10.0, body_walls="resolved")
    model2.advance(1e-4)
    assert np.all(np.abs(model2.k.interior()[first - 1, cols]) < 1e-20)   # held at 0 (to 1e-30 per unit dt)
    assert sim2.bodies[0].wall_law is None and sim.bodies[0].wall_law == nu


def test_the_equilibrium_wall_produces_k_at_the_log_layers_rate_whatever_k_is():
    """``body_walls="equilibrium"`` on the slab (first fluid cells at y+ 35 on Spalding's profile, u_tau 0.05):
    those cells produce k at the law's rate tau_w du/dn = u_tau^3 / (kappa d), the same for the freestream-like
    k = 1e-7 as for k = u_tau^2 / sqrt(beta*), where the wall function's production (u_tau^2 beta*^(1/4) sqrt(k)
    / (kappa d) under the limiter 10 beta* k omega_log) is 4e-7 of it and the layer stays laminar; at the
    log layer's k = u_tau^2 / sqrt(beta*) (Wilcox 2006, ch. 4) the production equals beta* k omega_log, the
    destruction the cell holds without its sublayer part: the layer settles on the law's eddy viscosity."""
    from bridge.cfd.turbulence import KOmegaSST

    u_tau, beta_star, kappa = 0.05, 0.09, 0.41
    k_log = u_tau ** 2 / np.sqrt(beta_star)
    produced = {}
    for walls in ("equilibrium", "function"):
        for k0 in (1e-7, k_log):
            sim, _, _ = _slab_flow(u_tau=u_tau, nu=1e-6)
            model = KOmegaSST(sim, k0, 10.0, body_walls=walls)   # update(): the sources from the uniform k0
            d_row = sim.grid.y_centres - 0.0213
            first = int(np.nonzero(d_row > 0)[0][0])
            d = d_row[first]
            produced[walls, k0] = model.k.source.numpy()[GHOST + first, GHOST:GHOST + sim.grid.nx][12:28]
    for k0 in (1e-7, k_log):
        np.testing.assert_allclose(produced["equilibrium", k0], u_tau ** 3 / (kappa * d), rtol=1e-4)
    omega_log = np.sqrt(k_log) / (beta_star ** 0.25 * kappa * d)
    np.testing.assert_allclose(produced["equilibrium", k_log], beta_star * k_log * omega_log, rtol=1e-4)
    assert np.all(produced["function", 1e-7] < 1e-6 * produced["equilibrium", 1e-7])
    np.testing.assert_allclose(produced["function", k_log], produced["equilibrium", k_log], rtol=1e-4)


def test_the_wall_function_refuses_what_it_cannot_do():
    from bridge.cfd.turbulence import KOmegaSST

    sim, body, _ = _slab_flow()
    body.order = 2
    with pytest.raises(ValueError, match="interpolation order 1"):
        body.set_wall_function(1e-5)
    body.order = 1
    with pytest.raises(ValueError, match="nu must be > 0"):
        body.set_wall_function(0.0)
    with pytest.raises(ValueError, match="body_walls: one of function, resolved, blended"):
        KOmegaSST(sim, 1e-3, 10.0, body_walls="log")


# --- which grid lines take the wall function (kernels.cfd.square_to_wall) ---------------------------

@wp.kernel
def _square(px: wp.array(dtype=wp.float64), py: wp.array(dtype=wp.float64), pos: wp.vec3d,
            verts: wp.array(dtype=wp.vec2d), horizontal: wp.array(dtype=wp.float64),
            vertical: wp.array(dtype=wp.float64)):
    i = wp.tid()
    horizontal[i] = wp.float64(0.0)
    vertical[i] = wp.float64(0.0)
    if square_to_wall(px[i], py[i], pos, verts, 1, 0):
        horizontal[i] = wp.float64(1.0)
    if square_to_wall(px[i], py[i], pos, verts, 0, 1):
        vertical[i] = wp.float64(1.0)


def _lines_square(verts, points, pose=(0.0, 0.0, 0.0)):
    pts = np.asarray(points, float)
    v = wp.array(np.asarray(verts, float), dtype=wp.vec2d, device="cpu")
    h, vv = _run(_square, len(pts), [pts[:, 0], pts[:, 1], wp.vec3d(*pose), v], 2)
    return h.astype(bool), vv.astype(bool)


def test_the_wall_function_takes_only_lines_that_meet_the_wall_nearly_square():
    """A wedge like the deck's trailing edge (panels at about 28 degrees to x): a vertical line meets a
    panel within 45 degrees of its normal, a horizontal one does not (there the component across the line
    is mostly the normal velocity, and the wall law on it diverged at the trailing edge, docs/aero.md). Past
    the tip the normal is the direction from the corner. A quarter turn of the body swaps the two lines."""
    wedge = [[0.0, -0.1], [0.2, 0.0], [0.0, 0.1]]        # tip at (0.2, 0), panels at 26.6 degrees
    points = [[0.1, 0.06],     # above the upper panel (normal 63.4 degrees from x)
              [0.1, -0.06],    # below the lower one
              [0.3, 0.01],     # past the tip, nearly on the line of symmetry: the corner's direction is ~x
              [0.22, 0.05]]    # past the tip, steeply above it: the corner's direction is ~68 degrees from x
    h, v = _lines_square(wedge, points)
    np.testing.assert_array_equal(h, [False, False, True, False])
    np.testing.assert_array_equal(v, [True, True, False, True])
    # the body turned by 90 degrees (pose theta) with the points turned with it: the roles swap
    c, s = 0.0, 1.0
    turned = [[c * x - s * y, s * x + c * y] for x, y in points]
    h2, v2 = _lines_square(wedge, turned, pose=(0.0, 0.0, np.pi / 2))
    np.testing.assert_array_equal(h2, v)
    np.testing.assert_array_equal(v2, h)
