"""The wake behind a heaving thin plate in the CFD, and what its measured speed and growth do to the lift in a
thin-aerofoil model (docs/validation.md, the notes on the plate's rows).

    python tools/validate_aero.py ...          # the derivatives against Theodorsen
    python tools/plate_wake.py --reduced-velocities 4 8 [--quality standard] [--grid overset] [--out DIR]

Theodorsen's flat sheet sheds its wake as a plane vortex sheet that travels at the free-stream speed U and
keeps its strength.  This tool measures both in the CFD: it runs the heave case of ``validate_aero`` with the
aero stage's grids, samples the vorticity of the fixed grid every 1/32 period, integrates it across the wake
(|y| < 1.5 chords) and fits the first harmonic of that circulation per unit length, Gamma_1(x), at every
column 0.2-7 chords behind the trailing edge.  Its phase gives the speed at which the shed vorticity travels,
c(x) = -omega / (d arg Gamma_1 / dx), its modulus how the wake amplifies or damps it.  On the overset pair it
also samples the pressure jump across the plate (1.5 cells off it, on the body grid) and compares its first
harmonic with Theodorsen's chordwise loading from the model below.

The model (``thin_plate_heave``): the plate as N lumped vortices (quarter-panel vortices, three-quarter-panel
collocation), a continuous wake sheet from the trailing edge whose density follows Kelvin's theorem and travels
at a prescribed c(x), optionally scaled by a prescribed gain g(x); the linearised pressure jump
rho (U gamma + d/dt int gamma) gives lift and moment.  With c = U and g = 1 it is Theodorsen's problem: the
derivatives converge to his at about N^-1/2 (the leading edge's square-root singularity; test), so the tool
reports the change that the measured wake makes at the same N, not absolute values.  Writes ``plate_wake.json``
and ``plate_wake.png`` (c(x)/U and |Gamma_1(x)|) into ``--out``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from validate_aero import plate_quality  # noqa: E402

from bridge.aero.forced_motion import ForcedCase  # noqa: E402
from bridge.aero.frequency_response import forced_motion_response  # noqa: E402
from bridge.aero.presets import build_flow, section_polygons  # noqa: E402
from bridge.aero.snapshots import cell_centred  # noqa: E402
from bridge.cfd.grids import GHOST  # noqa: E402
from bridge.cfd.sections import FlatPlate  # noqa: E402
from bridge.flutter.aerodynamics import Theodorsen  # noqa: E402
from bridge.flutter.derivatives import FRF, derivatives_from_frf  # noqa: E402

HEAVE = ("H1", "H4", "A1", "A4")   # the derivatives a heave run gives (B form, h and L down)


# ----------------------------------------------------------------------------------------------------------
# thin-aerofoil model with a prescribed wake

def _sheet_on_points(xc: np.ndarray, X: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Upward velocity at the points ``xc`` (all upstream of X[0]) induced by a clockwise vortex sheet of
    density f, piecewise linear on the nodes X: -1/(2 pi) int f / (xc - X) dX, each segment exactly."""
    X0, X1, f0 = X[:-1], X[1:], f[:-1]
    slope = np.diff(f) / np.diff(X)
    d0, d1 = X0[None, :] - xc[:, None], X1[None, :] - xc[:, None]
    log = np.log(d1 / d0)
    return (f0[None, :] * log + slope[None, :] * ((X1 - X0)[None, :] - d0 * log)).sum(axis=1) / (2 * math.pi)


def _heaving_plate(K: float, wake_speed, wake_gain, panels: int, length: float):
    """The model's solution per unit plate velocity hdot (up): vortex and panel-centre positions and each
    panel's lift, steady (at the vortex) and unsteady (at the centre) parts (rho = U = 1)."""
    edges = np.linspace(-0.5, 0.5, panels + 1)
    dc = np.diff(edges)
    xv, xc, xm = edges[:-1] + 0.25 * dc, edges[:-1] + 0.75 * dc, edges[:-1] + 0.5 * dc
    bound = -1.0 / (2 * math.pi * (xc[:, None] - xv[None, :]))
    s = np.concatenate([[0.0], np.geomspace(1e-7, 1.0, 400), np.arange(1.0, length, 0.005)[1:]])
    X = 0.5 + s
    c = np.ones_like(X) if wake_speed is None else np.asarray(wake_speed(X), dtype=float)
    travel = np.concatenate([[0.0], np.cumsum(0.5 * (1 / c[1:] + 1 / c[:-1]) * np.diff(X))])
    # per unit bound circulation: what left the trailing edge travel(x) ago, -dGamma_b/dt, spread over c
    density = -1j * K * np.exp(-1j * K * travel) / c
    if wake_gain is not None:
        density = density * np.asarray(wake_gain(X))
    taper = np.where(s > 0.8 * length, np.cos(0.5 * math.pi * (s - 0.8 * length) / (0.2 * length)) ** 2, 1.0)
    matrix = bound + _sheet_on_points(xc, X, density * taper)[:, None]
    gamma = np.linalg.solve(matrix, np.ones(panels, dtype=complex))   # plate velocity hdot = 1 (up)
    return xv, xm, dc, gamma, 1j * K * dc * np.cumsum(gamma)           # Katz & Plotkin's pressure jump


def thin_plate_heave(K: float, wake_speed=None, wake_gain=None, panels: int = 400,
                     length: float = 200.0) -> dict:
    """H1*, H4*, A1*, A4* of a heaving plate (chord 1 from -0.5 to 0.5, U = 1, omega = K) whose wake travels
    at ``wake_speed(x)`` (default U) with its Kelvin density scaled by ``wake_gain(x)`` (default 1); the wake
    is ``length`` chords long, tapered over its last fifth."""
    xv, xm, _, steady, unsteady = _heaving_plate(K, wake_speed, wake_gain, panels, length)
    lift = steady.sum() + unsteady.sum()                                # up
    moment = -(steady * xv).sum() - (unsteady * xm).sum()              # nose-up, about mid-chord
    per_h_lift, per_h_moment = lift * 1j * K, -moment * 1j * K         # per unit h down (L down, M nose-up)
    return {"H1": 2 * per_h_lift.imag / K**2, "H4": 2 * per_h_lift.real / K**2,
            "A1": 2 * per_h_moment.imag / K**2, "A4": 2 * per_h_moment.real / K**2}


def thin_plate_loading(K: float, panels: int = 400) -> tuple[np.ndarray, np.ndarray, complex]:
    """Theodorsen's problem in the model: panel centres, the pressure jump (lift per chord, up) there and the
    lift, all per unit plate velocity hdot (up), first harmonics."""
    _, xm, dc, steady, unsteady = _heaving_plate(K, None, None, panels, 200.0)
    return xm, (steady + unsteady) / dc, complex(steady.sum() + unsteady.sum())


# ----------------------------------------------------------------------------------------------------------
# the CFD's wake

def wake_harmonic(t: np.ndarray, x: np.ndarray, circulation: np.ndarray, K: float) -> tuple[np.ndarray, np.ndarray]:
    """First harmonic Gamma_1(x) of ``circulation`` (samples x columns; circulation ~ Re(Gamma_1 e^{iKt}))
    by least squares over the samples, and the speed c(x) = -K / (d arg Gamma_1 / dx) at which it travels."""
    first = _harmonic(t, circulation, K)
    return first, -K / np.gradient(np.unwrap(np.angle(first)), x)


def sample_wake(reduced_velocity: float, quality: str, grid: str, periods: int = 7, say=print) -> dict:
    """Run the thin plate's heave case for ``periods`` periods; from the third on, every 1/32 period, the
    vorticity of the fixed grid integrated over |y| < 1.5 across the columns 0.7-7.5 chords downstream of the
    mid-chord.  Returns the samples and the force record."""
    K = 2 * math.pi / reduced_velocity
    T = 2 * math.pi / K
    q = plate_quality(quality, grid)
    cells_across = 0.02 * q.grid.cells_per_chord / q.grid.dy_over_dx
    if cells_across < 2.0:   # as the aero stage warns: the immersed boundary barely sees the plate
        say(f"WARNING: the 2 % plate is {cells_across:.1f} cells thick on the {quality!r} grid (fewer than 2): "
            "its loads and wake are not to be trusted")
    polys = [section_polygons(FlatPlate(1.0, 0.02))[0]]
    case = ForcedCase.thesis("heave", K)
    flow = build_flow(q, polys, case)
    fixed = flow.simulations[0]
    g = GHOST
    xc, yc = np.asarray(fixed.grid.x_centres), np.asarray(fixed.grid.y_centres)
    cols, rows = np.where((xc > 0.7) & (xc < 7.5))[0], np.where(np.abs(yc) < 1.5)[0]
    dy = np.gradient(yc)[rows]
    # overset: the pressure jump across the plate, p on the second fluid row below minus above (the body grid
    # moves with the plate, so the rows stay put; the single grid's plate crosses its rows: not sampled)
    body = getattr(flow, "body", None)
    if body is not None:
        bx, by = np.asarray(body.grid.x_centres), np.asarray(body.grid.y_centres)
        above, below = (int(np.argmin(np.abs(by - y))) for y in (0.01 + 1.5 * (by[1] - by[0]),
                                                                   -0.01 - 1.5 * (by[1] - by[0])))
        gap = 0.5 * (by[above] - by[below]) - 0.01   # row to surface: the jump there is 2 gap rho hddot larger
        chord = np.where(np.abs(bx) < 0.5)[0]
    times, columns, jumps, record = [], [], [], []
    next_sample, t0, reported = 3 * T, time.perf_counter(), 0
    while flow.t < periods * T:
        flow.step(flow.stable_dt())
        fx, fy, mz = flow.last_force
        record.append((flow.t, fy, -mz, case.displacement(flow.t)))
        if flow.t >= next_sample:
            vort = cell_centred(fixed.grid, fixed.u.numpy(), fixed.v.numpy())[2]
            columns.append((vort[np.ix_(rows, cols)] * dy[:, None]).sum(axis=0))
            if body is not None:
                p = body.p.numpy()
                jumps.append(p[g + below, g + chord] - p[g + above, g + chord])
            times.append(flow.t)
            next_sample += T / 32
        if int(10 * flow.t / (periods * T)) > reported:
            reported = int(10 * flow.t / (periods * T))
            say(f"U/(fB) = {reduced_velocity:g} heave: t = {flow.t:.2f} of {periods * T:.2f} ({10 * reported} %), "
                f"{time.perf_counter() - t0:.0f} s")
    whole = np.array(times) < periods * T - T / 64   # 32 samples a period over whole periods, no end sample twice
    times, columns = list(np.array(times)[whole]), list(np.array(columns)[whole])
    jumps = list(np.array(jumps)[whole]) if jumps else jumps
    return {"K": K, "T": T, "t": np.array(times), "x": xc[cols], "circulation": np.array(columns),
            "record": np.array(record), "cells": flow.describe(),
            "jump": np.array(jumps) if body is not None else None, "jump_x": bx[chord] if body is not None else None,
            "jump_gap": gap if body is not None else None}


def _harmonic(t: np.ndarray, y: np.ndarray, K: float):
    """First harmonic Y_1 of y ~ Re(Y_1 e^{iKt}) + mean, least squares (y: samples or samples x columns)."""
    basis = np.column_stack([np.ones_like(t), np.cos(K * t), np.sin(K * t)])
    coef = np.linalg.lstsq(basis, y, rcond=None)[0]
    return coef[1] - 1j * coef[2]


def loading_against_theodorsen(sample: dict, panels: int = 400) -> dict:
    """The sampled pressure jump's first harmonic per unit plate velocity against the model's Theodorsen
    loading at the same x, and the lift from the forces against the model's lift."""
    K, T = sample["K"], sample["T"]
    t, lift, _, h = sample["record"].T
    keep = t >= 3 * T - 1e-9
    hdot = 1j * K * _harmonic(t[keep], h[keep], K)
    # the fluid between the sampled rows and the surfaces accelerates with the plate: dp/dy = -rho hddot there
    jump = _harmonic(sample["t"], sample["jump"], K) / hdot - 2 * sample["jump_gap"] * 1j * K
    xm, model, model_lift = thin_plate_loading(K, panels)
    ref = np.interp(sample["jump_x"], xm, model.real) + 1j * np.interp(sample["jump_x"], xm, model.imag)
    cfd_lift = _harmonic(t[keep], lift[keep], K) / hdot
    return {"x": sample["jump_x"], "ratio": jump / ref, "lift_ratio": complex(cfd_lift / model_lift),
            "jump_integral_over_lift": complex(np.trapezoid(jump, sample["jump_x"]) / cfd_lift)}


def cfd_heave_derivatives(sample: dict) -> dict:
    """H1*, H4*, A1*, A4* from the sampled run's force record, whole periods from the third on."""
    K, T = sample["K"], sample["T"]
    t, lift, moment, h = sample["record"].T
    n = int(t[-1] / T + 1e-9)
    keep = (t >= 3 * T - 1e-9) & (t <= n * T + 1e-9)
    (resp,) = forced_motion_response(t[keep], h[keep], [K], dof="heave", speed_m_s=1.0, deck_width_m=1.0,
                                     air_density_kg_m3=1.0, lift=lift[keep], moment=moment[keep], fundamental=K)
    one = np.array([1.0 + 0j])   # pitch entries, not used by H1, H4, A1, A4
    frf = FRF(h_pu=np.array([complex(resp.frf.h_pu)]), h_ptheta=one, h_mu=np.array([complex(resp.frf.h_mu)]),
              h_mtheta=one)
    d = derivatives_from_frf(np.array([K]), frf)
    return {n: float(np.asarray(getattr(d, n))[0]) for n in HEAVE}


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reduced-velocities", type=float, nargs="+", default=[4.0, 8.0])
    ap.add_argument("--quality", default="standard")
    ap.add_argument("--grid", default="overset", choices=("overset", "single"))
    ap.add_argument("--periods", type=int, default=7, help="periods run (the first three are not sampled)")
    ap.add_argument("--panels", type=int, default=400, help="vortices on the plate in the model")
    ap.add_argument("--out", type=Path, default=Path("out/plate_wake"))
    a = ap.parse_args(argv)
    if a.periods < 5:
        ap.error(f"--periods {a.periods}: at least 5 (3 dropped, 2 fitted)")
    rows = []
    for rv in a.reduced_velocities:
        s = sample_wake(rv, a.quality, a.grid, a.periods)
        K = s["K"]
        first, speed = wake_harmonic(s["t"], s["x"], s["circulation"], K)
        x = s["x"]
        mean_speed = float(-K / np.polyfit(x, np.unwrap(np.angle(first)), 1)[0])   # one line through the phase
        gain = np.abs(first) / np.abs(first[0])
        ref = derivatives_from_frf(np.array([K]), Theodorsen().frf(np.array([K]), 1.0))
        theo = {n: float(np.asarray(getattr(ref, n))[0]) for n in HEAVE}
        cfd = cfd_heave_derivatives(s)
        base = thin_plate_heave(K, panels=a.panels)
        slow = thin_plate_heave(K, wake_speed=lambda X, c=mean_speed: np.full_like(X, c), panels=a.panels)
        grown = thin_plate_heave(K, wake_gain=lambda X, x=x, g=gain: np.interp(X, x, g, left=1.0, right=g[-1]),
                                 panels=a.panels)
        row = {"reduced_velocity": rv, "cells": s["cells"], "wake_speed_mean": mean_speed,
               "wake_speed_range": [float(speed.min()), float(speed.max())],
               "wake_gain_end": float(gain[-1]), "x": x.tolist(), "speed": speed.tolist(), "gain": gain.tolist()}
        print(f"\nU/(fB) = {rv:g} ({s['cells']}): the shed vorticity travels at {mean_speed:.3f} U "
              f"({speed.min():.3f}-{speed.max():.3f}) from {x[0] - 0.5:.2f} to {x[-1] - 0.5:.2f} chords "
              f"behind the trailing edge; its first harmonic grows by a factor {gain[-1]:.2f} over that length")
        print("  derivative | CFD - Theodorsen | model: wake at the measured speed | model: measured growth")
        for n in HEAVE:
            row[n] = {"cfd": cfd[n], "theodorsen": theo[n],
                      "cfd_miss": (cfd[n] - theo[n]) / abs(theo[n]),
                      "model_speed": (slow[n] - base[n]) / abs(base[n]),
                      "model_growth": (grown[n] - base[n]) / abs(base[n])}
            print(f"  {n}* | {100 * row[n]['cfd_miss']:+.1f} % | {100 * row[n]['model_speed']:+.1f} % | "
                  f"{100 * row[n]['model_growth']:+.1f} %")
        if s["jump"] is not None:
            load = loading_against_theodorsen(s, a.panels)
            at = [-0.35, -0.25, -0.1, 0.0, 0.1, 0.25, 0.35, 0.45]
            ratios = [load["ratio"][int(np.argmin(np.abs(load["x"] - xi)))] for xi in at]
            row["loading"] = {"x": at, "ratio_re": [r.real for r in ratios], "ratio_im": [r.imag for r in ratios],
                              "lift_ratio": [load["lift_ratio"].real, load["lift_ratio"].imag],
                              "jump_integral_over_lift": abs(load["jump_integral_over_lift"])}
            print(f"  pressure jump / Theodorsen's (first harmonics, 1.5 cells off the plate; lift from the forces "
                  f"/ Theodorsen's: {load['lift_ratio']:.3f}; the sampled jump integrates to "
                  f"{100 * abs(load['jump_integral_over_lift']):.0f} % of the lift from the forces):")
            print("  " + ", ".join(f"x {xi:+.2f}: {abs(r):.2f} ({math.degrees(np.angle(r)):+.0f} deg)"
                                   for xi, r in zip(at, ratios, strict=True)))
        rows.append(row)
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "plate_wake.json").write_text(json.dumps(rows, indent=1))
    _plot(rows, a.out / "plate_wake.png")
    print(f"\nwrote {a.out / 'plate_wake.json'} and plate_wake.png")
    return rows


def _plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for r in rows:
        lab = f"U/(fB) = {r['reduced_velocity']:g}"
        ax1.plot(np.array(r["x"]) - 0.5, r["speed"], label=lab)
        ax2.plot(np.array(r["x"]) - 0.5, r["gain"], label=lab)
    ax1.axhline(1.0, color="k", lw=0.6)
    ax1.set_ylabel("c / U of the shed vorticity")
    ax2.set_ylabel("|Gamma_1(x)| / |Gamma_1(x_0)|")
    ax2.set_xlabel("chords behind the trailing edge")
    ax1.legend()
    ax1.set_title("Heaving thin plate: the wake's first harmonic (Theodorsen: c = U, no growth)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
