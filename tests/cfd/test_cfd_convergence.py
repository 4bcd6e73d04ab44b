"""Observed order of accuracy on the Taylor-Green vortex (exact solution), every advection scheme."""

import numpy as np
import pytest
from cfd_helpers import advance, loglog_slope, taylor_green, taylor_green_exact

from bridge.cfd.advection import SCHEMES

NU = 0.01  # viscous limit stays far below the CFL step on all three grids


@pytest.mark.parametrize("scheme", sorted(SCHEMES))
def test_space_time_order_taylor_green(scheme):
    """h and dt refined together (dt = 0.4 h / U): error O(h^2 + dt^2) -> slope >= 1.8."""
    T = 0.5
    hs, errs = [], []
    for n in (16, 32, 64):
        sim = taylor_green(n, NU, scheme)
        h = sim.grid.dx
        advance(sim, T, 0.4 * h)
        u, v, _ = sim.interior()
        ue, ve, _ = taylor_green_exact(sim.grid, NU, T)
        errs.append(np.sqrt(0.5 * (np.mean((u - ue) ** 2) + np.mean((v - ve) ** 2))))
        hs.append(h)
    assert loglog_slope(hs, errs) >= 1.8, (scheme, errs)


@pytest.mark.parametrize("scheme", sorted(SCHEMES))
def test_time_order_taylor_green(scheme):
    """Fixed 32^2 grid, dt halved three times, error against a dt/32 solution on the same grid."""
    T = 1.0
    n = 32
    h = np.pi / n
    ref = advance(taylor_green(n, NU, scheme), T, 0.0125 * h).interior()[0]
    dts, errs = [], []
    for c in (0.4, 0.2, 0.1):
        u = advance(taylor_green(n, NU, scheme), T, c * h).interior()[0]
        dts.append(c * h)
        errs.append(np.sqrt(np.mean((u - ref) ** 2)))
    assert loglog_slope(dts, errs) >= 1.8, (scheme, errs)


def test_pressure_converges_taylor_green():
    """Pressure (mean removed) converges too: slope over three grids >= 1.5 (first-order time
    splitting error of the incremental scheme is allowed for p, not for u)."""
    hs, errs = [], []
    for n in (16, 32, 64):
        sim = taylor_green(n, NU, "central")
        advance(sim, 0.5, 0.4 * sim.grid.dx)
        _, _, p = sim.interior()
        pe = taylor_green_exact(sim.grid, NU, 0.5)[2]
        errs.append(np.sqrt(np.mean(((p - p.mean()) - (pe - pe.mean())) ** 2)))
        hs.append(sim.grid.dx)
    assert loglog_slope(hs, errs) >= 1.5, errs
