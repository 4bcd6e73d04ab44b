"""A reference for the DFG cylinder benchmarks 2D-1 and 2D-2: the same cases in OpenFOAM on a body-fitted block mesh.

    python tools/openfoam_dfg.py dfg  [--around 128] [--t-end 10] [--procs 2] [--out DIR]   # 2D-1, Re 20, steady
    python tools/openfoam_dfg.py dfg2 [--around 128] [--t-end 8] [--procs 2] [--out DIR]    # 2D-2, Re 100, periodic
    python tools/openfoam_dfg.py dfg2 --around 184 --procs 2       # about 30 000 cells (--around 128: 15 000)
    python tools/openfoam_dfg.py dfg2 --outer 1 --max-co 0.25       # PISO instead of PIMPLE (see below)

What: the benchmarks 2D-1 and 2D-2 of Schaefer and Turek (1996), "Benchmark computations of laminar flow around a
cylinder", Notes on Numerical Fluid Mechanics 52, 547-566: a channel 2.2 x 0.41 with a cylinder of D = 0.1
centred at (0.2, 0.2), nu = 1e-3, rho = 1, the parabolic inflow u = 4 U_m y (H - y) / H^2 (U_m 0.3: Re 20, steady;
U_m 1.5: Re 100, periodic shedding), no slip on the channel walls and the cylinder, zero-gradient velocity and
p = 0 at the outflow.  c_D = 2 F_x / (rho Ubar^2 D), c_L likewise, Ubar = 2 U_m / 3, St = D f / Ubar.  The bands
of the benchmark's table: 2D-1 c_D 5.57-5.59, c_L 0.0104-0.0110; 2D-2 c_D,max 3.22-3.24, c_L,max 0.99-1.01,
St 0.295-0.305.

Why: ``python tools/validate_body_fitted.py dfg | dfg2`` runs the same cases in our body-fitted solver (an O-grid
over a Cartesian background); this tool gives a code nobody here wrote on a single body-fitted mesh, so that the
two can be set side by side in accuracy and in wall time, run one after the other on the same machine.

How: OpenFOAM's pimpleFoam (ESI v1912, laminar) on a blockMesh of 12 blocks: an O-grid ring of 4 blocks from the
cylinder (arcs) to a square of side 2 D round it (straight sides), ``--around`` cells round the cylinder, the radial
cells graded towards the wall (the first cell half the spacing along the wall, the last as large as the square's
cells, on the lines to the middles of the square's sides; both 1.8 times that on its diagonals, the ring's radial
lines being longer there), and 8 Cartesian blocks filling the channel with cells of the square's spacing, growing by
at most 3 % a cell to twice that size downstream of the square.  The radial count and its grading and the channel's
cells all follow from ``--around`` (128: 14 686 cells, 184: 29 846).  The worst non-orthogonality, ~43 deg, is at the
square's corners.  Second order in space and time: convection ``Gauss linearUpwind grad(U)`` (upwind-biased second
order; everything else ``Gauss linear``, corrected), time ``backward`` (BDF2), the step adjusted to a Courant number
of ``--max-co`` (default 0.5); PIMPLE with ``--outer`` outer correctors a step (default 2), each with 2 pressure
correctors and 1 non-orthogonal corrector.  The outer correctors matter for 2D-2: in PISO mode (``--outer 1``) the
splitting error lifted c_L,max on 14 686 cells to 1.138 at Co 1, 1.067 at Co 0.5 and 1.032 at Co 0.25, where 2 outer
correctors at Co 0.5 (the cost of PISO at Co 0.25) gave 0.994.  The inflow is ``fixedProfile`` (the parabola as a
polynomial in y at the face centres); the flow starts from rest.  The coefficients come from the ``forceCoeffs``
function object (lRef = D, Aref = D x the mesh's depth, magUInf = Ubar) every step.
2D-1 runs to ``--t-end`` (default 10); c_D, c_L at the end and their change over the last time unit (the steady
state's check) are reported.  2D-2 runs to ``--t-end`` (default 8) and takes c_D,max and c_L,max over the last
2 time units and St from c_L's period (the mean spacing of its upward crossings of its mean), as
validate_body_fitted.py's dfg2 does.

Results here (defaults, --procs 2): 2D-1 on 14 686 cells c_D 5.5769, c_L 0.01073 (2 910 steps, 63 s); 2D-2 on
14 686 cells c_D,max 3.2298, c_L,max 0.9936, St 0.2979 (13 929 steps, 440 s), on 29 846 cells 3.2296, 0.9940,
0.2999 (20 043 steps, ~1 700 s): all in the bands.  The times are pimpleFoam's own on a 2-core machine shared with
other runs, so only indicative.

Needs OpenFOAM (Debian's package ``openfoam``: ``apt-get install openfoam``); not a dependency of the project.
Writes the case to ``--out`` (default out/openfoam_dfg/<case>_n<around>), runs blockMesh, checkMesh and
decomposePar (tools/openfoam_plate.run), then pimpleFoam on ``--procs`` ranks with progress every ~30 s; rerun,
it resumes from the last written time (a later ``--t-end`` extends the run).  Prints the figures beside the
bands, the cell count and the wall time of pimpleFoam alone (its own ClockTime, and as timed from here with the
start-up of the process or of mpirun; blockMesh, checkMesh and decomposePar excluded); all of it goes to
``result.json`` in the case folder.  Timings on a shared machine: with more runnable processes than cores the MPI
ranks wait for each other at every one of a step's hundreds of collective operations; at a load of 13 on 2 cores a
step of the 14 686-cell case took a minute on 2 ranks and 0.2 s on 1, so use ``--procs 1`` on a busy machine.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from openfoam_plate import HEADER, control_dict, graded, grading_spec, run  # noqa: E402

from bridge.errors import InputError, check_range  # noqa: E402

D, XC, YC, H, LENGTH, NU = 0.1, 0.2, 0.2, 0.41, 2.2, 1e-3
HALF_SQUARE = 0.1        # the O-grid's outer square: x and y within 0.1 of the cylinder's centre
DEPTH = 0.1              # of the 2D mesh (one cell), so Aref = D * DEPTH
WALL_ASPECT = 0.5        # the first cell's height over its width along the cylinder
WAKE_STRETCH, WAKE_GROWTH = 2.0, 1.03    # downstream cells grow to 2x the square's cells, by at most 3 % a cell
UMAX = {"dfg": 0.3, "dfg2": 1.5}
T_END = {"dfg": 10.0, "dfg2": 8.0}
MAX_CO = 0.5             # the adjusted step's Courant number (the step taken goes to result.json)
OUTER = 2                # PIMPLE's outer correctors a step (1: PISO, whose splitting error lifted 2D-2's c_L,max)
WINDOW = 2.0             # dfg2: the last time units the maxima and St are taken over
BANDS = {"dfg": {"c_D": (5.57, 5.59), "c_L": (0.0104, 0.0110)},
         "dfg2": {"c_D_max": (3.22, 3.24), "c_L_max": (0.99, 1.01), "St": (0.295, 0.305)}}
CONVECTION = "Gauss linearUpwind grad(U)"


# ---------------------------------------------------------------------------------------------- the mesh


def ring_cells(around: int) -> tuple[int, float, float]:
    """The O-grid's radial cells: their count, the expansion from the wall to the square, and the first cell's
    height, along the ring's shortest radial line (to the middle of a side of the square, length a - D/2; the
    cells on the other radial lines are as much larger as the line is longer, 1.8 times on the diagonals).  The
    first cell is WALL_ASPECT times the spacing along the wall, the last as large as the square's cells; the count
    is the one whose geometric series best fits the line."""
    line = HALF_SQUARE - D / 2
    first, last = WALL_ASPECT * math.pi * D / around, 8 * HALF_SQUARE / around
    expansion = last / first
    best = None
    for n in range(2, 2000):
        r = expansion ** (1.0 / (n - 1))
        got = line * (r - 1.0) / (r ** n - 1.0)       # the first cell with n cells of this expansion
        if best is None or abs(math.log(got / first)) < abs(math.log(best[1] / first)):
            best = (n, got)
        if got < first:
            break
    return best[0], expansion, best[1]


def block_mesh_dict(around: int) -> tuple[str, dict]:
    """The channel and cylinder in 12 blocks: 4 round the cylinder (O-grid to the square), 8 Cartesian.
    Returns the dictionary's text and the mesh's figures (cells, radial count, first cell, square's cell)."""
    a, r = HALF_SQUARE, D / 2
    h0 = 2 * a / (around // 4)
    n_r, expansion, first = ring_cells(around)
    xs, ys = [0.0, XC - a, XC + a, LENGTH], [0.0, YC - a, YC + a, H]
    wake = graded(LENGTH - xs[2], h0, WAKE_STRETCH * h0, WAKE_GROWTH)
    x_spec = [(max(1, round(xs[1] / h0)), "1"), (around // 4, "1"), grading_spec(wake)]
    y_spec = [(max(1, round(ys[1] / h0)), "1"), (around // 4, "1"), (max(1, round((H - ys[2]) / h0)), "1")]
    per = 20     # vertices per z level: the 4 x 4 lattice, then the cylinder's 4 points at 225, 315, 45, 135 deg

    def v(i, j, k=0):
        return k * per + j * 4 + i

    def c(m, k=0):
        return k * per + 16 + m

    angles = [math.radians(x) for x in (225, 315, 45, 135)]
    points = [(x, y) for y in ys for x in xs] + [(XC + r * math.cos(t), YC + r * math.sin(t)) for t in angles]
    verts = "\n".join(f"    ({x:.12g} {y:.12g} {z:g})" for z in (0.0, DEPTH) for x, y in points)
    hexes = []          # (8 vertex labels, cells, grading)
    for j in range(3):
        for i in range(3):
            if (i, j) != (1, 1):
                (nx, gx), (ny, gy) = x_spec[i], y_spec[j]
                hexes.append(((v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)), (nx, ny), (gx, gy)))
    sw, se, ne, nw = v(1, 1), v(2, 1), v(2, 2), v(1, 2)
    q, e = around // 4, f"{expansion:.12g}"
    inv = f"{1.0 / expansion:.12g}"
    hexes += [((sw, se, c(1), c(0)), (q, n_r), ("1", inv)),       # below the cylinder: x2 from the square inwards
              ((c(1), se, ne, c(2)), (n_r, q), (e, "1")),         # right: x1 from the cylinder outwards
              ((c(3), c(2), ne, nw), (q, n_r), ("1", e)),         # above
              ((sw, c(0), c(3), nw), (n_r, q), (inv, "1"))]       # left: x1 from the square inwards
    blocks, cells = [], 0
    for labels, (n1, n2), (g1, g2) in hexes:
        hexv = " ".join(str(n) for n in labels + tuple(n + per for n in labels))
        blocks.append(f"    hex ({hexv}) ({n1} {n2} 1) simpleGrading ({g1} {g2} 1)")
        cells += n1 * n2
    arcs = []
    for m, t in enumerate((270, 0, 90, 180)):      # the cylinder's quarters between its 4 points
        px, py = XC + r * math.cos(math.radians(t)), YC + r * math.sin(math.radians(t))
        for k, z in ((0, 0.0), (1, DEPTH)):
            arcs.append(f"    arc {c(m, k)} {c((m + 1) % 4, k)} ({px:.12g} {py:.12g} {z:g})")

    def face(p, s):     # the side face through bottom-level vertices p and s
        return f"({p} {s} {s + per} {p + per})"

    def patch(name, kind, faces):
        body = "\n".join(f"            {f}" for f in faces)
        return f"    {name}\n    {{\n        type {kind};\n        faces\n        (\n{body}\n        );\n    }}"

    empty = []
    for labels, _, _ in hexes:
        empty.append(f"({labels[0]} {labels[3]} {labels[2]} {labels[1]})")
        empty.append("(" + " ".join(str(n + per) for n in labels) + ")")
    boundary = [patch("inlet", "patch", [face(v(0, j), v(0, j + 1)) for j in range(3)]),
                patch("outlet", "patch", [face(v(3, j), v(3, j + 1)) for j in range(3)]),
                patch("walls", "wall", [face(v(i, 0), v(i + 1, 0)) for i in range(3)]
                      + [face(v(i, 3), v(i + 1, 3)) for i in range(3)]),
                patch("cylinder", "wall", [face(c(m), c((m + 1) % 4)) for m in range(4)]),
                patch("frontAndBack", "empty", empty)]
    text = (HEADER.format(cls="dictionary", obj="blockMeshDict") + "convertToMeters 1;\n\nvertices\n(\n" + verts
            + "\n);\n\nblocks\n(\n" + "\n".join(blocks) + "\n);\n\nedges\n(\n" + "\n".join(arcs)
            + "\n);\n\nboundary\n(\n" + "\n".join(boundary) + "\n);\n\nmergePatchPairs ();\n")
    return text, {"cells": cells, "around": around, "rings": n_r, "first_cell": first, "square_cell": h0,
                  "ring_expansion": expansion, "channel_cells_x": sum(s[0] for s in x_spec),
                  "channel_cells_y": sum(s[0] for s in y_spec)}


# ---------------------------------------------------------------------------------------------- the case


def write_case(case: Path, name: str, around: int, t_end: float, max_co: float, procs: int,
               outer: int = OUTER) -> dict:
    """The case folder for ``name`` (dfg or dfg2); returns the mesh's figures.  A folder that already holds a
    mesh made from another blockMeshDict is refused (its results would not be this mesh's)."""
    mesh, figures = block_mesh_dict(around)
    old = case / "system" / "blockMeshDict"
    if (case / "constant" / "polyMesh" / "points").exists() and old.is_file() and old.read_text() != mesh:
        raise InputError("--out", str(case), "holds a case with another mesh: give a new folder or delete it")
    for sub in ("system", "constant", "0"):
        (case / sub).mkdir(parents=True, exist_ok=True)
    old.write_text(mesh)
    umax = UMAX[name]
    ubar = 2 * umax / 3
    write_interval = t_end / max(1, round(t_end))     # about 1, and t_end a whole number of them: written at the end
    functions = f"""    forceCoeffs
    {{
        type forceCoeffs;
        libs ("libforces.so");
        patches (cylinder);
        rho rhoInf;
        rhoInf 1;
        CofR ({XC:g} {YC:g} 0);
        liftDir (0 1 0);
        dragDir (1 0 0);
        pitchAxis (0 0 1);
        magUInf {ubar:.12g};
        lRef {D:g};
        Aref {D * DEPTH:.12g};
        writeControl timeStep;
        writeInterval 1;
        log false;
    }}
"""
    (case / "system" / "controlDict").write_text(control_dict(t_end, "1e-5", write_interval, max_co, "0.01", functions))
    (case / "system" / "fvSchemes").write_text(HEADER.format(cls="dictionary", obj="fvSchemes") + f"""
ddtSchemes {{ default backward; }}
gradSchemes {{ default Gauss linear; }}
divSchemes
{{
    default none;
    div(phi,U) {CONVECTION};
    div((nuEff*dev2(T(grad(U))))) Gauss linear;
}}
laplacianSchemes {{ default Gauss linear corrected; }}
interpolationSchemes {{ default linear; }}
snGradSchemes {{ default corrected; }}
""")
    (case / "system" / "fvSolution").write_text(HEADER.format(cls="dictionary", obj="fvSolution") + f"""
solvers
{{
    p {{ solver GAMG; smoother GaussSeidel; tolerance 1e-7; relTol 0.01; }}
    pFinal {{ $p; relTol 0; }}
    "U(|Final)" {{ solver smoothSolver; smoother symGaussSeidel; tolerance 1e-9; relTol 0; }}
}}
PIMPLE
{{
    momentumPredictor yes;
    nOuterCorrectors {outer};
    nCorrectors 2;
    nNonOrthogonalCorrectors 1;     // the O-grid is up to ~43 deg non-orthogonal (at the square's corners)
}}
""")
    (case / "system" / "decomposeParDict").write_text(HEADER.format(cls="dictionary", obj="decomposeParDict") + f"""
numberOfSubdomains {procs};
method simple;
coeffs {{ n ({procs} 1 1); delta 0.001; }}
""")
    (case / "constant" / "transportProperties").write_text(
        HEADER.format(cls="dictionary", obj="transportProperties") + f"\ntransportModel Newtonian;\nnu {NU:g};\n")
    (case / "constant" / "turbulenceProperties").write_text(
        HEADER.format(cls="dictionary", obj="turbulenceProperties") + "\nsimulationType laminar;\n")
    k1, k2 = 4 * umax / H, -4 * umax / H ** 2        # u(y) = k1 y + k2 y^2
    (case / "0" / "U").write_text(HEADER.format(cls="volVectorField", obj="U") + f"""
dimensions [0 1 -1 0 0 0 0];
internalField uniform (0 0 0);
boundaryField
{{
    inlet
    {{
        type fixedProfile;
        profile polynomial ( (({k1:.12g} 0 0) (1 0 0)) (({k2:.12g} 0 0) (2 0 0)) );
        direction (0 1 0);
        origin 0;
    }}
    outlet {{ type zeroGradient; }}
    "(walls|cylinder)" {{ type noSlip; }}
    frontAndBack {{ type empty; }}
}}
""")
    (case / "0" / "p").write_text(HEADER.format(cls="volScalarField", obj="p") + """
dimensions [0 2 -2 0 0 0 0];
internalField uniform 0;
boundaryField
{
    inlet { type zeroGradient; }
    outlet { type fixedValue; value uniform 0; }
    "(walls|cylinder)" { type zeroGradient; }
    frontAndBack { type empty; }
}
""")
    return figures


# ---------------------------------------------------------------------------------------------- the results


def read_coefficients(case: Path) -> dict:
    """forceCoeffs' time series (``t``, ``Cd``, ``Cl``, ...: the columns its header names), merged over
    restarts: each start writes postProcessing/forceCoeffs/<start>/coefficient.dat (coefficient_0.dat, ... when
    the folder was there already), and a later file replaces what the older ones held from its first time on."""
    root = case / "postProcessing" / "forceCoeffs"
    if not root.is_dir():
        raise SystemExit(f"{root}: missing, the forceCoeffs function object wrote nothing")
    series, names = {}, None

    def order(path: Path) -> int:      # coefficient.dat first, then coefficient_0.dat, coefficient_1.dat, ...
        tail = path.stem.partition("_")[2]
        return int(tail) + 1 if tail.isdigit() else 0

    for start in sorted(root.iterdir(), key=lambda p: float(p.name)):
        for path in sorted(start.glob("coefficient*.dat"), key=order):
            lines = path.read_text().splitlines()
            head = [s for s in lines if s.startswith("#") and "Cd" in s]
            if head:
                names = head[-1].lstrip("#").split()
            rows = [[float(x) for x in s.split()] for s in lines if s.strip() and not s.startswith("#")]
            if not rows:
                continue
            for k in [k for k in series if k >= rows[0][0]]:
                del series[k]
            for row in rows:
                series[row[0]] = row[1:]
    if names is None or not series:
        raise SystemExit(f"{root}: no coefficients written")
    t = np.array(sorted(series))
    data = np.array([series[k] for k in t])
    out = {"t": t}
    for i, n in enumerate(names[1:]):
        out[n] = data[:, i]
    return out


def steady_figures(co: dict) -> dict:
    """2D-1: c_D and c_L at the end, and how much they still moved over the last time unit and the last 0.5
    (validate_body_fitted.py's check)."""
    t, cd, cl = co["t"], co["Cd"], co["Cl"]
    last1, last05 = t > t[-1] - 1.0, t > t[-1] - 0.5
    return {"c_D": float(cd[-1]), "c_L": float(cl[-1]), "c_D_change_last_1": float(np.ptp(cd[last1])),
            "c_D_change_last_0.5": float(np.ptp(cd[last05])), "c_L_change_last_1": float(np.ptp(cl[last1]))}


def periodic_figures(co: dict, window: float = WINDOW) -> dict:
    """2D-2: c_D,max and c_L,max over the last ``window``, and St from c_L's period, the mean spacing of its
    upward crossings of its mean there (linearly interpolated), exactly as validate_body_fitted.py's dfg2."""
    t, cd, cl_all = co["t"], co["Cd"], co["Cl"]
    sel = t > t[-1] - window
    cl, ts = cl_all[sel], t[sel]
    up = np.nonzero((cl[:-1] < cl.mean()) & (cl[1:] >= cl.mean()))[0]
    crossings = ts[up] + (cl.mean() - cl[up]) / (cl[up + 1] - cl[up]) * (ts[up + 1] - ts[up])
    period = float(np.mean(np.diff(crossings))) if crossings.size > 1 else float("nan")
    ubar = 2 * UMAX["dfg2"] / 3
    return {"c_D_max": float(cd[sel].max()), "c_L_max": float(cl.max()), "c_D_min": float(cd[sel].min()),
            "c_L_min": float(cl.min()), "St": D / (period * ubar), "period": period,
            "periods_in_window": int(max(crossings.size - 1, 0)), "window": window}


def _check_mesh(case: Path) -> dict:
    """Cells and the worst non-orthogonality and skewness from checkMesh's log (where it is there)."""
    log = case / "log.checkMesh"
    if not log.is_file():
        return {}
    text = log.read_text()
    out = {}
    for key, pattern in (("cells", r"^\s*cells:\s+(\d+)"),
                         ("max_non_orthogonality_deg", r"Max:\s*([0-9.eE+-]+)\s+average"),
                         ("max_skewness", r"Max skewness = ([0-9.eE+-]+)")):
        m = re.search(pattern, text, re.M)
        if m:
            out[key] = float(m.group(1)) if "." in m.group(1) or "e" in m.group(1) else int(m.group(1))
    out["mesh_ok"] = "Mesh OK" in text
    return out


def _clock_time(case: Path) -> float | None:
    """pimpleFoam's own ClockTime at its last step, from the newest log (this invocation's run)."""
    logs = sorted(case.glob("log.pimpleFoam.*"), key=lambda p: int(p.suffix[1:]))
    if not logs:
        return None
    found = re.findall(r"ClockTime = ([0-9.eE+-]+)", logs[-1].read_text())
    return float(found[-1]) if found else None


def _latest_time(case: Path) -> float:
    """The latest time written (in processor0 for a decomposed case), 0 if none."""
    times = [0.0]
    for folder in (case, case / "processor0"):
        if folder.is_dir():
            times += [float(d.name) for d in folder.iterdir() if d.is_dir() and re.fullmatch(r"[0-9.eE+-]+", d.name)]
    return max(times)


# ---------------------------------------------------------------------------------------------- the command line


def _check(args) -> None:
    """Each option in its range, else InputError naming it, its value and the range."""
    if args.around % 4 or not 32 <= args.around <= 512:
        raise InputError("--around", args.around, "a multiple of 4 in 32 .. 512 (cells round the cylinder)")
    low = 3.0 if args.case == "dfg2" else 0.5     # 2D-2 needs the transient and the window of 2 behind it
    check_range("--t-end", args.t_end, low, 50.0)
    check_range("--max-co", args.max_co, 0.05, 1.0)
    if not 1 <= args.outer <= 5:
        raise InputError("--outer", args.outer, "allowed 1 .. 5 (PIMPLE outer correctors a step; 1 is PISO)")
    cores = os.cpu_count() or 1
    if not 1 <= args.procs <= max(2, cores):
        raise InputError("--procs", args.procs, f"allowed 1 .. {max(2, cores)} (MPI ranks)")


def _missing_openfoam(procs: int) -> list[str]:
    need = ("blockMesh", "checkMesh", "pimpleFoam") + (("mpirun", "decomposePar") if procs > 1 else ())
    return [c for c in need if shutil.which(c) is None]


def _mark(value: float, band: tuple[float, float]) -> str:
    return "in band" if band[0] <= value <= band[1] else ("below" if value < band[0] else "above")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", choices=("dfg", "dfg2"), help="dfg: 2D-1 (Re 20, steady); dfg2: 2D-2 (Re 100, periodic)")
    ap.add_argument("--around", type=int, default=128,
                    help="cells round the cylinder, a multiple of 4 in 32 .. 512 (default 128: about 15 000 cells; "
                         "184: about 30 000)")
    ap.add_argument("--t-end", type=float, default=None, help="end time (default dfg 10, dfg2 8)")
    ap.add_argument("--max-co", type=float, default=MAX_CO,
                    help=f"Courant number of the adjusted step, 0.05 .. 1 (default {MAX_CO:g})")
    ap.add_argument("--outer", type=int, default=OUTER,
                    help=f"PIMPLE outer correctors a step, 1 .. 5 (default {OUTER}; 1: PISO)")
    ap.add_argument("--procs", type=int, default=2, help="MPI ranks (default 2)")
    ap.add_argument("--out", type=Path, default=None, help="case folder (default out/openfoam_dfg/<case>_n<around>)")
    ap.add_argument("--mesh-only", action="store_true", help="write the case and report the mesh, run nothing")
    args = ap.parse_args(argv)
    args.t_end = T_END[args.case] if args.t_end is None else args.t_end
    try:
        _check(args)
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    if not args.mesh_only and (missing := _missing_openfoam(args.procs)):
        print(f"error: OpenFOAM not found ({', '.join(missing)} not on PATH): install it with "
              "`apt-get install openfoam` (Debian/Ubuntu: ESI v1912, whose binaries land in /usr/bin), or source "
              "the etc/bashrc of another installation", file=sys.stderr)
        return 2
    label = "DFG 2D-1" if args.case == "dfg" else "DFG 2D-2"
    case = args.out or Path("out") / "openfoam_dfg" / f"{args.case}_n{args.around}"
    try:
        mesh = write_case(case, args.case, args.around, args.t_end, args.max_co, args.procs, args.outer)
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(f"{label}: {mesh['cells']} cells ({args.around} round the cylinder, {mesh['rings']} radial, first "
          f"{mesh['first_cell']:.2e}), to t = {args.t_end:g} on {args.procs} rank(s); case in {case}", flush=True)
    if args.mesh_only:
        return 0
    start = _latest_time(case)
    if start > 0:
        print(f"  resuming from t = {start:g}", flush=True)
    wall = run(case, args.procs, args.t_end, say=lambda s, **kw: print(s.replace(" B/V", ""), **kw))
    co = read_coefficients(case)
    figures = steady_figures(co) if args.case == "dfg" else periodic_figures(co)
    bands = BANDS[args.case]
    result = {"case": label, "tool": "OpenFOAM pimpleFoam (ESI v1912), tools/openfoam_dfg.py", "around": args.around,
              **mesh, "check_mesh": _check_mesh(case), "t_end": float(co["t"][-1]), "started_from": start,
              "steps": int(co["t"].size), "dt_last": float(co["t"][-1] - co["t"][-2]), "max_co": args.max_co,
              "outer_correctors": args.outer, "procs": args.procs, "convection": CONVECTION,
              "time_scheme": "backward", "wall_s": wall, "pimpleFoam_clock_s": _clock_time(case),
              "wall_note": "pimpleFoam alone: pimpleFoam_clock_s its own ClockTime, wall_s timed from here with the "
                           "start-up (mpirun's too) to 5 s; blockMesh, checkMesh, decomposePar excluded"
                           + (f"; this invocation only, from t = {start:g}" if start > 0 else ""),
              **figures, **{f"band_{k}": v for k, v in bands.items()}}
    (case / "result.json").write_text(json.dumps(result, indent=1))
    clock = result["pimpleFoam_clock_s"]
    print(f"{label}: {mesh['cells']} cells, {result['steps']} steps to t = {result['t_end']:g}; pimpleFoam alone on "
          f"{args.procs} rank(s): {clock if clock is not None else float('nan'):.0f} s wall (its ClockTime), "
          f"{wall:.0f} s with the start-up (to 5 s); blockMesh, checkMesh, decomposePar excluded")
    for key, band in bands.items():
        print(f"  {key:8s} {figures[key]:.5g}   band {band[0]:g} .. {band[1]:g}: {_mark(figures[key], band)}")
    if args.case == "dfg":
        print(f"  c_D changed by {figures['c_D_change_last_1']:.1e} over the last time unit")
    else:
        print(f"  {figures['periods_in_window']} periods in the last {WINDOW:g}")
    print(f"  -> {case / 'result.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
