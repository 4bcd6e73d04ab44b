"""Small builders shared by the CFD tests (module name unique across test folders: the tests
import it by name) and the devices to run kernel tests on (cuda only when present)."""

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
import warp as wp

from bridge.cfd import BoundaryConditions, CartesianGrid, FlowConfig, Simulation

wp.config.quiet = True

DEVICES = [
    pytest.param("cpu", id="cpu"),
    pytest.param("cuda", id="cuda", marks=[pytest.mark.cuda,
                                           pytest.mark.skipif(not wp.is_cuda_available(), reason="no CUDA device")]),
]

SLIP_BOX = BoundaryConditions(left="slip", right="slip", bottom="slip", top="slip")


def taylor_green(n: int, nu: float, scheme: str, device: str = "cpu", threads: int = 2):
    """Taylor-Green vortex on [0, pi]^2 with slip walls (an exact NS solution there):
    u = sin x cos y F, v = -cos x sin y F, p = (cos 2x + cos 2y) F^2 / 4, F = exp(-2 nu t)."""
    grid = CartesianGrid.uniform(n, n, (0.0, np.pi), (0.0, np.pi))
    sim = Simulation(grid, FlowConfig(nu=nu, advection=scheme, bc=SLIP_BOX, threads=threads), device=device)
    sim.set_state(*taylor_green_exact(grid, nu, 0.0))
    return sim


def taylor_green_exact(grid, nu, t):
    xf, yf, xc, yc = grid.x_faces, grid.y_faces, grid.x_centres, grid.y_centres
    f = np.exp(-2 * nu * t)
    u = np.sin(xf)[None, :] * np.cos(yc)[:, None] * f
    v = -np.cos(xc)[None, :] * np.sin(yf)[:, None] * f
    p = 0.25 * (np.cos(2 * xc)[None, :] + np.cos(2 * yc)[:, None]) * f * f
    return u, v, p


def advance(sim, t_end, cfl_dt):
    """Fixed steps of at most cfl_dt landing exactly on t_end."""
    n = int(np.ceil(t_end / cfl_dt - 1e-9))
    for _ in range(n):
        sim.step(t_end / n)
    return sim


def loglog_slope(h, err):
    return float(np.polyfit(np.log(h), np.log(err), 1)[0])


def load_tool(name: str):
    """Import tools/<name>.py (the tools folder is not a package)."""
    path = Path(__file__).resolve().parents[2] / "tools" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod         # where a dataclass of the tool looks its module up
    spec.loader.exec_module(mod)
    return mod
