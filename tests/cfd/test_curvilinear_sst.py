"""The SST model on the body-fitted O-grid (bridge/cfd/curvilinear_sst.py): its sources and time step against
the closed form of decaying turbulence, the wall's values, the eddy viscosity handed to the flow, and a resumed
run continuing bit for bit.  TMR's flat plate on the body-fitted wall (c_f against the published band):
tools/validate_turbulence.py ogplate (docs/validation.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bridge.cfd import Stationary, run
from bridge.cfd.curvilinear import CurvilinearFlow, CurvilinearGrid, Farfield, polar_grid
from bridge.cfd.curvilinear_sst import CurvilinearSST, first_height_for, sst_terms

K0, W0, BETA_STAR, BETA_2 = 0.01, 1.0, 0.09, 0.0828


def closed_form(t):
    """Homogeneous turbulence at rest, away from walls (F1 = 0: the outer constants): omega = omega0 / (1 + beta_2
    omega0 t), k = k0 (1 + beta_2 omega0 t)^(-beta*/beta_2) (Wilcox 2006, 4.3)."""
    s = 1 + BETA_2 * W0 * t
    return K0 * s ** (-BETA_STAR / BETA_2), W0 / s


def _decay(dt: float, t_end: float = 4.0):
    x, y = polar_grid(1.0, 40.0, 32, 0.05, 1.15)
    flow = CurvilinearFlow(CurvilinearGrid(x, y), 1e-4, Stationary(), Farfield(0.0, 0.0))
    model = CurvilinearSST(flow, K0, W0, ghosts=lambda t: tuple(np.full(flow.grid.xg.shape, v) for v in closed_form(t)))
    while flow.t < t_end - 1e-9:
        flow.step(dt)
    far = model.wall_distance > 10.0   # beyond the reach of the wall's k = 0 (diffusion length ~ 0.2 by t = 4)
    k, w = closed_form(flow.t)
    return max(np.abs(model.k[far] / k - 1).max(), np.abs(model.omega[far] / w - 1).max()), model


def test_decaying_turbulence_follows_the_closed_form_at_first_order_in_the_step():
    (e1, m), (e2, _) = _decay(0.08, 2.0), _decay(0.04, 2.0)
    assert e2 < 1e-4 and 0.9 < math.log2(e1 / e2) < 1.1, (e1, e2)
    assert np.all(m.k[0] < m.k[-1]) and np.all(m.k >= 0)            # the wall's k = 0 reaches the first rings
    assert np.allclose(m.flow.nu_t, m.nu_t) and m.flow._turbulent  # the flow carries the model's nu_t


def test_the_wall_omega_and_the_first_height_rule():
    x, y = polar_grid(0.5, 5.0, 32, 1e-3, 1.2)
    flow = CurvilinearFlow(CurvilinearGrid(x, y), 1e-5, Stationary(), Farfield(1.0, 0.0))
    m = CurvilinearSST(flow, 1e-6, 1.0)
    d1 = m.wall_distance[0]
    assert np.allclose(d1, 5e-4, rtol=0.01)   # the first centre: half the first height (from the 32-gon)
    assert np.allclose(m.omega_wall, 60 * 1e-5 / (0.075 * d1 ** 2))   # Menter 1994
    # White's turbulent plate: y+ = 1 at Re 1e6 on the chord: c_f = 0.026 Re^(-1/7) = 0.003196, y = 1 / (Re u_tau)
    assert first_height_for(1e6) == pytest.approx(1 / (1e6 * math.sqrt(0.026 * 1e6 ** (-1 / 7) / 2)), rel=1e-12)
    with pytest.raises(ValueError, match="reynolds"):
        first_height_for(-1.0)


def test_sst_terms_limit_the_eddy_viscosity_by_the_strain():
    """nu_t = a1 k / max(a1 omega, S F2): in a strong strain next to a wall (F2 = 1) the Bradshaw limit a1 k / S."""
    k, w, d = np.array([1e-2]), np.array([1.0]), np.array([1e-3])
    nu_t, f1, (pk, dk), _ = sst_terms(k, w, np.array([100.0 ** 2]), np.zeros(1), d, 1e-5)
    assert nu_t[0] == pytest.approx(0.31 * 1e-2 / 100.0, rel=1e-9) and f1[0] == pytest.approx(1.0)
    assert pk[0] == pytest.approx(min(nu_t[0] * 1e4, 10 * 0.09 * 1e-2)) and dk[0] == pytest.approx(0.09)


def test_a_resumed_run_continues_bit_for_bit():
    def make():
        x, y = polar_grid(0.5, 5.0, 32, 2e-3, 1.2)
        flow = CurvilinearFlow(CurvilinearGrid(x, y), 1e-4, Stationary(), Farfield(1.0, 0.0))
        flow.set_uniform_flow(1.0)
        CurvilinearSST(flow, 1e-4, 10.0)
        return flow

    a = make()
    run(a, 0.3)
    saved = {k: np.array(v, copy=True) for k, v in a.checkpoint_arrays().items()}
    assert "turbulence/k" in saved
    t, n = a.t, a.n_steps
    run(a, 0.6)
    b = make()
    b.restore_arrays(saved, t, n)
    run(b, 0.6)
    assert np.array_equal(a.u, b.u) and np.array_equal(a.turbulence.omega, b.turbulence.omega)


def _spalding_yplus(up):
    """Spalding's law (Spalding 1961, J. Appl. Mech. 28: 455), kappa 0.41, B 5.0: y+ from u+ in closed form."""
    z = 0.41 * up
    return up + math.exp(-0.41 * 5.0) * (math.exp(z) - 1 - z - z * z / 2 - z ** 3 / 6)


def _wall_function_flow(speed: float, nu: float = 1e-6):
    """A cylinder's O-grid in a uniform stream ``speed`` (no step taken), with the SST wall function."""
    x, y = polar_grid(0.5, 5.0, 64, 2e-3, 1.15)
    flow = CurvilinearFlow(CurvilinearGrid(x, y), nu, Stationary(), Farfield(speed, 0.0))
    flow.set_uniform_flow(speed)
    return flow, CurvilinearSST(flow, 1e-6 * speed ** 2, 1.0, walls="equilibrium")


def test_the_wall_function_gives_spaldings_friction_and_takes_it_into_the_flows_shear():
    flow, m = _wall_function_flow(1.0)
    u_tau, d, nu_w = m.wall_law(0.0)
    g = flow.grid
    speed = np.hypot(flow.u[0], flow.v[0])
    for i in (10, 16, 40):   # the sides: the first cell's point on the law, U / u_tau = u+ at y+ = d u_tau / nu
        up, yp = speed[i] / u_tau[i], d[i] * u_tau[i] / flow.nu
        assert yp > 30 and _spalding_yplus(up) == pytest.approx(yp, rel=1e-9)
    # the flow's wall shear (its force's) is u_tau^2 along the first cell's relative velocity
    su, sv = flow.wall_shear(0.0)
    assert np.allclose(flow.nu * np.hypot(su, sv), u_tau ** 2, rtol=1e-9)
    assert np.allclose(nu_w, u_tau ** 2 * d / speed) and np.all(flow.nu_j[0] == nu_w)
    # in the viscous sublayer the law is u+ = y+: the wall diffusivity is nu and the shear the linear profile's
    slow, m_slow = _wall_function_flow(1e-6)
    u_tau, d, _ = m_slow.wall_law(0.0)
    speed = np.hypot(slow.u[0], slow.v[0])
    assert np.allclose(u_tau * u_tau * d / speed, slow.nu, rtol=1e-6, atol=0.0)   # the law's own, before its floor
    su, _ = slow.wall_shear(0.0)
    assert np.allclose(su, (slow.u[0]) / g.wall_distance[0], rtol=1e-6)


def test_the_wall_function_holds_the_first_cells_omega_and_keeps_k_and_omega_from_the_wall():
    flow, m = _wall_function_flow(1.0)
    run(flow, 0.05)
    k0 = m.k[0].copy()
    flow.step()
    d = flow.grid.wall_distance[0]
    w_vis, w_log = 6 * flow.nu / (0.075 * d ** 2), np.sqrt(k0) / (0.09 ** 0.25 * 0.41 * d)
    # omega held at the blend of the sublayer's and the log layer's, by the k the step started from
    assert np.allclose(m.omega[0], np.hypot(w_vis, w_log), rtol=1e-9)
    assert np.all(m.nu_t[0] > 0) and np.allclose(m.nu_t[0], m.k[0] / m.omega[0])
    # the log layer's production made k grow from the freestream's 1e-6 in the first ring, and no k left
    # through the wall (no flux: k is largest at the wall, not zero there as on a resolved wall)
    assert np.all(m.k[0] > 1e-4) and np.median(m.k[0] / m.k[3]) > 1
    with pytest.raises(ValueError, match="walls"):
        CurvilinearSST(flow, 1e-6, 1.0, walls="function")
