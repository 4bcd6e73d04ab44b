"""Checks of the k-omega SST model (bridge/cfd/turbulence.py, the 2003 variant); not in the test run.

    python tools/validate_turbulence.py decay                # closed form, first order in dt
    python tools/validate_turbulence.py channel --re-tau 395 # fully developed channel vs the log law
    python tools/validate_turbulence.py plate --nx 200 --t-end 2  # TMR flat plate (about 25 min)
    python tools/validate_turbulence.py ibplate --dy 4e-4 --t-end 2.5  # the same plate immersed, wall function
    python tools/validate_turbulence.py ogplate --t-end 2.5  # the same plate on the body-fitted wall (17 min)
    python tools/validate_turbulence.py ogplate --walls equilibrium --dy1 4e-4 --growth 1.2 --t-end 2.5
                                                 # ... with the wall function, the first cell at y+ ~ 40
                                                 [--walls blended|equilibrium|resolved]  # other wall treatments

decay: homogeneous turbulence at rest (no walls: F1 = 0, the outer constants), k0 = 0.01, omega0 = 1,
to t = 4 with dt = 0.02, 0.01, 0.005. Closed form: omega = omega0 / (1 + beta_2 omega0 t),
k = k0 (1 + beta_2 omega0 t)^(-beta*/beta_2).

channel: the fully developed plane channel (walls at y = 0 and 2, half-height h = 1, u_tau = 1, nu =
1/Re_tau, driven by dp/dx = -1) as a column of cells: the SST model's k and omega carried by the
library's transport and coefficient kernels on a 4-column grid with no variation in x, the mean
momentum d/dy((nu + nu_t) dU/dy) + 1 = 0 marched implicitly in pseudo-time (a tridiagonal solve per
step; the 2D solver has no periodic sides). Grid: 64 cells across, tanh-clustered (first cell centre
at y+ = 1), marched to t = 8 h/u_tau (steady: the wall shear balances the driving gradient to 0.1 %).
Reported: U+ against y+ beside the log law U+ = ln(y+)/0.41 + 5.0 (TMR's constants), U_b+ and U_c+.
plate: TMR's 2D zero-pressure-gradient flat plate at Re 5e6 per unit length, the plate from x = 0
(the inflow, at the leading edge) to 2, top at y = 1 (slip), TMR's freestream (k = 2.25e-7 U^2,
nu_t/nu = 0.009), the first cell ``--dy1`` high (5e-6: y+ ~ 0.5 at x = 0.97) growing by ``--growth``,
``--nx`` uniform cells along x, the laminar solver with nu + nu_t from the model each step, to
``--t-end`` (in L/U). Reported: c_f at x = 0.97008 against TMR's 0.00271-0.00272 and the velocity
profile there in wall units; c_f(x) and the profile as plate_nx<N>.png beside ``--out``.
ibplate: the same plate (Re 5e6 per unit length, TMR's freestream) as an immersed body with
Spalding's wall function (bridge/cfd/turbulence.py): a plate from x = 0 to 2, ``6 dy`` thick with
wedge ends 0.05 long, in a stream from x = -0.5 to 2.5 between slip walls at y = +-1, cells 0.01 long
and ``--dy`` high at the plate (stretching by 1.1 beyond 4 cells of it), both sides turbulent. c_f(x)
on the upper side comes from the wall law through the velocity of the first u-face row more than 1.5
dy above the wall (as the wall function sees it); reported: c_f at x = 0.97 against TMR's resolved
0.00271-0.00272, its y+, and the drag force beside the friction integrated from c_f(x) on both sides.
ogplate: the same plate on the body-fitted wall (bridge/cfd/curvilinear_sst.py: SST resolved to the wall on an
O-grid): a plate 2 long and ``--thickness`` thick (0.02: 1 % of its length) with semi-elliptic ends (axes 4
thicknesses by one), the leading edge at x = 0, in a uniform stream (the O-grid's outer boundary ``--outer`` from
the wall, default 1 as TMR's top boundary; the freestream's k and omega there, which decay on their way to the
plate), ``--around`` wall nodes, the first cell ``--dy1`` high growing by ``--growth``; ``--walls equilibrium``
takes Spalding's wall function (bridge/cfd/curvilinear_sst.py) for a first cell in the log layer instead of the
resolved wall (default). Reported as plate's: c_f at x = 0.97008 on the upper side against TMR's 0.00271-0.00272.
Results are appended to ``--out`` as JSON lines.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.linalg import solve_banded

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import warp as wp  # noqa: E402

from bridge.cfd import BoundaryConditions, CartesianGrid, FlowConfig, Simulation  # noqa: E402
from bridge.cfd.grids import GHOST  # noqa: E402
from bridge.cfd.turbulence import KOmegaSST  # noqa: E402

KAPPA, B = 0.41, 5.0
BETA_STAR, BETA_2 = 0.09, 0.0828


def decay(dts=(0.02, 0.01, 0.005), t_end=4.0, k0=0.01, omega0=1.0):
    grid = CartesianGrid.uniform(8, 8, (0.0, 1.0), (0.0, 1.0))
    omega_exact = omega0 / (1 + BETA_2 * omega0 * t_end)
    k_exact = k0 * (1 + BETA_2 * omega0 * t_end) ** (-BETA_STAR / BETA_2)
    rows = []
    for dt in dts:
        sim = Simulation(grid, FlowConfig(nu=1e-3, threads=1, bc=BoundaryConditions(left="slip", right="slip")))
        model = KOmegaSST(sim, k0, omega0)
        for _ in range(int(round(t_end / dt))):
            sim.step(dt)   # the fluid at rest; the step advances the model
        rows.append({"dt": dt, "k_error": float(model.k.interior().mean() / k_exact - 1),
                     "omega_error": float(model.omega.interior().mean() / omega_exact - 1),
                     "spread": float(np.ptp(model.k.interior()))})
    return {"case": "SST decay", "t_end": t_end, "k_exact": k_exact, "omega_exact": omega_exact, "runs": rows}


def channel(re_tau=395.0, n=64, stretch=2.0, t_end=8.0, progress=None):
    """The column channel (module doc); returns (y centres, U, u_tau from the wall shear, nu, model)."""
    nu = 1.0 / re_tau
    y = 1 - np.tanh(stretch * (1 - 2 * np.linspace(0.0, 1.0, n + 1))) / np.tanh(stretch)
    grid = CartesianGrid(np.linspace(0.0, 0.1, 5), y)
    sim = Simulation(grid, FlowConfig(nu=nu, threads=1, bc=BoundaryConditions(left="slip", right="slip",
                                                                              bottom="noslip", top="noslip")))
    g, yc, dy = GHOST, grid.y_centres, grid.dy
    # start: Reichardt's profile and an equilibrium-like k, omega (any reasonable start converges)
    yw = np.minimum(yc, 2 - yc) * re_tau
    u = np.log(1 + KAPPA * yw) / KAPPA + 7.8 * (1 - np.exp(-yw / 11) - yw / 11 * np.exp(-yw / 3))
    k = (1 - np.exp(-yw / 20)) ** 2 / np.sqrt(BETA_STAR) + 1e-6
    omega = np.sqrt(k) / (BETA_STAR ** 0.25 * KAPPA * np.minimum(yc, 2 - yc))
    model = KOmegaSST(sim, 1e-6, 1.0)
    model.k.set(np.repeat(k[:, None], 4, 1))
    model.omega.set(np.repeat(omega[:, None], 4, 1))
    hu = sim.u.numpy()   # the flow's u, a view on the CPU
    dc = np.concatenate(([yc[0] - y[0]], np.diff(yc), [y[-1] - yc[-1]]))   # centre-to-centre (wall: to the wall)
    t, steps = 0.0, 0
    while t < t_end:
        hu[g:g + n, :] = u[:, None]
        model.update()
        dt = model.stable_dt()
        nu_eff = sim.nu.numpy()[g:g + n, g]
        nf = np.concatenate(([nu_eff[0]], 0.5 * (nu_eff[1:] + nu_eff[:-1]), [nu_eff[-1]]))
        a = nf / dc
        bands = np.zeros((3, n))
        bands[0, 1:] = -a[1:-1]
        bands[1] = dy / dt + a[:-1] + a[1:]
        bands[2, :-1] = -a[1:-1]
        u = solve_banded((1, 1), bands, dy / dt * u + dy * 1.0)
        model.k.advance(dt)
        model.omega.advance(dt)
        t += dt
        steps += 1
        if progress and steps % 5000 == 0:
            progress(t, t_end)
    u_tau = float(np.sqrt(nu_eff[0] * u[0] / (yc[0] - y[0])))
    return yc, u, u_tau, nu, model, steps


def channel_report(re_tau=395.0, t_end=8.0):
    t0 = time.perf_counter()

    def progress(t, t_end):
        print(f"  t = {t:.2f} of {t_end:g} h/u_tau", file=sys.stderr, flush=True)

    yc, u, u_tau, nu, model, steps = channel(re_tau, t_end=t_end, progress=progress)
    half = yc < 1
    yp, up = yc[half] * u_tau / nu, u[half] / u_tau
    log = np.log(yp) / KAPPA + B
    band = (yp >= 30) & (yp <= 100)
    dy = model.sim.grid.dy
    return {"case": "SST channel", "re_tau": re_tau, "cells_across": int(yc.size), "t_end": t_end,
            "steps": steps, "wall_s": time.perf_counter() - t0, "u_tau_from_wall_shear": u_tau,
            "U_b+": float(np.sum(u * dy) / 2 / u_tau), "U_c+": float(up.max()),
            "y+": yp.tolist(), "U+": up.tolist(),
            "log_law_deviation_30_100": float(np.max(np.abs(up[band] / log[band] - 1))),
            "first_cell": {"y+": float(yp[0]), "U+": float(up[0])}}


def plate_faces(dy1: float, growth: float, height: float) -> np.ndarray:
    """Faces from a wall at 0: first cell dy1, each next one ``growth`` times taller, the last cut to
    end at ``height``."""
    faces, h = [0.0], dy1
    while faces[-1] + h < height:
        faces.append(faces[-1] + h)
        h *= growth
    if height - faces[-1] < 0.3 * h / growth:
        faces.pop()
    faces.append(height)
    return np.array(faces)


def plate(nx=200, dy1=5e-6, growth=1.12, t_end=3.0, reynolds=5e6, threads=2, progress=None):
    """TMR's 2D zero-pressure-gradient flat plate (module doc): returns the flow, the model, the skin
    friction along the plate (x of the u-faces, c_f) and c_f at x = 0.97 every 0.25 L/U."""
    nu = 1.0 / reynolds
    grid = CartesianGrid(np.linspace(0.0, 2.0, nx + 1), plate_faces(dy1, growth, 1.0))
    bc = BoundaryConditions(left="inflow", right="outflow", bottom="noslip", top="slip", u_inf=1.0)
    sim = Simulation(grid, FlowConfig(nu=nu, cfl=0.5, fourier=0.2, threads=threads, bc=bc))
    k_inf = 9e-9 / 0.2 ** 2                # TMR: k = 9e-9 a^2 at M = 0.2, in units of U^2
    model = KOmegaSST(sim, k_inf, k_inf / (0.009 * nu))   # TMR: nu_t / nu = 0.009 in the freestream
    sim.set_state(u=1.0)
    model.update()

    def skin_friction():   # c_f = 2 nu du/dy at the wall along the plate (the u-faces of the first row)
        return 2 * nu * sim.u.numpy()[GHOST, GHOST:GHOST + nx + 1] / grid.y_centres[0]

    history, next_mark = [], 0.25
    while sim.t < t_end:
        dt = sim.stable_dt()   # the flow's limit and its model's
        sim.step(dt)   # and its SST model
        if sim.t >= next_mark:   # c_f at x = 0.97 every 0.25 L/U: how settled the plate is
            history.append((float(sim.t), float(np.interp(0.97008, grid.x_faces, skin_friction()))))
            next_mark += 0.25
        if progress and sim.n_steps % 2000 == 0:
            u = sim.u.numpy()[GHOST, GHOST:GHOST + nx + 1]
            if not np.isfinite(u).all():
                raise FloatingPointError(f"plate: non-finite velocity at t = {sim.t}")
            progress(sim.t, t_end)
    return sim, model, grid.x_faces, skin_friction(), history


def spalding_uplus_from_re(re_y: np.ndarray) -> np.ndarray:
    """u+ = U / u_tau of points moving at U at distance y from a wall, from re_y = U y / nu, on Spalding's
    law (kernels/wall_law.py has the formula; here a dense table, independent of the kernels)."""
    up = np.linspace(1e-6, 60.0, 600_001)
    z = KAPPA * up
    yp = up + np.exp(-KAPPA * B) * (np.exp(z) - 1 - z - z * z / 2 - z ** 3 / 6)
    return np.interp(re_y, up * yp, up)


def ibplate(dy=4e-4, dx=0.01, t_end=2.5, reynolds=5e6, threads=2, progress=None, body_walls="function"):
    """The flat plate as an immersed body with the wall function (module doc; ``body_walls``: KOmegaSST's, the
    wall function everywhere, "blended" or "equilibrium"): returns a report dict."""
    from bridge.cfd import Polygon, Stationary, stretched_faces

    t0 = time.perf_counter()
    nu = 1.0 / reynolds
    half = 3 * dy                                   # the plate is 6 dy thick
    x = np.arange(-0.5, 2.5 + 0.5 * dx, dx)
    grid = CartesianGrid(x, stretched_faces(-1.0, 1.0, (-half - 4 * dy, half + 4 * dy), dy, 1.1))
    bc = BoundaryConditions(left="inflow", right="outflow", bottom="slip", top="slip", u_inf=1.0)
    sim = Simulation(grid, FlowConfig(nu=nu, cfl=0.5, fourier=0.2, threads=threads, bc=bc))
    w = 0.05
    sim.add_body(Polygon(np.array([[0, 0], [w, -half], [2 - w, -half], [2, 0], [2 - w, half], [w, half]])),
                 Stationary())
    k_inf = 9e-9 / 0.2 ** 2
    model = KOmegaSST(sim, k_inf, k_inf / (0.009 * nu), body_walls=body_walls)
    sim.set_state(u=1.0)
    model.update()
    yc = grid.y_centres
    row = int(np.nonzero(yc > half + 1.5 * dy)[0][0])
    d_ref = yc[row] - half
    xu = grid.x_faces
    on = (xu > w) & (xu < 2 - w)

    def skin_friction():
        u = sim.u.numpy()[GHOST + row, GHOST:GHOST + grid.nx + 1]
        up = spalding_uplus_from_re(np.maximum(u, 0.0) * d_ref / nu)
        u_tau = np.where(up > 0, np.maximum(u, 0.0) / np.maximum(up, 1e-30), 0.0)
        return 2 * u_tau ** 2, d_ref * u_tau / nu

    history, next_mark = [], 0.25
    while sim.t < t_end:
        dt = sim.stable_dt()   # the flow's limit and its model's
        sim.step(dt)   # and its SST model
        if sim.t >= next_mark:
            cf, _ = skin_friction()
            history.append((float(sim.t), float(np.interp(0.97008, xu, cf)), float(sim.last_force[0][0])))
            next_mark += 0.25
            if not np.isfinite(cf).all():
                raise FloatingPointError(f"ibplate: non-finite velocity at t = {sim.t}")
            if progress:
                progress(sim.t, t_end)
    cf, yp = skin_friction()
    friction = 2 * np.trapezoid(np.where(on, cf, 0.0), xu) * 0.5   # both sides, rho U^2 / 2 = 1/2
    return {"case": f"SST flat plate, immersed, walls: {body_walls}", "dy": dy, "dx": dx, "nx": grid.nx,
            "ny": grid.ny,
            "t_end": t_end, "steps": sim.n_steps, "wall_s": time.perf_counter() - t0,
            "cf_0.97": float(np.interp(0.97008, xu, cf)), "band": [0.00271, 0.00272],
            "y+_0.97": float(np.interp(0.97008, xu, yp)), "reference_height": float(d_ref),
            "drag_force": float(sim.last_force[0][0]), "friction_from_cf": float(friction),
            "cf_0.97_history": history, "x": xu[on].tolist(), "cf": cf[on].tolist()}


def plate_report(nx, dy1, growth, t_end):
    t0 = time.perf_counter()

    def progress(t, t_end):
        print(f"  t = {t:.3f} of {t_end:g}", file=sys.stderr, flush=True)

    sim, model, x, cf, history = plate(nx, dy1, growth, t_end, progress=progress)
    g = sim.grid
    cf97 = float(np.interp(0.97008, x, cf))
    u_tau = np.sqrt(0.5 * cf97)
    # the velocity profile at the u-face column nearest x = 0.97 in wall units
    i = int(np.argmin(np.abs(x - 0.97008)))
    u_col = sim.u.numpy()[GHOST:GHOST + g.ny, GHOST + i]
    yp, up = g.y_centres * u_tau * 5e6, u_col / u_tau
    band = (yp >= 30) & (yp <= 300)
    log = np.log(yp) / KAPPA + B
    return {"case": "SST flat plate (TMR)", "nx": g.nx, "ny": g.ny, "dy1": dy1, "growth": growth, "t_end": t_end,
            "steps": sim.n_steps, "wall_s": time.perf_counter() - t0, "cf_0.97": cf97, "band": [0.00271, 0.00272],
            "first_cell_y+_0.97": float(yp[0]), "first_cell_U+_0.97": float(up[0]),
            "cf_0.97_history": history,
            "log_law_deviation_30_300": float(np.max(np.abs(up[band] / log[band] - 1))) if band.any() else None,
            "x": x.tolist(), "cf": cf.tolist(), "profile_y+": yp.tolist(), "profile_U+": up.tolist()}


def plate_outline(thickness: float, length: float = 2.0, n_end: int = 60) -> np.ndarray:
    """Counter-clockwise outline of a flat plate from x = 0 to ``length`` (the flat part from one end's
    length, 2 thicknesses, to ``length``) with semi-elliptic ends (nose radius thickness / 8), the leading edge
    at x = 0."""
    a, b = 2.0 * thickness, 0.5 * thickness
    th = np.linspace(0.0, np.pi, n_end + 1)
    phi = np.linspace(0.0, 0.5 * np.pi, n_end // 2 + 1)
    # the trailing end from (length + a, 0) up to (length, b); the leading end from (a, b) round to (a, -b)
    back_top = np.column_stack([length + a * np.cos(phi), b * np.sin(phi)])
    front = np.column_stack([a - a * np.sin(th), b * np.cos(th)])
    back_bottom = np.column_stack([length + a * np.cos(phi[::-1]), -b * np.sin(phi[::-1])])
    return np.vstack([back_top, front, back_bottom[:-1]])


def ogplate(around=600, dy1=5e-6, growth=1.12, thickness=0.02, outer=1.0, t_end=3.0, reynolds=5e6, cfl=0.8,
            progress=None, walls="resolved"):
    """TMR's flat plate on the body-fitted wall (module doc): returns the flow, its model, x and c_f along the
    upper side, c_f at x = 0.97 every 0.25 L/U and the grid's quality."""
    from bridge.cfd.curvilinear import CurvilinearFlow, CurvilinearGrid, Farfield
    from bridge.cfd.curvilinear_sst import CurvilinearSST
    from bridge.cfd.motion import Stationary
    from bridge.cfd.ogrid import o_grid

    nu = 1.0 / reynolds
    og = o_grid(plate_outline(thickness), around, dy1, growth, outer, corner_refinement=20.0)
    grid = CurvilinearGrid(og.x, og.y)
    flow = CurvilinearFlow(grid, nu, Stationary(), Farfield(1.0, 0.0), cfl=cfl)
    flow.set_uniform_flow(1.0, 0.0)
    k_inf = 9e-9 / 0.2 ** 2                # TMR: k = 9e-9 a^2 at M = 0.2, in units of U^2
    model = CurvilinearSST(flow, k_inf, k_inf / (0.009 * nu), walls=walls)   # TMR: nu_t / nu = 0.009 outside
    xm, ym = grid.xmj[0, :, 0], grid.xmj[0, :, 1]
    upper = (ym > 0) & (xm > 0.2) & (xm < 1.9)
    order = np.argsort(xm[upper])

    def skin_friction():   # c_f = 2 nu du/dn along the upper side (tangent: +x there)
        su, _ = flow.wall_shear(flow.t)
        return xm[upper][order], (2 * nu * su[upper])[order]

    history, next_mark = [], 0.25
    while flow.t < t_end:
        flow.step()
        if flow.t >= next_mark:
            x, cf = skin_friction()
            history.append((float(flow.t), float(np.interp(0.97008, x, cf))))
            next_mark += 0.25
            if not np.isfinite(cf).all():
                raise FloatingPointError(f"ogplate: non-finite skin friction at t = {flow.t}")
            if progress:
                progress(flow.t, t_end, history[-1][1], flow.n_steps)
    x, cf = skin_friction()
    return flow, model, x, cf, history, og.quality()


def ogplate_report(around, dy1, growth, thickness, outer, t_end, cfl, walls="resolved"):
    t0 = time.perf_counter()

    def progress(t, t_end, cf, n):
        print(f"  t = {t:.3f} of {t_end:g}: c_f(0.97) = {cf:.6f} ({n} steps, {time.perf_counter() - t0:.0f} s)",
              file=sys.stderr, flush=True)

    flow, model, x, cf, history, quality = ogplate(around, dy1, growth, thickness, outer, t_end, cfl=cfl,
                                                    progress=progress, walls=walls)
    g = flow.grid
    cf97 = float(np.interp(0.97008, x, cf))
    u_tau = np.sqrt(0.5 * cf97)
    i = int(np.argmin(np.abs(g.xmj[0, :, 0] - 0.97008) + 10 * (g.xmj[0, :, 1] < 0)))
    yp = model.wall_distance[:, i] * u_tau / flow.nu
    up = flow.u[:, i] / u_tau
    band = (yp >= 30) & (yp <= 300)
    log = np.log(yp) / KAPPA + B
    return {"case": f"SST flat plate (TMR), body-fitted wall, walls: {walls}", "around": g.ni, "rings": g.nj,
            "dy1": dy1,
            "growth": growth, "thickness": thickness, "outer": outer, "t_end": t_end, "cfl": cfl,
            "steps": flow.n_steps, "wall_s": time.perf_counter() - t0, "cf_0.97": cf97, "band": [0.00271, 0.00272],
            "first_cell_y+_0.97": float(yp[0]), "cf_0.97_history": history, "grid_quality": quality.summary(),
            "log_law_deviation_30_300": float(np.max(np.abs(up[band] / log[band] - 1))) if band.any() else None,
            "nx": g.ni, "ny": g.nj,
            "x": x.tolist(), "cf": cf.tolist(), "profile_y+": yp.tolist(), "profile_U+": up.tolist()}


def _plot_plate(r, stem: Path) -> None:
    """c_f(x) and the profile at x = 0.97 in wall units, as a PNG beside the results."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
    ax[0].plot(r["x"], r["cf"], label="SST-2003")
    ax[0].errorbar([0.97008], [0.002715], yerr=[[0.000005], [0.000005]], fmt="o", color="k",
                   label="TMR, incompressible codes (0.00271-0.00272)")
    ax[0].set(xlabel="x", ylabel="c_f", ylim=(0.0015, 0.006), title=f"flat plate, Re 5e6, {r['nx']} x {r['ny']}")
    ax[0].legend()
    yp = np.array(r["profile_y+"])
    ax[1].semilogx(yp, r["profile_U+"], "o-", ms=3, label="SST-2003, x = 0.97")
    ax[1].semilogx(yp, np.log(yp) / KAPPA + B, "--", label="log law (0.41, 5.0)")
    ax[1].semilogx(yp[yp < 12], yp[yp < 12], ":", label="U+ = y+")
    ax[1].set(xlabel="y+", ylabel="U+", xlim=(0.3, 1e4), ylim=(0, 35))
    ax[1].legend()
    stem.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(stem.with_suffix(".png"), dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", choices=["decay", "channel", "plate", "ibplate", "ogplate"])
    ap.add_argument("--around", type=int, default=600, help="ogplate: wall nodes around the plate")
    ap.add_argument("--thickness", type=float, default=0.02, help="ogplate: the plate's thickness (length 2)")
    ap.add_argument("--outer", type=float, default=1.0, help="ogplate: the O-grid's reach from the wall")
    ap.add_argument("--cfl", type=float, default=0.8, help="ogplate: the convective Courant number")
    ap.add_argument("--dy", type=float, default=4e-4, help="ibplate: cell height at the plate (4e-4: y+ ~ 100)")
    ap.add_argument("--walls", choices=KOmegaSST.BODY_WALLS, default=None,
                    help="ibplate: Spalding's wall function everywhere (default), blended with the linear profile "
                         "where the layer is not turbulent, with the log layer's own k production so the layer is "
                         "turbulent from the front, or no wall law (bridge.cfd.KOmegaSST's body_walls); ogplate: "
                         "resolved (default) or equilibrium")
    ap.add_argument("--nx", type=int, default=200, help="plate: cells along x in [0, 2]")
    ap.add_argument("--dy1", type=float, default=5e-6, help="plate: first cell height (Re 5e6: y+ ~ 1 is 5e-6)")
    ap.add_argument("--growth", type=float, default=1.12, help="plate: cell growth away from the wall")
    ap.add_argument("--re-tau", type=float, default=395.0)
    ap.add_argument("--t-end", type=float, default=8.0, help="channel: pseudo-time in h/u_tau")
    ap.add_argument("--out", default="out/validation_turbulence.jsonl")
    args = ap.parse_args(argv)
    if not 100 <= args.re_tau <= 2000:
        ap.error(f"--re-tau: {args.re_tau} not allowed; allowed: 100 .. 2000 (64 cells across)")
    if not args.t_end > 0:
        ap.error(f"--t-end: {args.t_end} not allowed; allowed: > 0")
    wp.config.quiet = True
    if args.case == "decay":
        r = decay()
    elif args.case == "channel":
        r = channel_report(args.re_tau, args.t_end)
    elif args.case == "ibplate":
        if not 5e-5 <= args.dy <= 5e-3:
            ap.error(f"--dy: {args.dy} not allowed; allowed: 5e-5 .. 5e-3")
        r = ibplate(args.dy, t_end=args.t_end, body_walls=args.walls or "function",
                    progress=lambda t, t_end: print(f"  t = {t:.2f} of {t_end:g}", file=sys.stderr, flush=True))
    elif args.case == "ogplate":
        walls = args.walls or "resolved"
        if walls not in ("resolved", "equilibrium"):
            ap.error(f"--walls: {walls} not allowed with ogplate; allowed: resolved, equilibrium")
        r = ogplate_report(args.around, args.dy1, args.growth, args.thickness, args.outer, args.t_end, args.cfl,
                           walls)
        _plot_plate(r, Path(args.out).with_name(f"ogplate_{args.around}"))
    else:
        r = plate_report(args.nx, args.dy1, args.growth, args.t_end)
        _plot_plate(r, Path(args.out).with_name(f"plate_nx{args.nx}"))
    r["command"] = "python tools/validate_turbulence.py " + " ".join(argv if argv is not None else sys.argv[1:])
    print(json.dumps({k: v for k, v in r.items() if k not in ("y+", "U+", "x", "cf", "profile_y+", "profile_U+")}),
          flush=True)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "a") as fh:
        fh.write(json.dumps(r) + "\n")
    return r


if __name__ == "__main__":
    main()
