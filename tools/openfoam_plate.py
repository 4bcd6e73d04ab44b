"""A body-fitted reference for the heaving or pitching thin plate: the same case in OpenFOAM (docs/validation.md).

    python tools/openfoam_plate.py --reduced-velocity 4 [--dof heave|pitch] [--edge-cell 0.0025]
                                   [--reynolds 1000] [--thickness 0.02] [--periods 6] [--procs 2]
                                   [--turbulence sst --reynolds 1e6 --edge-cell 0.005]
    python tools/openfoam_plate.py --dof static --angle 2 [--duration 20] [--turbulence sst --reynolds 1e6]

Why: the plate's flutter derivatives from our CFD miss Theodorsen's by 10-20 % at U/(fB) = 4 whatever the
grid, step, domain or edges (docs/validation.md), and the question left was whether that is the viscous flow or
the immersed boundary.  This tool answers it with a code nobody here wrote and a method that has no
immersed boundary: OpenFOAM's pimpleFoam (laminar, second order in space and time) on a block mesh fitted
to the plate (square edges, cells clustered at its surfaces and edges), the whole mesh moving with the plate
as a rigid body.  Same plate, Reynolds number, domain (3 chords from mid-chord to the inflow, 20 to the
outflow, slip sides 3 chords from the centre line), thesis amplitude and fit (whole periods after the
transient, bridge.aero.frequency_response) as `python tools/validate_aero.py`.

With ``--turbulence sst`` the same case runs OpenFOAM's kOmegaSST (the 2003 variant, as bridge.cfd.turbulence)
with our freestream k and omega and Spalding's wall function for nut on the plate: a body-fitted reference for
the SST runs of `python tools/validate_aero.py --turbulence sst` (docs/validation.md, row 22).

Heave is a rigid translation of the whole mesh (``oscillatingLinearMotion``).  Pitch rotates the plate's
surface about its mid-chord and deforms the mesh around it (``displacementLaplacian`` with
``angularOscillatingDisplacement`` on the plate), so that the inflow, outflow and sides stay where they are.
``--dof static`` turns the plate to ``--angle`` the same way (over the first B/V) and holds it there: the steady
C_D, C_L, C_M (averaged over the last quarter of ``--duration``) beside the thin plate's potential flow, a
reference for ``bridge.aero.static``, and the pressure along the chord, averaged over the same quarter
(:func:`plate_loading`; ``tools/plate_loading.py --openfoam CASE`` puts it beside ours).

Needs OpenFOAM (ESI v1912 was used: Debian's package ``openfoam``, ``apt-get install openfoam``); not a
dependency of the project.  Writes the case to ``--out`` (default out/openfoam_plate/<case>), runs
blockMesh, decomposePar and pimpleFoam on ``--procs`` cores showing progress, resumes from the last
written time if rerun, and prints the derivatives beside Theodorsen's; the numbers go to ``result.json``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.aero.forced_motion import THESIS_HEAVE_RATE, THESIS_PITCH_RATE  # noqa: E402
from bridge.aero.frequency_response import forced_motion_response  # noqa: E402
from bridge.flutter.aerodynamics import Theodorsen  # noqa: E402
from bridge.flutter.derivatives import FRF, derivatives_from_frf  # noqa: E402

UPSTREAM, DOWNSTREAM, HALF_HEIGHT = 3.0, 20.0, 3.0      # the standard preset's domain, chords from mid-chord
PROVIDES = {"heave": ("h_pu", "h_mu"), "pitch": ("h_ptheta", "h_mtheta")}
DERIVATIVES = {"heave": ("H1", "H4", "A1", "A4"), "pitch": ("H2", "H3", "A2", "A3")}

HEADER = """FoamFile
{{
    version 2.0;
    format ascii;
    class {cls};
    object {obj};
}}
"""


# ---------------------------------------------------------------------------------------------- the mesh


def graded(length: float, first: float, largest: float, growth: float) -> list[tuple[float, int, float]]:
    """Cells along an edge of ``length``: from ``first`` growing by about ``growth`` per cell to
    ``largest``, then uniform.  Segments (length, cells, last cell / first cell) for blockMesh."""
    if first >= largest:
        return [(length, max(1, round(length / first)), 1.0)]
    n = max(2, math.ceil(math.log(largest / first) / math.log(growth)) + 1)
    r = (largest / first) ** (1.0 / (n - 1))
    grown = first * (r ** n - 1.0) / (r - 1.0)
    if grown >= length:      # the edge ends before the cells reach ``largest``: grow over all of it
        n = max(2, math.ceil(math.log(1.0 + length * (growth - 1.0) / first) / math.log(growth)))
        lo, hi = 1.0 + 1e-9, 2.0       # the ratio r with first (r^n - 1) / (r - 1) = length
        for _ in range(200):
            r = 0.5 * (lo + hi)
            (lo, hi) = (r, hi) if first * (r ** n - 1.0) / (r - 1.0) < length else (lo, r)
        return [(length, n, r ** (n - 1))]
    return [(grown, n, largest / first), (length - grown, max(1, math.ceil((length - grown) / largest - 1e-9)), 1.0)]


def reverse(segments):
    return [(seg_len, n, 1.0 / e) for seg_len, n, e in reversed(segments)]


def grading_spec(segments) -> tuple[int, str]:
    """blockMesh's multi-grading for ``segments`` (fractions of length and of cells, expansion)."""
    total_len, total_n = sum(s[0] for s in segments), sum(s[1] for s in segments)
    parts = " ".join(f"({s[0] / total_len:.12g} {s[1] / total_n:.12g} {s[2]:.12g})" for s in segments)
    return total_n, f"({parts})"


def block_mesh_dict(edge: float, thickness: float, growth: float) -> tuple[str, int]:
    """The plate (chord 1, mid-chord at the origin) in 8 blocks round it; cells of ``edge`` at its surfaces
    and edges, at most ``growth`` larger from cell to cell, 20 per chord in the near wake (to 8 chords behind
    the plate: the wake at U/(fB) = 4 sheds 4 chords a period), 10 per chord at the far boundaries."""
    half = 0.5 * thickness
    wake = 0.05
    xs = [-UPSTREAM, -0.5, 0.5, DOWNSTREAM]
    ys = [-HALF_HEIGHT, -half, half, HALF_HEIGHT]
    up = reverse(graded(UPSTREAM - 0.5, edge, 0.1, growth))
    chord = graded(0.5, edge, 0.01, growth)
    chord = chord + reverse(chord)
    near = graded(7.5, edge, wake, growth)
    down = near + graded(DOWNSTREAM - 8.0, wake, 0.1, growth)
    side = graded(HALF_HEIGHT - half, edge, 0.1, growth)
    across = [(thickness, max(2, round(thickness / edge)), 1.0)]
    x_spec = [grading_spec(s) for s in (up, chord, down)]
    y_spec = [grading_spec(s) for s in (reverse(side), across, side)]

    def v(i, j, k):
        return k * 16 + j * 4 + i

    verts = "\n".join(f"    ({x:.12g} {y:.12g} {z:g})" for z in (0.0, 1.0) for y in ys for x in xs)
    blocks, cells = [], 0
    for j in range(3):
        for i in range(3):
            if (i, j) == (1, 1):
                continue      # the plate
            hexv = " ".join(str(n) for n in (v(i, j, 0), v(i + 1, j, 0), v(i + 1, j + 1, 0), v(i, j + 1, 0),
                                             v(i, j, 1), v(i + 1, j, 1), v(i + 1, j + 1, 1), v(i, j + 1, 1)))
            (nx, gx), (ny, gy) = x_spec[i], y_spec[j]
            blocks.append(f"    hex ({hexv}) ({nx} {ny} 1) simpleGrading ({gx} {gy} 1)")
            cells += nx * ny

    def face(a, b):     # the side face through bottom vertices a and b
        return f"({a} {b} {b + 16} {a + 16})"

    inlet = [face(v(0, j, 0), v(0, j + 1, 0)) for j in range(3)]
    outlet = [face(v(3, j, 0), v(3, j + 1, 0)) for j in range(3)]
    bottom = [face(v(i, 0, 0), v(i + 1, 0, 0)) for i in range(3)]
    top = [face(v(i, 3, 0), v(i + 1, 3, 0)) for i in range(3)]
    plate = [face(v(1, 1, 0), v(2, 1, 0)), face(v(1, 2, 0), v(2, 2, 0)),
             face(v(1, 1, 0), v(1, 2, 0)), face(v(2, 1, 0), v(2, 2, 0))]
    empty = []
    for j in range(3):
        for i in range(3):
            if (i, j) != (1, 1):
                empty.append(f"({v(i, j, 0)} {v(i, j + 1, 0)} {v(i + 1, j + 1, 0)} {v(i + 1, j, 0)})")
                empty.append(f"({v(i, j, 1)} {v(i + 1, j, 1)} {v(i + 1, j + 1, 1)} {v(i, j + 1, 1)})")

    def patch(name, kind, faces):
        body = "\n".join(f"            {f}" for f in faces)
        return f"    {name}\n    {{\n        type {kind};\n        faces\n        (\n{body}\n        );\n    }}"

    text = (HEADER.format(cls="dictionary", obj="blockMeshDict") + "convertToMeters 1;\n\nvertices\n(\n" + verts
            + "\n);\n\nblocks\n(\n" + "\n".join(blocks) + "\n);\n\nedges ();\n\nboundary\n(\n"
            + "\n".join([patch("inlet", "patch", inlet), patch("outlet", "patch", outlet),
                         patch("bottom", "patch", bottom), patch("top", "patch", top),
                         patch("plate", "wall", plate), patch("frontAndBack", "empty", empty)])
            + "\n);\n\nmergePatchPairs ();\n")
    return text, cells


# ---------------------------------------------------------------------------------------------- the case


def control_dict(end_time: float, delta_t: str, write_interval: float, max_co: float, max_delta_t: str,
                 functions: str) -> str:
    """system/controlDict of a pimpleFoam case: adjustable steps at ``max_co``, written every ``write_interval``
    (the last two kept, binary), restarted from the latest time; ``functions`` the function objects' entries."""
    return HEADER.format(cls="dictionary", obj="controlDict") + f"""
application pimpleFoam;
startFrom latestTime;
startTime 0;
stopAt endTime;
endTime {end_time:.12g};
deltaT {delta_t};
writeControl adjustableRunTime;
writeInterval {write_interval:.12g};
purgeWrite 2;
writeFormat binary;
writePrecision 12;
timeFormat general;
timePrecision 12;
runTimeModifiable no;
adjustTimeStep yes;
maxCo {max_co:g};
maxDeltaT {max_delta_t};
functions
{{
{functions}}}
"""


def write_case(case: Path, dof: str, K: float, amplitude: float, reynolds: float, thickness: float,
               edge: float, growth: float, end_time: float, write_interval: float, procs: int, max_co: float,
               turbulence: str = "laminar", angle: float = 0.0) -> int:
    """The case folder; ``dof`` heave or pitch (``amplitude`` in chords or rad at ``K``), or static: the plate
    held at ``angle`` (rad, nose-up), turned there over the first STATIC_RAMP."""
    for sub in ("system", "constant", "0"):
        (case / sub).mkdir(parents=True, exist_ok=True)
    mesh, cells = block_mesh_dict(edge, thickness, growth)
    (case / "system" / "blockMeshDict").write_text(mesh)
    # held still: the pressure averaged over the last quarter too (pMean, read by plate_surface_pressure)
    average = "" if dof != "static" else f"""
    pAverage
    {{
        type fieldAverage;
        libs ("libfieldFunctionObjects.so");
        timeStart {0.75 * end_time:.12g};
        writeControl writeTime;
        fields (p {{ mean on; prime2Mean off; base time; }});
    }}"""
    functions = f"""    forces
    {{
        type forces;
        libs ("libforces.so");
        patches (plate);
        rho rhoInf;
        rhoInf 1;
        CofR (0 0 0);
        writeControl timeStep;
        writeInterval 1;
        log false;
    }}{average}
"""
    text = control_dict(end_time, f"{0.2 * edge:.6g}", write_interval, max_co, "1", functions)
    (case / "system" / "controlDict").write_text(text)
    (case / "system" / "fvSchemes").write_text(HEADER.format(cls="dictionary", obj="fvSchemes") + """
ddtSchemes { default backward; }
gradSchemes { default Gauss linear; }
divSchemes
{
    default none;
    div(phi,U) Gauss linearUpwind grad(U);
    div((nuEff*dev2(T(grad(U))))) Gauss linear;
    div(phi,k) Gauss linearUpwind grad(k);
    div(phi,omega) Gauss linearUpwind grad(omega);
}
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes { default corrected; }
wallDist { method meshWave; }
""")
    (case / "system" / "fvSolution").write_text(HEADER.format(cls="dictionary", obj="fvSolution") + """
solvers
{
    p { solver GAMG; smoother GaussSeidel; tolerance 1e-6; relTol 0.05; }
    pFinal { $p; relTol 0; }
    "pcorr.*" { $p; tolerance 1e-6; relTol 0; }
    "(U|k|omega)(|Final)" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-8; relTol 0; }
    cellDisplacement { solver PCG; preconditioner DIC; tolerance 1e-10; relTol 0; }
    cellDisplacementFinal { $cellDisplacement; }
}
PIMPLE
{
    momentumPredictor yes;
    nOuterCorrectors 1;
    nCorrectors 2;
    nNonOrthogonalCorrectors 0;     // the mesh is orthogonal
    correctPhi no;
}
""")
    (case / "system" / "decomposeParDict").write_text(HEADER.format(cls="dictionary", obj="decomposeParDict") + f"""
numberOfSubdomains {procs};
method simple;
coeffs {{ n ({procs} 1 1); delta 0.001; }}
""")
    (case / "constant" / "transportProperties").write_text(
        HEADER.format(cls="dictionary", obj="transportProperties")
        + f"\ntransportModel Newtonian;\nnu {1.0 / reynolds:.12g};\n")
    (case / "constant" / "turbulenceProperties").write_text(
        HEADER.format(cls="dictionary", obj="turbulenceProperties")
        + ("\nsimulationType laminar;\n" if turbulence == "laminar" else
           "\nsimulationType RAS;\nRAS\n{\n    RASModel kOmegaSST;\n    turbulence on;\n    printCoeffs on;\n}\n"))
    if turbulence == "sst":
        _write_turbulence_fields(case, reynolds)
    if dof == "heave":
        motion = f"""
motionSolver solidBody;
solidBodyMotionFunction oscillatingLinearMotion;
amplitude (0 {amplitude:.12g} 0);
omega {K:.12g};
"""
    else:
        motion = """
motionSolver displacementLaplacian;
diffusivity inverseDistance (plate);
"""
    (case / "constant" / "dynamicMeshDict").write_text(
        HEADER.format(cls="dictionary", obj="dynamicMeshDict")
        + "\ndynamicFvMesh dynamicMotionSolverFvMesh;\nmotionSolverLibs (\"libfvMotionSolvers.so\");\n" + motion)
    far = "inlet|outlet|bottom|top"
    (case / "0" / "U").write_text(HEADER.format(cls="volVectorField", obj="U") + """
dimensions [0 1 -1 0 0 0 0];
internalField uniform (1 0 0);
boundaryField
{
    inlet { type fixedValue; value uniform (1 0 0); }
    outlet { type inletOutlet; inletValue uniform (0 0 0); value uniform (1 0 0); }
    "(bottom|top)" { type slip; }
    plate { type movingWallVelocity; value uniform (0 0 0); }
    frontAndBack { type empty; }
}
""")
    (case / "0" / "p").write_text(HEADER.format(cls="volScalarField", obj="p") + """
dimensions [0 2 -2 0 0 0 0];
internalField uniform 0;
boundaryField
{
    inlet { type zeroGradient; }
    outlet { type fixedValue; value uniform 0; }
    "(bottom|top)" { type zeroGradient; }
    plate { type zeroGradient; }
    frontAndBack { type empty; }
}
""")
    if dof == "static":
        _write_static_rotation(case, angle, end_time, far)
    elif dof == "pitch":    # nose-up is clockwise: a negative rotation about z
        _write_point_displacement(case, far, f"""type angularOscillatingDisplacement;
        axis (0 0 -1);
        origin (0 0 0);
        angle0 0;
        amplitude {amplitude:.12g};
        omega {K:.12g};""")
    return cells


STATIC_RAMP = 1.0   # B/V over which the static case turns the plate to its angle


def _write_static_rotation(case: Path, angle: float, end_time: float, far: str) -> None:
    """The plate turned nose-up (clockwise: a negative rotation about z) to ``angle`` along a half-cosine over
    STATIC_RAMP, then held (``tabulated6DoFMotion`` on the plate's points, the mesh deformed round it).  Turned
    in one step instead, the plate's edges moved at 15 V on the 0.005-chord mesh and the solver failed."""
    times = np.linspace(0.0, STATIC_RAMP, 21)
    degrees = -math.degrees(angle) * 0.5 * (1.0 - np.cos(np.pi * times / STATIC_RAMP))
    rows = [(t, d) for t, d in zip(times, degrees, strict=True)] + [(max(end_time, STATIC_RAMP) + 1.0, degrees[-1])]
    (case / "constant" / "rotation.dat").write_text(
        f"{len(rows)}\n(\n" + "".join(f"({t:.12g} ((0 0 0) (0 0 {d:.12g})))\n" for t, d in rows) + ")\n")
    _write_point_displacement(case, far, """type solidBodyMotionDisplacement;
        solidBodyMotionFunction tabulated6DoFMotion;
        CofG (0 0 0);
        timeDataFileName "$FOAM_CASE/constant/rotation.dat";""")


def _write_point_displacement(case: Path, far: str, plate: str) -> None:
    """0/pointDisplacement of the deforming mesh: the far boundaries fixed, the plate's points moved as
    ``plate`` (its boundary entry without the value) says."""
    header = HEADER.format(cls="pointVectorField", obj="pointDisplacement")
    (case / "0" / "pointDisplacement").write_text(header + f"""
dimensions [0 1 0 0 0 0 0];
internalField uniform (0 0 0);
boundaryField
{{
    "({far})" {{ type fixedValue; value uniform (0 0 0); }}
    plate
    {{
        {plate}
        value uniform (0 0 0);
    }}
    frontAndBack {{ type empty; }}
}}
""")


def _write_turbulence_fields(case: Path, reynolds: float) -> None:
    """k, omega and nut for OpenFOAM's kOmegaSST (Menter, Kuntz and Langtry 2003, as bridge.cfd.turbulence):
    the freestream values of our runs (bridge.cfd.turbulence.freestream_turbulence: intensity 0.1 %, eddy
    viscosity a hundredth of nu), and on the plate Spalding's wall function for nut, as ours, with OpenFOAM's
    standard k and omega wall functions."""
    from bridge.cfd.turbulence import freestream_turbulence

    k_inf, omega_inf = freestream_turbulence(1.0, 1.0 / reynolds)
    fields = {"k": ("[0 2 -2 0 0 0 0]", k_inf, "kqRWallFunction"),
              "omega": ("[0 0 -1 0 0 0 0]", omega_inf, "omegaWallFunction"),
              "nut": ("[0 2 -1 0 0 0 0]", 0.0, "nutUSpaldingWallFunction")}
    for name, (dims, value, wall) in fields.items():
        far = ("inlet { type calculated; value uniform 0; }\n    outlet { type calculated; value uniform 0; }"
               if name == "nut" else
               f"inlet {{ type fixedValue; value uniform {value:.12g}; }}\n"
               f"    outlet {{ type inletOutlet; inletValue uniform {value:.12g}; value uniform {value:.12g}; }}")
        sides = "calculated; value uniform 0" if name == "nut" else "zeroGradient"
        (case / "0" / name).write_text(HEADER.format(cls="volScalarField", obj=name) + f"""
dimensions {dims};
internalField uniform {value:.12g};
boundaryField
{{
    {far}
    "(bottom|top)" {{ type {sides}; }}
    plate {{ type {wall}; value uniform {value:.12g}; }}
    frontAndBack {{ type empty; }}
}}
""")


def _foam_env() -> dict:
    env = dict(os.environ)
    if "WM_PROJECT_DIR" not in env and Path("/usr/share/openfoam/etc/controlDict").exists():
        env["WM_PROJECT_DIR"] = "/usr/share/openfoam"      # Debian's package, without its bashrc sourced
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    return env


def run(case: Path, procs: int, end_time: float, say=print) -> float:
    """blockMesh and decomposePar (first time only), then pimpleFoam from the latest written time, with
    progress every ~30 s.  Returns the solver's wall time in seconds."""
    env = _foam_env()

    def step(*cmd, log):
        with open(case / log, "w") as out:
            rc = subprocess.run(cmd, cwd=case, stdout=out, stderr=subprocess.STDOUT, env=env).returncode
        if rc != 0:
            raise SystemExit(f"{' '.join(cmd)} failed (exit {rc}): see {case / log}")

    if not (case / "constant" / "polyMesh" / "points").exists():
        step("blockMesh", log="log.blockMesh")
        step("checkMesh", log="log.checkMesh")
    if procs > 1 and not (case / "processor0").exists():
        step("decomposePar", "-force", log="log.decomposePar")
    cmd = (["mpirun", "-np", str(procs), "pimpleFoam", "-parallel"] if procs > 1 else ["pimpleFoam"])
    logs = sorted(case.glob("log.pimpleFoam.*"))
    log = case / f"log.pimpleFoam.{len(logs)}"
    t0 = time.time()
    with open(log, "w") as out:
        proc = subprocess.Popen(cmd, cwd=case, stdout=out, stderr=subprocess.STDOUT, env=env)
        pattern = re.compile(rb"^Time = ([0-9.eE+-]+)", re.M)
        first, last_say = None, t0
        while proc.poll() is None:
            time.sleep(5)
            if time.time() - last_say < 30:
                continue
            last_say = time.time()
            tail = log.read_bytes()[-20000:]
            times = pattern.findall(tail)
            if not times:
                continue
            now, wall = float(times[-1]), time.time()
            first = (now, wall) if first is None else first     # the rate from the first report on
            rate = (now - first[0]) / max(wall - first[1], 1e-9)
            left = f"about {(end_time - now) / rate / 60:.0f} min left" if rate > 0 else "rate not known yet"
            say(f"  t = {now:.2f} of {end_time:.2f} B/V, {wall - t0:.0f} s, {left}", flush=True)
    if proc.returncode != 0:
        raise SystemExit(f"pimpleFoam failed (exit {proc.returncode}): see {log}")
    return time.time() - t0


# ---------------------------------------------------------------------------------------------- the forces


def _numbers(line: str) -> list[float]:
    return [float(s) for s in line.replace("(", " ").replace(")", " ").split()]


def read_forces(case: Path) -> dict:
    """Time, total force (x, y) and moment z about the origin, merged over restarts (a later start wins).
    A restart from a time that already has a folder writes ``force_0.dat``, ``force_1.dat``, ... beside the
    first ``force.dat`` (OpenFOAM keeps the old file): those are read in that order, each newer file from its
    first time on replacing what the older ones held."""
    root = case / "postProcessing" / "forces"
    starts = sorted(root.iterdir(), key=lambda p: float(p.name))
    series = {}

    def order(path: Path) -> int:      # force.dat first, then force_0.dat, force_1.dat, ...
        tail = path.stem.partition("_")[2]
        return int(tail) + 1 if tail.isdigit() else 0

    for start in starts:
        forces = sorted(start.glob("force*.dat"), key=order)
        if not forces:
            raise SystemExit(f"no force.dat in {start}: the forces function object wrote something else")
        for force in forces:
            moment = start / force.name.replace("force", "moment", 1)
            f = [_numbers(s) for s in force.read_text().splitlines() if s and not s.startswith("#")]
            m = [_numbers(s) for s in moment.read_text().splitlines() if s and not s.startswith("#")]
            if not f:
                continue
            t0 = min(float(start.name), f[0][0])
            for k in [k for k in series if k >= t0]:
                del series[k]
            for rf, rm in zip(f, m, strict=False):
                series[rf[0]] = (rf[1], rf[2], rm[3])
    t = np.array(sorted(series))
    data = np.array([series[k] for k in t])
    return {"t": t, "fx": data[:, 0], "fy": data[:, 1], "mz": data[:, 2]}


def derivatives(dof: str, K: float, amplitude: float, forces: dict, discard: int) -> dict:
    """Lift up and moment nose-up about the mid-chord, the first harmonics over whole periods after
    ``discard`` and the derivatives of ``dof`` beside Theodorsen's."""
    t = forces["t"]
    motion = amplitude * np.sin(K * t)
    lift = forces["fy"]
    if dof == "heave":   # the moment about the plate's mid-chord, which is at (0, h(t)) while the origin stays
        moment = -(forces["mz"] + motion * forces["fx"])
    else:
        moment = -forces["mz"]
    T = 2 * math.pi / K
    n = int(math.floor(t[-1] / T + 1e-9))
    sel = (t >= discard * T - 1e-9) & (t <= n * T + 1e-9)
    (resp,) = forced_motion_response(t[sel], motion[sel], [K], dof=dof, speed_m_s=1.0, deck_width_m=1.0,
                                     air_density_kg_m3=1.0, lift=lift[sel], moment=moment[sel], fundamental=K)
    ref = Theodorsen().frf(np.array([K]), 1.0)
    h = {name: complex(getattr(resp.frf, name)) for name in PROVIDES[dof]}
    frf = FRF(*(np.array([h.get(name, complex(np.asarray(getattr(ref, name))[0]))])
                for name in ("h_pu", "h_ptheta", "h_mu", "h_mtheta")))
    cfd, theo = derivatives_from_frf(np.array([K]), frf), derivatives_from_frf(np.array([K]), ref)
    out = {"periods_fitted": int(resp.periods), "frf": {k: [v.real, v.imag] for k, v in h.items()}}
    for name in DERIVATIVES[dof]:
        c, r = float(np.asarray(getattr(cfd, name))[0]), float(np.asarray(getattr(theo, name))[0])
        out[name] = {"openfoam": c, "theodorsen": r, "relative_difference": (c - r) / abs(r)}
    return out


# ---------------------------------------------------------------------------------------------- the plate's pressure


def _foam_body(path: Path) -> tuple[bytes, bool, bytes]:
    """The bytes of an OpenFOAM file after its FoamFile header, whether it is written in binary, and its class."""
    raw = path.read_bytes()
    head = raw.index(b"FoamFile")
    end = raw.index(b"}", head)
    cls = re.search(rb"class\s+(\w+)", raw[head:end])
    return raw[end + 1:], re.search(rb"format\s+binary", raw[head:end]) is not None, cls.group(1) if cls else b""


def _foam_list(data: bytes, binary: bool, dtype, width: int = 1, start: int = 0) -> tuple[np.ndarray, int]:
    """The first ``N ( ... )`` list at or after ``start`` (N items of ``width`` numbers) and where it ends."""
    m = re.compile(rb"(\d+)\s*\(").search(data, start)
    if m is None:
        raise ValueError("no list found")
    n, i = int(m.group(1)), m.end()
    if binary:
        values = np.frombuffer(data, dtype=dtype, count=n * width, offset=i)
        return values.reshape(n, width) if width > 1 else values, i + values.nbytes + 1
    depth, j = 1, i
    while depth:
        depth += {40: 1, 41: -1}.get(data[j], 0)   # "(" and ")"
        j += 1
    text = data[i:j - 1].replace(b"(", b" ").replace(b")", b" ").split()
    values = np.array(text, dtype=dtype)
    if values.size != n * width:
        raise ValueError(f"a list of {n} x {width} holds {values.size} numbers")
    return values.reshape(n, width) if width > 1 else values, j


def _foam_faces(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """A mesh's faces as (offsets, point labels): a faceCompactList (binary, as this tool's cases write it) or
    an ascii faceList (``N ( 4(a b c d) ... )``, as foamFormatConvert to ascii writes it)."""
    data, binary, cls = _foam_body(path)
    if binary or cls == b"faceCompactList":
        offsets, end = _foam_list(data, binary, "<i4")
        labels, _ = _foam_list(data, binary, "<i4", start=end)
        return offsets, labels
    m = re.compile(rb"(\d+)\s*\(").search(data)
    faces = [np.array(f.split(), dtype=np.int32) for f in re.findall(rb"\d+\s*\(([^()]*)\)", data[m.end():])]
    if len(faces) != int(m.group(1)):
        raise ValueError(f"{path}: {len(faces)} faces read, {int(m.group(1))} announced")
    return np.concatenate([[0], np.cumsum([f.size for f in faces])]), np.concatenate(faces)


def plate_surface_pressure(case: Path, time: str | None = None) -> dict:
    """The pressure on the plate's upper and lower faces at ``time`` (default: the latest written), as C_p.

    The plate turns as a rigid body, so its faces keep their places in the mesh as written at the start
    (constant/polyMesh), which is the plate's own frame: x from the leading edge in chords, the upper side at
    y > 0.  The wall takes its cell's pressure (zeroGradient; OpenFOAM's p is per density, the reference that of
    the outflow): the time average ``pMean`` where the folder holds one (a static case's last quarter), else the
    pressure of that instant.  Returns ``x``, ``width`` (the face's extent along the chord) and ``cp`` for each
    side, and which ``field`` was read."""
    folder = _time_folder(case, time)
    mesh = _PlateMesh(case)
    field = "pMean" if (folder / "pMean").is_file() else "p"     # the time average where the case wrote one
    cp = _foam_field(folder / field)[mesh.owner[mesh.plate]] / 0.5
    out = {"time": float(folder.name), "field": field}
    for side, sel in mesh.sides():
        out[side] = {"x": mesh.centre[sel, 0] + 0.5, "width": mesh.width[sel], "cp": cp[sel]}
    return out


def _time_folder(case: Path, time: str | None) -> Path:
    """The case's folder of ``time``, by default the latest that holds a pressure field."""
    case = Path(case)
    if time is not None:
        return case / time
    times = sorted((d for d in case.iterdir() if d.is_dir() and re.fullmatch(r"[0-9.eE+-]+", d.name)
                    and (d / "p").is_file()), key=lambda d: float(d.name))
    if not times:
        raise SystemExit(f"{case}: no time folder with a pressure field")
    return times[-1]


def _foam_field(path: Path, width: int = 1) -> np.ndarray:
    """A volume field's values in the cells (its internalField: a nonuniform list)."""
    data, binary, _ = _foam_body(path)
    return _foam_list(data, binary, "<f8", width, start=data.index(b"internalField"))[0]


class _PlateMesh:
    """The case's mesh as written at the start (constant/polyMesh): the points, the faces, their owner cells,
    and the faces of the patch ``plate`` (``plate``: their indices; ``centre``, ``width``: along the chord)."""

    def __init__(self, case: Path):
        mesh = Path(case) / "constant" / "polyMesh"
        pts, binary, _ = _foam_body(mesh / "points")
        self.points, _ = _foam_list(pts, binary, "<f8", 3)
        self.offsets, self.labels = _foam_faces(mesh / "faces")
        ob, binary, _ = _foam_body(mesh / "owner")
        self.owner, _ = _foam_list(ob, binary, "<i4")
        self.mesh = mesh
        entry = re.search(r"\bplate\s*\{([^}]*)\}", (mesh / "boundary").read_text())
        if entry is None:
            raise SystemExit(f"{mesh / 'boundary'}: no patch 'plate'")
        n = int(re.search(r"nFaces\s+(\d+)", entry.group(1)).group(1))
        first = int(re.search(r"startFace\s+(\d+)", entry.group(1)).group(1))
        self.plate = np.arange(first, first + n)
        faces = [self.labels[self.offsets[f]:self.offsets[f + 1]] for f in self.plate]
        self.centre = np.array([self.points[f].mean(axis=0) for f in faces])
        self.width = np.array([np.ptp(self.points[f, 0]) for f in faces])

    def sides(self):
        """("upper" | "lower", indices into ``plate``, ordered along the chord) for the two flat sides (the edges'
        faces have no extent along x)."""
        flat = self.width > 1e-9
        for side, sel in (("upper", flat & (self.centre[:, 1] > 0)), ("lower", flat & (self.centre[:, 1] < 0))):
            idx = np.nonzero(sel)[0]
            yield side, idx[np.argsort(self.centre[idx, 0])]

    def cell_centres(self) -> np.ndarray:
        """Each cell's centre as the mean of its faces' centres (exact for the cells of this tool's blockMesh,
        which are rectangles at the start)."""
        nb, binary, _ = _foam_body(self.mesh / "neighbour")
        neighbour, _ = _foam_list(nb, binary, "<i4")
        counts = np.diff(self.offsets)
        face_centres = np.add.reduceat(self.points[self.labels], self.offsets[:-1], axis=0) / counts[:, None]
        n_cells = int(self.owner.max()) + 1
        total, faces = np.zeros((n_cells, 3)), np.zeros(n_cells)
        for cells, centres in ((self.owner, face_centres[:self.owner.size]),
                               (neighbour, face_centres[:neighbour.size])):
            np.add.at(total, cells, centres)
            np.add.at(faces, cells, 1.0)
        return total / faces[:, None]


def plate_loading(case: Path, angle_deg: float, time: str | None = None) -> dict:
    """Delta C_p along the chord from :func:`plate_surface_pressure`, the upper faces' pressure taken at the
    lower faces' x (the two sides' faces match on this mesh): ``x``, ``delta_cp``, ``time`` and ``loading``
    (bridge.aero.static.chordwise_loading)."""
    from bridge.aero.static import chordwise_loading

    s = plate_surface_pressure(case, time)
    up, lo = s["upper"], s["lower"]
    delta = lo["cp"] - np.interp(lo["x"], up["x"], up["cp"])
    return {"x": lo["x"], "delta_cp": delta, "time": s["time"], "field": s["field"],
            "loading": chordwise_loading(lo["x"], delta, lo["width"], math.radians(angle_deg))}


def plate_eddy_viscosity(case: Path, angle_deg: float, nu: float, height: float = 0.05,
                         time: str | None = None) -> dict:
    """Along the plate's upper side at ``time`` (default: the latest written): the largest eddy viscosity over
    nu in the cells within ``height`` (chords) above each face, and the velocity along the chord (leading to
    trailing edge; the plate turned nose-up by ``angle_deg``) in the face's own cell, the first off the wall.
    The cells are placed as written at the start (constant/polyMesh), the plate's own frame, as the pressure
    reader's faces are: the mesh deforms round the turning plate so that the cells this close to it turn with it.
    Returns ``x`` (from the leading edge), ``nut_over_nu_max``, ``first_cell_height`` and ``first_cell_u``."""
    folder = _time_folder(case, time)
    mesh = _PlateMesh(case)
    centres = mesh.cell_centres()
    nut = _foam_field(folder / "nut")
    velocity = _foam_field(folder / "U", 3)
    a = math.radians(angle_deg)
    along = velocity[:, 0] * math.cos(a) - velocity[:, 1] * math.sin(a)
    idx = dict(mesh.sides())["upper"]
    peak = []
    for x, w, top in zip(mesh.centre[idx, 0], mesh.width[idx], mesh.centre[idx, 1], strict=True):
        above = centres[:, 1] - top
        column = (np.abs(centres[:, 0] - x) < 0.25 * w) & (above > 0) & (above < height)
        peak.append(float(nut[column].max()) / nu if column.any() else float("nan"))
    first = mesh.owner[mesh.plate[idx]]
    return {"time": float(folder.name), "x": mesh.centre[idx, 0] + 0.5, "nut_over_nu_max": np.array(peak),
            "first_cell_height": centres[first, 1] - mesh.centre[idx, 1], "first_cell_u": along[first]}


def static_coefficients(angle: float, forces: dict, average_from: float) -> dict:
    """Drag, lift (wind axes: the stream is along x) and nose-up moment about the mid-chord per 1/2 rho V^2 B
    (and B^2), averaged from ``average_from`` on, with their standard deviation there (the flow's
    unsteadiness), beside the thin plate's potential-flow 2 pi alpha and pi alpha / 2."""
    sel = forces["t"] >= average_from
    if not sel.any():
        raise SystemExit(f"no forces after t = {average_from:g}: the run ended at {forces['t'][-1]:g}")
    series = {"C_D": 2 * forces["fx"][sel], "C_L": 2 * forces["fy"][sel], "C_M": -2 * forces["mz"][sel]}
    out = {name: {"mean": float(v.mean()), "std": float(v.std())} for name, v in series.items()}
    out["C_L"]["potential_flow"] = 2 * math.pi * angle
    out["C_M"]["potential_flow"] = math.pi * angle / 2
    for name in ("C_L", "C_M"):
        out[name]["ratio"] = out[name]["mean"] / out[name]["potential_flow"] if angle else float("nan")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--reduced-velocity", type=float, default=4.0, help="U/(fB) (default 4)")
    ap.add_argument("--dof", choices=("heave", "pitch", "static"), default="heave",
                    help="forced heave or pitch, or static: the plate held at --angle (steady coefficients)")
    ap.add_argument("--angle", type=float, default=2.0, help="static: angle of attack, degrees (default 2)")
    ap.add_argument("--duration", type=float, default=20.0,
                    help="static: B/V run (default 20); the last quarter is averaged")
    ap.add_argument("--edge-cell", type=float, default=0.0025, help="cell at the plate, chords (default 0.0025)")
    ap.add_argument("--growth", type=float, default=1.05, help="largest cell-to-cell growth (default 1.05)")
    ap.add_argument("--reynolds", type=float, default=1000.0, help="V B / nu (default 1000, the standard preset)")
    ap.add_argument("--thickness", type=float, default=0.02, help="of the chord (default 0.02)")
    ap.add_argument("--turbulence", choices=("laminar", "sst"), default="laminar",
                    help="laminar (default) or k-omega SST with Spalding's wall function on the plate: the "
                         "edge cell should then put the first cell's centre at y+ 30-100 (about 0.003 at Re 1e6)")
    ap.add_argument("--periods", type=int, default=6, help="periods run (default 6)")
    ap.add_argument("--discard", type=int, default=3, help="periods dropped before the fit (default 3)")
    ap.add_argument("--amplitude-scale", type=float, default=1.0, help="times the thesis amplitude (default 1)")
    ap.add_argument("--max-co", type=float, default=0.8, help="Courant number limit (default 0.8)")
    ap.add_argument("--procs", type=int, default=2, help="MPI ranks (default 2)")
    ap.add_argument("--out", type=Path, default=None, help="case folder (default out/openfoam_plate/<case>)")
    ap.add_argument("--mesh-only", action="store_true", help="write the case and report the mesh, run nothing")
    args = ap.parse_args(argv)
    for name, value, lo in (("--reduced-velocity", args.reduced_velocity, 0.0), ("--edge-cell", args.edge_cell, 0.0),
                            ("--reynolds", args.reynolds, 0.0), ("--thickness", args.thickness, 0.0),
                            ("--amplitude-scale", args.amplitude_scale, 0.0), ("--max-co", args.max_co, 0.0),
                            ("--duration", args.duration, 0.0)):
        if not value > lo:
            ap.error(f"{name}: must be > {lo:g}, got {value:g}")
    if not 1.0 < args.growth <= 1.3:
        ap.error(f"--growth: must be in (1, 1.3], got {args.growth:g}")
    if not abs(args.angle) <= 20.0:
        ap.error(f"--angle: must be in [-20, 20] degrees, got {args.angle:g}")
    if not 0 <= args.discard < args.periods:
        ap.error(f"--discard: must be in [0, --periods), got {args.discard}")
    if not args.mesh_only:
        missing = [c for c in ("blockMesh", "pimpleFoam") + (("mpirun", "decomposePar") if args.procs > 1 else ())
                   if shutil.which(c) is None]
        if missing:
            print(f"error: {', '.join(missing)} not found: install OpenFOAM (apt-get install openfoam)",
                  file=sys.stderr)
            return 2
    tail = ("_sst" if args.turbulence == "sst" else "")
    grid = f"Re{args.reynolds:g}_t{args.thickness:g}_e{args.edge_cell:g}_g{args.growth:g}"
    if args.dof == "static":
        return _static(args, f"static_a{args.angle:g}_{grid}{tail}")
    K = 2 * math.pi / args.reduced_velocity
    rate = THESIS_HEAVE_RATE if args.dof == "heave" else THESIS_PITCH_RATE
    amplitude = args.amplitude_scale * rate / K
    name = f"{args.dof}_U{args.reduced_velocity:g}_{grid}_a{args.amplitude_scale:g}{tail}"
    case = args.out or Path("out") / "openfoam_plate" / name
    T = 2 * math.pi / K
    end_time = args.periods * T
    cells = write_case(case, args.dof, K, amplitude, args.reynolds, args.thickness, args.edge_cell, args.growth,
                       end_time, T, args.procs, args.max_co, args.turbulence)
    print(f"{name}: {cells} cells, {args.periods} periods of {T:.3f} B/V, amplitude "
          f"{amplitude:.5g} {'chords' if args.dof == 'heave' else 'rad'}; case in {case}", flush=True)
    if args.mesh_only:
        return 0
    wall = run(case, args.procs, end_time)
    forces = read_forces(case)
    result = {"case": name, **_common(args, cells, forces, wall), "reduced_velocity": args.reduced_velocity,
              "K": K, "amplitude": amplitude, **derivatives(args.dof, K, amplitude, forces, args.discard)}
    (case / "result.json").write_text(json.dumps(result, indent=1))
    print(f"{cells} cells, {forces['t'].size} steps, {wall:.0f} s; {result['periods_fitted']} periods fitted")
    for n in DERIVATIVES[args.dof]:
        r = result[n]
        print(f"  {n}*: OpenFOAM {r['openfoam']:+.4f}, Theodorsen {r['theodorsen']:+.4f} "
              f"({100 * r['relative_difference']:+.1f} %)")
    return 0


def _common(args, cells: int, forces: dict, wall: float) -> dict:
    return {"dof": args.dof, "reynolds": args.reynolds, "turbulence": args.turbulence, "thickness": args.thickness,
            "edge_cell": args.edge_cell, "growth": args.growth, "cells": cells, "steps": int(forces["t"].size),
            "wall_s": wall}


def _static(args, name: str) -> int:
    """The plate held at --angle for --duration B/V; the coefficients averaged over the last quarter."""
    angle = math.radians(args.angle)
    case = args.out or Path("out") / "openfoam_plate" / name
    cells = write_case(case, "static", 1.0, 0.0, args.reynolds, args.thickness, args.edge_cell, args.growth,
                       args.duration, args.duration / 4, args.procs, args.max_co, args.turbulence, angle=angle)
    print(f"{name}: {cells} cells, held at {args.angle:g} deg for {args.duration:g} B/V; case in {case}",
          flush=True)
    if args.mesh_only:
        return 0
    wall = run(case, args.procs, args.duration)
    forces = read_forces(case)
    coefficients = static_coefficients(angle, forces, 0.75 * args.duration)
    result = {"case": name, **_common(args, cells, forces, wall), "angle_deg": args.angle,
              "duration": args.duration, **coefficients}
    if args.angle:   # where along the chord the plate carries its lift (tools/plate_loading.py compares ours)
        got = plate_loading(case, args.angle)
        loading = got["loading"]
        result["loading"] = {**loading.as_dict(), "pressure_field": got["field"]}
    (case / "result.json").write_text(json.dumps(result, indent=1))
    print(f"{cells} cells, {forces['t'].size} steps, {wall:.0f} s; averaged over t >= {0.75 * args.duration:g}")
    for n, c in coefficients.items():
        ref = (f", {c['ratio']:.3f} x potential flow's {c['potential_flow']:+.4f}" if "ratio" in c else "")
        print(f"  {n}: {c['mean']:+.4f} (sd {c['std']:.1e}){ref}")
    if "loading" in result:
        print(f"  from the plate's pressure ({'averaged' if got['field'] == 'pMean' else 'at the end'}): "
              f"C_L {loading.lift:+.4f}, "
              f"C_M {loading.moment:+.4f}, centre of pressure {loading.centre_of_pressure:.3f} chords from the "
              "leading edge")
    return 0


if __name__ == "__main__":
    sys.exit(main())
