"""Where the thin plate held at an angle carries its lift: the pressure along its chord (docs/validation.md).

    python tools/plate_loading.py [--angle 2] [--turbulence sst --reynolds 1e6] [--cells-per-chord 40]
                                  [--dy-over-dx 0.25] [--quality standard] [--duration 20]
                                  [--sst-walls function|blended|equilibrium|resolved] [--openfoam CASE]
                                  [--out out/plate_loading]

Why: our SST plate's moment per angle is 18-24 % below OpenFOAM's body-fitted plate's while the lifts agree
within a few per cent (docs/validation.md), so the two codes carry the lift at different places along the chord.
This tool holds the plate (``bridge.cfd.sections.FlatPlate``, 2 % thick) at ``--angle`` on the preset's overset
pair (``bridge.aero.forced_motion.run_case`` with a ``StaticCase``), averages the body grid's pressure over the
last quarter of the run, and reads it along the chord in the first cells above and below the plate that no
forcing touches (the forced cells' pressure is set by the forcing as much as by the flow); the body grid moves
with the plate, so its rows are parallel to the chord.  Delta C_p is summed over strips of the chord beside
the thin plate's potential flow (``bridge.aero.static.chordwise_loading``), with C_L, C_M (mid-chord, nose-up)
and the centre of pressure from these samples beside the force record's (what the samples miss: the wall
lies 1.5-2.5 cells below them, and the leading edge's peak is steep).  ``--openfoam CASE`` adds the same for a
case of ``python tools/openfoam_plate.py --dof static`` (the pressure of the cells on the plate's faces, averaged
over the last quarter where the case wrote pMean, else at its last time).

Above the upper side it also gives, along the chord, the largest eddy viscosity (nu_t / nu) within 0.05 chord
of the surface and the velocity along the chord in the first cell off the wall (ours: the first no forcing
touches; OpenFOAM's: the face's own cell), time-averaged as the pressure (OpenFOAM's: at its last time): where a
code's boundary layer is laminar, turbulent or reversed.  ``--sst-walls`` chooses our SST's treatment of the
plate's walls (``Physics.sst_walls``): "function" (default here, the documented plate runs': Spalding's wall
function with the model's production of k), "blended", the wall function only where the layer is turbulent,
"equilibrium", the wall function with the log layer's own production of k (the layer turbulent from the
leading edge; the aero stage's default), or "resolved" (a diagnostic: at Re 1e6 the first cells lie far above
the viscous sublayer, so the wall shear is not right; docs/aero.md).

Writes ``loading.json`` and ``loading.png`` (Delta C_p and the eddy viscosity along the chord) to ``--out``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bridge.aero.forced_motion import StaticCase, run_case  # noqa: E402
from bridge.aero.presets import SST_WALLS, section_polygons  # noqa: E402
from bridge.aero.static import chordwise_loading  # noqa: E402
from bridge.cfd.grids import GHOST  # noqa: E402
from bridge.cfd.sections import FlatPlate  # noqa: E402
from bridge.errors import InputError  # noqa: E402
from bridge.files import atomic_write_bytes, atomic_write_text, check_output_root  # noqa: E402


def _say(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


class _FieldAverage:
    """The body grid's pressure, nu + nu_t and velocity (storage arrays) averaged in time from ``start`` on
    (``run_case``'s ``observe``)."""

    FIELDS = ("p", "nu", "u")

    def __init__(self, start: float):
        self.start, self.sum, self.span, self.flow, self._t = start, None, 0.0, None, None

    def __call__(self, flow) -> None:
        t_old, self._t, self.flow = self._t, flow.t, flow
        if t_old is None or flow.t <= self.start:
            return
        dt = flow.t - t_old
        now = [dt * getattr(flow.body, name).numpy() for name in self.FIELDS]
        self.sum = now if self.sum is None else [a + b for a, b in zip(self.sum, now, strict=True)]
        self.span += dt

    def mean(self, name: str) -> np.ndarray:
        if self.sum is None:
            raise RuntimeError("no steps after the start of the average")
        return self.sum[self.FIELDS.index(name)] / self.span


def first_free_rows(forced: np.ndarray, y_centres: np.ndarray, columns: np.ndarray, top: np.ndarray) -> np.ndarray:
    """For each of ``columns``, the row of the first cell whose centre lies above ``top`` (the surface's height
    there) and which has no forced face; ``forced`` (ny, nx) from ``ImmersedBody.forced_cells``."""
    rows = []
    for i, t in zip(columns, top, strict=True):
        above = np.nonzero(y_centres > t)[0]
        rows.append(above[np.argmax(~forced[above, i])])
    return np.array(rows)


def surface_rows(forced: np.ndarray, y_centres: np.ndarray, columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each column, the row of the first cell above the plate (centre y > 0) and of the first below it that
    has no forced face; ``forced`` (ny, nx) from ``ImmersedBody.forced_cells``.  The side below is the side
    above of the grid seen from beneath (rows reversed, y negated)."""
    zero = np.zeros(len(columns))
    up = first_free_rows(forced, y_centres, columns, zero)
    down = len(y_centres) - 1 - first_free_rows(forced[::-1], -y_centres[::-1], columns, zero)
    return up, down


def our_loading(angle_deg: float, quality, thickness: float, threads: int | None) -> dict:
    """The plate held at ``angle_deg`` on ``quality`` (an overset preset); the loading, the eddy viscosity above
    the upper side (:func:`upper_side_flow`) and the force record's coefficients over the last quarter."""
    poly = section_polygons(FlatPlate(1.0, thickness))[0]
    average = _FieldAverage(0.75 * quality.run.static_duration)
    rec = run_case(poly, StaticCase(angle_deg), quality, progress=_say, label=f"plate at {angle_deg:g} deg",
                   threads=threads, observe=average)
    flow = average.flow
    grid = flow.body.grid
    inner = (slice(GHOST, GHOST + grid.ny), slice(GHOST, GHOST + grid.nx))
    p = average.mean("p")[inner]
    forced = flow.body.bodies[0].forced_cells()
    columns = np.nonzero(np.abs(grid.x_centres) < 0.5)[0]
    up, down = surface_rows(forced, grid.y_centres, columns)
    delta = (p[down, columns] - p[up, columns]) / 0.5
    x = grid.x_centres[columns] + 0.5
    u_faces = average.mean("u")[GHOST:GHOST + grid.ny, GHOST:GHOST + grid.nx + 1]
    upper = upper_side_flow(average.mean("nu")[inner] * quality.physics.reynolds - 1.0,
                            0.5 * (u_faces[:, :-1] + u_faces[:, 1:]), grid.y_centres, columns, up, thickness / 2)
    loading = chordwise_loading(x, delta, np.full(x.size, grid.dx), math.radians(angle_deg))
    sel = rec.t > 0.75 * rec.t[-1]
    record = {"C_L": float(2 * rec.lift[sel].mean()), "C_M": float(2 * rec.moment[sel].mean()),
              "C_D": float(2 * rec.drag[sel].mean()),
              "C_L_std": float(2 * rec.lift[sel].std())}
    record["centre_of_pressure"] = 0.5 - record["C_M"] / record["C_L"]
    return {"loading": loading, "record": record, "x": x, "delta_cp": delta,
            "sample_height_cells": float(np.mean(grid.y_centres[up] - thickness / 2) / grid.dy[0]),
            "upper_side": {"x": x, **upper},
            "cells": rec.meta["cells"], "grids": rec.meta["grids"], "wall_s": rec.wall_s}


def upper_side_flow(nut_over_nu: np.ndarray, u_centres: np.ndarray, y_centres: np.ndarray, columns: np.ndarray,
                    rows: np.ndarray, top: float, height: float = 0.05) -> dict:
    """Above the plate's upper side (its surface at y = ``top``; arrays (ny, nx) of cell values): in each of
    ``columns`` the largest nu_t / nu of the cells whose centres lie within ``height`` above the surface, and the
    velocity along the chord in the first cell that no forcing touches (``rows``, from :func:`surface_rows`)
    with that cell's height above the surface."""
    band = (y_centres > top) & (y_centres < top + height)
    return {"nut_over_nu_max": nut_over_nu[np.ix_(band, columns)].max(axis=0),
            "first_cell_height": y_centres[rows] - top, "first_cell_u": u_centres[rows, columns]}


def _row(name: str, loading, record: dict | None = None) -> str:
    a = loading.alpha
    text = (f"{name}: from the pressure C_L {loading.lift:.4f} ({loading.lift / (2 * math.pi * a):.3f} x 2 pi alpha), "
            f"C_M {loading.moment:.4f} ({loading.moment / (math.pi * a / 2):.3f} x pi alpha / 2), centre of pressure "
            f"{loading.centre_of_pressure:.3f}")
    if record is not None:
        text += (f"; force record C_L {record['C_L'] / (2 * math.pi * a):.3f} x, C_M "
                 f"{record['C_M'] / (math.pi * a / 2):.3f} x, centre {record['centre_of_pressure']:.3f}")
    return text


def _listed(side: dict) -> dict:
    return {k: np.asarray(v).tolist() for k, v in side.items() if k != "time"}


def _plot(path: Path, curves: list[tuple[str, np.ndarray, np.ndarray]], alpha: float, sides: list) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
    x = np.linspace(0.002, 0.998, 500)
    ax.plot(x, 4 * alpha * np.sqrt((1 - x) / x), "k-", lw=1, label="thin plate, potential flow")
    for name, xs, d in curves:
        ax.plot(xs, d, ".-", ms=3, lw=1, label=name)
    ax.set_ylabel("Delta C_p (lower - upper)")
    ax.set_ylim(-0.2, 1.5)
    ax.grid(alpha=0.3)
    ax.legend()
    for name, side in sides:
        bx.semilogy(side["x"], np.maximum(side["nut_over_nu_max"], 1e-3), ".-", ms=3, lw=1, label=name)
    bx.set_xlabel("x / B from the leading edge")
    bx.set_ylabel("largest nu_t / nu within 0.05 B\nabove the upper side")
    bx.grid(alpha=0.3)
    bx.legend()
    fig.tight_layout()
    save_png(path, fig)


def save_png(path: Path, fig) -> None:
    """Write ``fig`` to ``path`` as PNG (whole or not at all) and close it."""
    import io

    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120)
    plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())


def main(argv=None) -> int:
    from validate_aero import plate_quality

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--angle", type=float, default=2.0, help="angle of attack, degrees (default 2)")
    ap.add_argument("--turbulence", choices=("laminar", "sst"), default="sst", help="default sst")
    ap.add_argument("--reynolds", type=float, default=1e6, help="V B / nu (default 1e6)")
    ap.add_argument("--quality", default="standard", help="aero preset, on its overset pair (default standard)")
    ap.add_argument("--cells-per-chord", type=int, default=None, help="the body grid's (default: the preset's)")
    ap.add_argument("--dy-over-dx", type=float, default=None,
                    help="the body grid's cell height over its width (default: the preset's)")
    ap.add_argument("--duration", type=float, default=20.0, help="B/V held (default 20); the last quarter averaged")
    ap.add_argument("--thickness", type=float, default=0.02, help="of the chord (default 0.02)")
    ap.add_argument("--threads", type=int, default=None, help="threads of the step (default: by grid size)")
    ap.add_argument("--openfoam", type=Path, default=None, metavar="CASE",
                    help="a case of tools/openfoam_plate.py --dof static at the same angle, shown beside ours")
    ap.add_argument("--sst-walls", choices=SST_WALLS, default="function",
                    help="with SST, the plate's walls: Spalding's wall function with the model's k production "
                         "(default: the documented plate runs'), blended with the no-slip profile where the layer is "
                         "not turbulent, with the log layer's own k production (the aero stage's default), or "
                         "resolved (a diagnostic: the first cells lie far above the viscous sublayer)")
    ap.add_argument("--out", type=Path, default=Path("out/plate_loading"), help="folder (default out/plate_loading)")
    args = ap.parse_args(argv)
    if args.sst_walls != "function" and args.turbulence != "sst":
        ap.error(f"--sst-walls: {args.sst_walls} needs --turbulence sst (a laminar plate has resolved walls)")
    for name, value, ok, allowed in (
            ("--angle", args.angle, 0.0 < abs(args.angle) <= 10.0, "0 < |angle| <= 10 degrees"),
            ("--reynolds", args.reynolds, args.reynolds > 0, "> 0"),
            ("--duration", args.duration, args.duration >= 1.0, ">= 1"),
            ("--thickness", args.thickness, 0.0 < args.thickness <= 0.1, "(0, 0.1]"),
            ("--cells-per-chord", args.cells_per_chord, args.cells_per_chord is None or args.cells_per_chord >= 8,
             ">= 8")):
        if not ok:
            ap.error(f"{name}: {value:g} not allowed; must be {allowed}")
    if args.openfoam is not None and not (args.openfoam / "constant" / "polyMesh" / "boundary").is_file():
        ap.error(f"--openfoam: {args.openfoam} is no OpenFOAM case (no constant/polyMesh/boundary)")
    try:
        q = plate_quality(args.quality, "overset", args.turbulence, args.reynolds,
                          {"cells_per_chord": args.cells_per_chord, "dy_over_dx": args.dy_over_dx}, args.sst_walls)
        q = q.with_(static_duration=args.duration)
        check_output_root(args.out)
    except (InputError, KeyError, ValueError) as err:
        ap.error(str(err))
    ours = our_loading(args.angle, q, args.thickness, args.threads)
    loading = ours["loading"]
    result = {"angle_deg": args.angle, "turbulence": args.turbulence, "reynolds": args.reynolds,
              "thickness": args.thickness, "quality": args.quality, "cells_per_chord": q.grid.cells_per_chord,
              "dy_over_dx": q.grid.dy_over_dx, "sst_walls": args.sst_walls,
              "duration": args.duration, "cells": ours["cells"], "grids": ours["grids"], "wall_s": ours["wall_s"],
              "sample_height_cells": ours["sample_height_cells"], "ours": loading.as_dict(),
              "ours_force_record": ours["record"], "ours_delta_cp": {"x": ours["x"].tolist(),
                                                                     "delta_cp": ours["delta_cp"].tolist()},
              "ours_upper_side": _listed(ours["upper_side"])}
    print(_row(f"ours ({q.grid.cells_per_chord} cells per chord)", loading, ours["record"]))
    curves = [(f"ours, {q.grid.cells_per_chord} cells per chord", ours["x"], ours["delta_cp"])]
    rows = [("ours", loading)]
    sides = [("ours", ours["upper_side"])]
    if args.openfoam is not None:
        from openfoam_plate import plate_eddy_viscosity, plate_loading

        got = plate_loading(args.openfoam, args.angle)
        sides.append(("OpenFOAM", plate_eddy_viscosity(args.openfoam, args.angle, 1.0 / args.reynolds)))
        result["openfoam_upper_side"] = _listed(sides[-1][1])
        of = got["loading"]
        result["openfoam"] = {"case": str(args.openfoam), "time": got["time"], "pressure_field": got["field"],
                              **of.as_dict()}
        when = "time-averaged" if got["field"] == "pMean" else f"t = {got['time']:g}"
        print(_row(f"OpenFOAM ({args.openfoam.name}, {when})", of))
        curves.append(("OpenFOAM, " + args.openfoam.name, got["x"], got["delta_cp"]))
        rows.append(("OpenFOAM", of))
    print("strip of the chord   " + "   ".join(f"{n:>9}" for n, _ in rows) + "   potential flow")
    for k in range(loading.strips.size):
        cells = "   ".join(f"{r.strips[k]:9.5f}" for _, r in rows)
        print(f"  {loading.edges[k]:.2f} - {loading.edges[k + 1]:.2f}        {cells}   {loading.potential[k]:9.5f}")
    print("above the upper side: largest nu_t/nu within 0.05 chord; u along the chord in the first free cell")
    print("  x/B    " + "   ".join(f"{n:>17}" for n, _ in sides))
    for x0 in (0.01, 0.02, 0.05, 0.1, 0.2, 0.4, 0.7, 0.9):
        cells = []
        for _, side in sides:
            i = int(np.argmin(np.abs(side["x"] - x0)))
            cells.append(f"{side['nut_over_nu_max'][i]:8.1f} {side['first_cell_u'][i]:+8.3f}")
        print(f"  {x0:4.2f}   " + "   ".join(cells))
    atomic_write_text(args.out / "loading.json", json.dumps(result, indent=1))
    _plot(args.out / "loading.png", curves, math.radians(args.angle), sides)
    print(f"wrote {args.out / 'loading.json'} and {args.out / 'loading.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
