"""The Great Belt deck's boundary layers over its top and under its bottom: laminar, turbulent, short of the
log layer, or reversed (docs/aero.md, "Grid study"; docs/cfd.md, "Turbulence model and walls").

    python tools/deck_layer.py [--section great_belt|plate] [--nose-height F] [--bottom-flat F]
                               [--quality quick] [--cells-per-chord N] [--background-coarsening M]
                               [--body-margin B]
                               [--angle 2]
                               [--speed 50] [--sst-walls equilibrium|function|blended] [--duration 20]
                               [--threads N] [--out out/deck_layer]

Why: the SST deck's wall treatment decides whether its layer is turbulent from the nose, as it is at the
deck's Reynolds number (1e8), and the wall function's velocity profile assumes that it is.  This tool holds
the deck (``bridge.cfd.sections.great_belt_section``) at ``--angle`` on the preset's overset pair at Re = V B /
nu_air with the k-omega SST model (``run_case`` with a ``StaticCase``), averages the body grid's eddy
viscosity and velocity over the second half of the run (the half the static coefficients use), and gives the
mean lift, drag and moment coefficients over that half, the same from the first free cells' pressure over the
top and under the bottom (``pressure_loads``: where along the chord the lift is carried) and, along the top, at
fixed stations from the nose:

- nu_t / nu in the first cell above the top that no forcing touches, and the largest within 0.05 B of it;
- that cell's speed along the chord (over V) and its distance d to the deck's surface (over B), and the speed
  at 0.01, 0.02, 0.05 and 0.1 B above the top (interpolated in the column): how thick the layer is;
- the specific dissipation omega there at the end of the run, over the log layer's u_tau / (sqrt(beta*) kappa d);
- the layer's displacement thickness up to 0.1 B (``displacement_thickness``), the speed there its edge's;
- the eddy viscosity of the law of the wall at that cell, nu (dy+/du+ - 1) on Spalding's profile through the
  cell's speed and distance (kappa u_tau d in the log layer), and the cell's share of it.

The same under the bottom (the section seen from beneath), where the layer runs into the rising rear panel.
A layer in equilibrium with the wall law has a share near 1; a laminar one near 0.

``--section plate`` runs the control instead: a flat plate 2 % of the chord thick, of the deck's chord and
Reynolds number, best held at zero incidence, whose turbulent layer has a textbook thickness (delta / x = 0.37
Re_x^(-1/5): under 0.01 of the chord), so that what the grid and the wall treatment add to a layer shows apart
from the deck's shape.  ``--nose-height 1`` moves the deck's nose up onto the roof line (no fairing panel, no
corner over the top); ``--bottom-flat 0.3`` lengthens the inclined bottom panels so that the rear one rises
at 17 degrees instead of 28.  The body grid rotates with the deck, so its rows run along the chord and the deck's
polygon is fixed in it.  Writes ``layer.json`` and ``layer.png`` (the two eddy viscosities along the top; the
first free cells' speed over the top and under the bottom, where a reversed layer shows; the pressure's load
along the chord) to ``--out``.
``--cells-per-chord``, ``--background-coarsening`` and ``--body-margin`` replace the preset's body grid spacing,
the background's coarsening and how far the body grid reaches beyond the deck, on the preset's domain (a grid
study beyond ``fine``, or the background's share), and the JSON keeps the lift's record (``C_L_record``, one
value per 0.1 B/V) so that the settling of the mean shows.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from plate_loading import _FieldAverage, _say, first_free_rows, save_png  # noqa: E402
from reynolds_study import NU_AIR  # noqa: E402
from validate_turbulence import BETA_STAR, KAPPA, spalding_uplus_from_re  # noqa: E402
from validate_turbulence import B as B_LOG  # noqa: E402

from bridge.aero.forced_motion import StaticCase, run_case  # noqa: E402
from bridge.aero.presets import QUALITY, SST_WALLS, preset  # noqa: E402
from bridge.aero.presets import section_polygons as unit_polygons  # noqa: E402
from bridge.aero.static import chordwise_loading  # noqa: E402
from bridge.cfd.grids import GHOST  # noqa: E402
from bridge.cfd.sections import FlatPlate, great_belt_section  # noqa: E402
from bridge.errors import InputError  # noqa: E402
from bridge.files import atomic_write_text, check_output_root  # noqa: E402

STATIONS = (0.1, 0.2, 0.4, 0.6, 0.8, 0.95, 0.97)   # x / B from the nose
HEIGHTS = (0.01, 0.02, 0.05, 0.1)                 # above the top, B: the speed profile through the layer
PLATE_THICKNESS = 0.02                            # of the chord, --section plate
RECORD_STEP = 0.1                                 # B/V between the values of the kept lift record
BAND = 0.05                                       # the height above the top searched for the largest nu_t


def distance_to_polygon(points: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """Shortest distance from each of ``points`` (n, 2) to the closed polygon's edges (``vertices`` (m, 2))."""
    a, b = vertices, np.roll(vertices, -1, axis=0)
    ab = b - a
    rel = points[:, None, :] - a[None, :, :]
    s = np.clip((rel * ab).sum(-1) / (ab * ab).sum(-1), 0.0, 1.0)
    return np.linalg.norm(rel - s[..., None] * ab, axis=-1).min(axis=1)


def top_of(vertices: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The polygon's highest boundary point above each x (its top surface; NaN where no edge spans x)."""
    a, b = vertices, np.roll(vertices, -1, axis=0)
    out = np.full(x.shape, -np.inf)
    for (x0, y0), (x1, y1) in zip(a, b, strict=True):
        if x1 == x0:
            continue
        s = (x - x0) / (x1 - x0)
        inside = (s >= 0) & (s <= 1)
        out[inside] = np.maximum(out[inside], y0 + s[inside] * (y1 - y0))
    return np.where(np.isfinite(out), out, np.nan)


def displacement_thickness(y_centres: np.ndarray, u: np.ndarray, top: float, height: float) -> float:
    """delta* = integral of (1 - u / u_e) from the surface at ``top`` up to ``top + height``, u_e the speed there
    (interpolated in the column ``u`` at ``y_centres``): the trapezoidal rule on the cell centres in between,
    with u = 0 on the surface (the section held still), whatever forcing the cells under the first free one
    carry."""
    edge = top + height
    inside = (y_centres > top) & (y_centres < edge)
    ys = np.concatenate([[top], y_centres[inside], [edge]])
    ue = float(np.interp(edge, y_centres, u))
    deficit = 1.0 - np.concatenate([[0.0], u[inside], [ue]]) / ue
    return float(np.sum(0.5 * (deficit[1:] + deficit[:-1]) * np.diff(ys)))


def law_eddy_viscosity(speed: np.ndarray, d: np.ndarray, nu: float) -> np.ndarray:
    """nu (dy+/du+ - 1) on Spalding's law through points at distance ``d`` moving at ``speed`` along the wall
    (``kernels.wall_law.wall_law_eddy_viscosity``, here from validate_turbulence's table): kappa u_tau d in
    the log layer, 0 in the sublayer."""
    up = spalding_uplus_from_re(np.abs(speed) * d / nu)
    z = KAPPA * up
    slope = 1.0 + math.exp(-KAPPA * B_LOG) * KAPPA * (np.exp(z) - 1.0 - z - z * z / 2.0)
    return nu * (slope - 1.0)


SECTIONS = ("great_belt", "plate")


def section_polygons(name: str, nose_height: float | None = None, bottom_flat: float | None = None) -> list:
    """The unit-chord polygons of ``name``: the Great Belt deck, or a flat plate ``PLATE_THICKNESS`` of the
    chord thick (``bridge.cfd.sections.FlatPlate``, square ends, as tools/plate_loading.py's): the control,
    whose layer at zero incidence has a textbook thickness.  ``nose_height``: the deck's
    ``StreamlinedBox.nose_height_fraction`` instead of its default (1 puts the nose on the roof line: no
    fairing panel, no corner over the top).  ``bottom_flat``: its ``bottom_flat_fraction`` instead of the default
    0.6 (smaller: longer, shallower inclined bottom panels; the rear one rises at 28 degrees by default, at
    17 degrees with 0.3)."""
    if name == "plate":
        return unit_polygons(FlatPlate(1.0, PLATE_THICKNESS))[:1]
    deck = great_belt_section()
    if nose_height is not None:
        deck = replace(deck, nose_height_fraction=nose_height)
    if bottom_flat is not None:
        deck = replace(deck, bottom_flat_fraction=bottom_flat)
    return unit_polygons(deck)


def deck_layer(q, angle_deg: float, threads: int | None, polys: list, section: str = "great_belt") -> dict:
    """The section ``polys`` (unit chord, ``section`` names it in the progress) held at ``angle_deg`` on ``q``
    (an overset SST preset); the layer over its top (module doc), and under its bottom as ``"bottom"``."""
    average = _FieldAverage(0.5 * q.run.static_duration)
    rec = run_case(polys, StaticCase(angle_deg), q, progress=_say, label=f"{section} at {angle_deg:g} deg",
                   threads=threads, observe=average)
    flow = average.flow
    grid = flow.body.grid
    inner = (slice(GHOST, GHOST + grid.ny), slice(GHOST, GHOST + grid.nx))
    u_faces = average.mean("u")[GHOST:GHOST + grid.ny, GHOST:GHOST + grid.nx + 1]
    forced = np.zeros((grid.ny, grid.nx), dtype=bool)
    for body in flow.body.bodies:
        forced |= body.forced_cells()
    fields = {"nut": average.mean("nu")[inner] - 1.0 / q.physics.reynolds,
              "u": 0.5 * (u_faces[:, :-1] + u_faces[:, 1:]),
              "forced": forced, "omega": flow.turbulence.body.omega.q.numpy()[inner]}
    # the pressure's level is free: measured from its mean over the body grid's outermost ring of cells (the
    # body grid's margin beyond the deck, 0.35 B on standard and fine, 0.375 B on quick; the same ring seen
    # from beneath), so that the sides' pressures compare between grids
    pressure = average.mean("p")[inner]
    ring = np.concatenate([pressure[0], pressure[-1], pressure[1:-1, 0], pressure[1:-1, -1]])
    fields["p"] = pressure - ring.mean()
    # the side below, seen from beneath: the rows and the heights mirrored, the chordwise speed unchanged
    below = {name: a[::-1] for name, a in fields.items()}
    mirrored = [p.vertices * np.array([1.0, -1.0]) for p in polys]
    second = rec.t > 0.5 * q.run.static_duration   # per rho V^2 B (B^2): twice the coefficients
    forces = {name: float(2.0 * getattr(rec, force)[second].mean())
              for name, force in (("C_L", "lift"), ("C_D", "drag"), ("C_M", "moment"))}
    record_t = np.arange(0.0, float(rec.t[-1]) + 1e-9, RECORD_STEP)
    record = 2.0 * np.interp(record_t, rec.t, rec.lift)
    top = layer_along(fields, grid.y_centres, grid.x_centres, [p.vertices for p in polys], q.physics.reynolds)
    bottom = layer_along(below, -grid.y_centres[::-1], grid.x_centres, mirrored, q.physics.reynolds)
    return {**forces, **top, "bottom": bottom, **pressure_loads(top, bottom, grid.dx),
            "cells": rec.meta["cells"], "grids": rec.meta["grids"], "wall_s": rec.wall_s, "steps": rec.steps,
            "C_L_record": [round(float(c), 6) for c in record]}


def pressure_loads(top: dict, bottom: dict, dx: float) -> dict:
    """Where along the chord the pressure carries the lift: the load n = C_p,bottom - C_p,top per unit chord at
    each column (the first free cells' pressures, ``layer_along``'s "first_cell_cp"; the pressure force's
    component normal to the chord on a surface y(x) is the integral of p over x, whatever its slope), its sum
    C_N (the chord-normal force per 1/2 rho V^2 B: C_L within C_T sin(alpha) and the friction) and its moment
    C_M,p about mid-chord, nose-up (``bridge.aero.static.chordwise_loading``'s sums; its thin-plate strips are not
    used): what a change of the lift between grids is made of, column by column."""
    x = np.array(top["x_from_nose"])
    load = np.array(bottom["first_cell_cp"]) - np.array(top["first_cell_cp"])
    sums = chordwise_loading(x, load, np.full(x.size, dx), 0.0)
    return {"normal_load": load.tolist(), "C_N_pressure": sums.lift, "C_M_pressure": sums.moment}


def layer_along(fields: dict, y_centres: np.ndarray, x_centres: np.ndarray, outlines: list, reynolds: float) -> dict:
    """The layer over the top of ``outlines`` (unit chord, the first the section's body) from the body grid's
    time-averaged ``fields`` (ny, nx: "nut", "u" and "p" at the cell centres, "forced", "omega"); module doc."""
    nu = 1.0 / reynolds
    nut, u = fields["nut"], fields["u"]
    columns = np.nonzero(np.abs(x_centres) < 0.5)[0]
    x = x_centres[columns]
    top = top_of(outlines[0], x)
    up = first_free_rows(fields["forced"], y_centres, columns, top)
    yc = y_centres[up]
    d = np.min([distance_to_polygon(np.column_stack([x, yc]), v) for v in outlines], axis=0)
    band = y_centres[:, None] < top[None, :] + BAND
    above = y_centres[:, None] > top[None, :]
    nut_cols = nut[:, columns] / nu
    largest = np.where(band & above, nut_cols, -np.inf).max(axis=0)
    speed = u[up, columns]
    profile = [[float(np.interp(t + h, y_centres, u[:, i])) for h in HEIGHTS] for i, t in zip(columns, top,
                                                                                              strict=True)]
    displacement = [displacement_thickness(y_centres, u[:, i], t, HEIGHTS[-1]) for i, t in zip(columns, top,
                                                                                                strict=True)]
    law = law_eddy_viscosity(speed, d, nu)
    first = nut[up, columns]
    # the specific dissipation at the end of the run against the log layer's u_tau / (sqrt(beta*) kappa d),
    # u_tau from the cell's speed on Spalding's law
    omega = fields["omega"][up, columns]
    cp = 2.0 * fields["p"][up, columns]      # per 1/2 rho V^2, V = rho = 1
    u_tau = np.abs(speed) / np.maximum(spalding_uplus_from_re(np.abs(speed) * d / nu), 1e-12)
    omega_log = u_tau / (math.sqrt(BETA_STAR) * KAPPA * d)
    return {"x_from_nose": (x + 0.5).tolist(), "first_cell_nut_over_nu": (first / nu).tolist(),
            "largest_nut_over_nu": largest.tolist(), "first_cell_u": speed.tolist(),
            "heights": list(HEIGHTS), "u_at_heights": profile,
            "first_cell_distance": d.tolist(), "law_nut_over_nu": (law / nu).tolist(),
            "share_of_law": [float(f / w) if w > 0 else None for f, w in zip(first, law, strict=True)],
            "first_cell_omega_over_log": (omega / omega_log).tolist(), "first_cell_cp": cp.tolist(),
            "displacement_thickness": displacement}


def _table(got: dict) -> None:
    x = np.array(got["x_from_nose"])
    for i in sorted({int(np.argmin(np.abs(x - x0))) for x0 in STATIONS}):   # a coarse grid may merge stations
        print(f"  {x[i]:4.2f}   {got['first_cell_nut_over_nu'][i]:22.3g}   {got['largest_nut_over_nu'][i]:21.3g}"
              f"   {got['first_cell_u'][i]:+.3f}  {got['first_cell_distance'][i]:.4f}   "
              f"{got['law_nut_over_nu'][i]:14.3g}   {_share(got['share_of_law'][i])}   "
              + " / ".join(f"{v:.3f}" for v in got["u_at_heights"][i])
              + f"   {got['first_cell_omega_over_log'][i]:.3g}   {got['displacement_thickness'][i]:.4f}")


def _share(value: float | None) -> str:
    return "    -" if value is None else f"{value:5.2g}"


def _plot(path: Path, got: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx, cx) = plt.subplots(1, 3, figsize=(16, 4))
    x = np.array(got["x_from_nose"])
    ax.semilogy(x, np.maximum(got["first_cell_nut_over_nu"], 1e-3), ".-", ms=3, lw=1, label="first free cell")
    ax.semilogy(x, np.maximum(got["largest_nut_over_nu"], 1e-3), ".-", ms=3, lw=1,
                label=f"largest within {BAND:g} B")
    ax.semilogy(x, np.maximum(got["law_nut_over_nu"], 1e-3), "k--", lw=1,
                label="law of the wall at the first free cell")
    ax.set_xlabel("x / B from the nose")
    ax.set_ylabel("nu_t / nu above the top")
    ax.grid(alpha=0.3)
    ax.legend()
    for side, values, style in (("top", got, ".-"), ("bottom", got["bottom"], "x--")):
        bx.plot(values["x_from_nose"], values["first_cell_u"], style, ms=3, lw=1, label=f"{side}: first free cell")
    bx.axhline(0.0, color="k", lw=0.5)
    bx.set_xlabel("x / B from the nose")
    bx.set_ylabel("u / V along the chord (below 0: reversed)")
    bx.grid(alpha=0.3)
    bx.legend()
    cx.plot(x, got["normal_load"], ".-", ms=3, lw=1)
    cx.axhline(0.0, color="k", lw=0.5)
    cx.set_xlabel("x / B from the nose")
    cx.set_ylabel("C_p,bottom - C_p,top (first free cells)")
    cx.set_title(f"C_N {got['C_N_pressure']:+.3f} (C_L {got['C_L']:+.3f})", fontsize=9)
    cx.grid(alpha=0.3)
    fig.tight_layout()
    save_png(path, fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quality", default="quick", choices=sorted(QUALITY), help="aero preset (default quick)")
    ap.add_argument("--cells-per-chord", type=int, default=None,
                    help="the body grid's cells per chord (default the preset's: 16 / 40 / 80)")
    ap.add_argument("--background-coarsening", type=int, default=None,
                    help="the background's cells this many times the body grid's (default the preset's 2)")
    ap.add_argument("--body-margin", type=float, default=None,
                    help="chords the body grid reaches beyond the deck (default the preset's 0.35; at least 6 "
                         "background cells)")
    ap.add_argument("--section", choices=SECTIONS, default="great_belt",
                    help="the Great Belt deck (default) or a flat plate 2 %% of the chord thick (the control; "
                         "hold it at --angle 0)")
    ap.add_argument("--nose-height", type=float, default=None,
                    help="the deck's nose_height_fraction (default the section's 0.8; 1: no corner over the top)")
    ap.add_argument("--bottom-flat", type=float, default=None,
                    help="the deck's bottom_flat_fraction (default the section's 0.6; smaller: shallower "
                         "inclined bottom panels)")
    ap.add_argument("--angle", type=float, default=2.0, help="angle of attack, degrees (default 2)")
    ap.add_argument("--speed", type=float, default=50.0, help="wind speed [m/s]: Re = V B / nu_air (default 50)")
    ap.add_argument("--sst-walls", choices=[w for w in SST_WALLS if w != "resolved"], default="equilibrium",
                    help="the deck's SST walls (default equilibrium, the aero stage's)")
    ap.add_argument("--duration", type=float, default=20.0, help="B/V held (default 20); the second half averaged")
    ap.add_argument("--threads", type=int, default=None, help="threads of the step (default: by grid size)")
    ap.add_argument("--out", type=Path, default=Path("out/deck_layer"), help="folder (default out/deck_layer)")
    args = ap.parse_args(argv)
    for name, value, ok, allowed in (
            ("--angle", args.angle, abs(args.angle) <= 10.0, "-10 to 10 degrees"),
            ("--speed", args.speed, args.speed > 0, "> 0"),
            ("--duration", args.duration, args.duration >= 2.0, ">= 2"),
            ("--cells-per-chord", args.cells_per_chord,
             args.cells_per_chord is None or 8 <= args.cells_per_chord <= 2000, "8 to 2000"),
            ("--background-coarsening", args.background_coarsening,
             args.background_coarsening is None or 1 <= args.background_coarsening <= 16, "1 to 16"),
            ("--body-margin", args.body_margin,
             args.body_margin is None or 0.05 <= args.body_margin <= 5.0, "0.05 to 5 chords"),
            ("--threads", args.threads, args.threads is None or args.threads >= 1, ">= 1"),
            ("--nose-height", args.nose_height, args.nose_height is None or 0.0 < args.nose_height <= 1.0, "(0, 1]"),
            ("--bottom-flat", args.bottom_flat, args.bottom_flat is None or 0.0 <= args.bottom_flat < 1.0, "[0, 1)")):
        if not ok:
            ap.error(f"{name}: {value:g} not allowed; must be {allowed}")
    section = great_belt_section()
    try:
        q = preset(args.quality, "overset").with_(turbulence="sst", reynolds=args.speed * section.chord_m / NU_AIR,
                    sst_walls=args.sst_walls, static_duration=args.duration)
        if args.cells_per_chord is not None:
            q = q.with_(cells_per_chord=args.cells_per_chord)
        if args.background_coarsening is not None:
            q = q.with_(background_coarsening=args.background_coarsening)
        if args.body_margin is not None:
            q = q.with_(body_margin=args.body_margin)
        for option, value in (("--nose-height", args.nose_height), ("--bottom-flat", args.bottom_flat)):
            if value is not None and args.section != "great_belt":
                raise InputError(option, value, "applies to --section great_belt only")
        polys = section_polygons(args.section, args.nose_height, args.bottom_flat)
        check_output_root(args.out)
    except (InputError, ValueError) as err:
        ap.error(str(err))
    got = deck_layer(q, args.angle, args.threads, polys, args.section)
    result = {"section": args.section, "nose_height_fraction": args.nose_height,
              "bottom_flat_fraction": args.bottom_flat, "angle_deg": args.angle,
              "speed_m_s": args.speed, "reynolds": q.physics.reynolds, "quality": args.quality,
              "cells_per_chord": q.grid.cells_per_chord, "background_coarsening": q.grid.background_coarsening,
              "body_margin": q.grid.body_margin,
              "sst_walls": args.sst_walls, "duration": args.duration, **got}
    print(f"{args.section} at {args.angle:g} deg, Re {q.physics.reynolds:.3g}, {args.quality} "
          f"({q.grid.cells_per_chord} cells per chord, background x{q.grid.background_coarsening}), "
          f"SST walls {args.sst_walls}; second half of {args.duration:g} B/V")
    print("  C_L {C_L:+.4f}   C_D {C_D:.4f}   C_M {C_M:+.4f}   (means over the second half)".format(**got))
    print("  from the first free cells' pressure: C_N {C_N_pressure:+.4f}   C_M {C_M_pressure:+.4f}".format(**got))
    for side, beyond, values in (("top", "above the top", got), ("bottom", "below the bottom", got["bottom"])):
        print(f"{side}:\n  x/B   first free cell nu_t/nu   largest within {BAND:g} B   u/V     d/B      law's nu_t/nu"
              "   share   u/V at " + " / ".join(f"{h:g}" for h in HEIGHTS)
              + f" B {beyond}   omega/omega_log   delta*/B")
        _table(values)
    atomic_write_text(args.out / "layer.json", json.dumps(result, indent=1))
    _plot(args.out / "layer.png", got)
    print(f"wrote {args.out / 'layer.json'} and {args.out / 'layer.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
