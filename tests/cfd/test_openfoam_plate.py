"""tools/openfoam_plate.py without OpenFOAM: its graded edges, its block mesh and its force conversion
(the loads of Theodorsen's plate, 1935, NACA Report 496, put in as OpenFOAM writes them, give his
derivatives back)."""

import math

import numpy as np
import pytest
from cfd_helpers import load_tool

from bridge.aero.forced_motion import THESIS_HEAVE_RATE, THESIS_PITCH_RATE
from bridge.flutter.aerodynamics import Theodorsen
from bridge.flutter.derivatives import derivatives_from_frf


def _cells(segments):
    """Cell sizes along an edge from blockMesh's (length, cells, last/first) segments."""
    sizes = []
    for length, n, ratio in segments:
        r = ratio ** (1.0 / (n - 1)) if n > 1 else 1.0
        first = length / n if abs(r - 1.0) < 1e-12 else length * (r - 1.0) / (r ** n - 1.0)
        sizes.extend(first * r ** np.arange(n))
    return np.array(sizes)


@pytest.mark.parametrize("length, first, largest, growth", [(2.5, 0.0025, 0.1, 1.05), (0.5, 0.0025, 0.01, 1.05),
                                                            (0.3, 0.001, 0.2, 1.1), (1.0, 0.05, 0.02, 1.05)])
def test_graded_edges_fill_their_length_and_grow_as_asked(length, first, largest, growth):
    of = load_tool("openfoam_plate")
    sizes = _cells(of.graded(length, first, largest, growth))
    assert sizes.sum() == pytest.approx(length, rel=0.02)
    assert sizes[0] == pytest.approx(min(first, length / round(length / first)), rel=0.05)
    assert sizes.max() <= max(largest, first) * 1.05
    assert np.all(sizes[1:] / sizes[:-1] <= growth * 1.02)


def test_block_mesh_has_eight_blocks_round_the_plate_with_right_handed_cells():
    of = load_tool("openfoam_plate")
    text, cells = of.block_mesh_dict(0.005, 0.02, 1.1)
    verts = np.array([[float(v) for v in line.strip()[1:-1].split()]
                      for line in text.split("vertices\n(\n")[1].split("\n);")[0].splitlines()])
    blocks = [line for line in text.splitlines() if line.strip().startswith("hex")]
    assert len(blocks) == 8 and len(verts) == 32
    total = 0
    for line in blocks:
        ids = [int(s) for s in line.split("(")[1].split(")")[0].split()]
        nx, ny, _ = (int(s) for s in line.split(")")[1].split("(")[1].split())
        total += nx * ny
        p0, p1, p3 = verts[ids[0]], verts[ids[1]], verts[ids[3]]
        assert (p1[0] - p0[0]) * (p3[1] - p0[1]) > 0           # counter-clockwise bottom face
        assert verts[ids[4]][2] > p0[2]                          # the top face above it
        # no block covers the plate
        centre = verts[[ids[0], ids[2]]].mean(axis=0)
        assert not (abs(centre[0]) < 0.5 and abs(centre[1]) < 0.01)
    assert total == cells
    plate = text.split("plate\n")[1].split(");")[0]
    assert plate.count("(") - 1 == 4                             # four faces: top, bottom, both edges


@pytest.mark.parametrize("dof", ["heave", "pitch"])
def test_forces_as_openfoam_writes_them_give_theodorsens_derivatives(dof):
    """Theodorsen's loads for the motion a sin(K t) written as OpenFOAM's forces on the plate: the lift
    F_y, a steady drag, the moment about the fixed origin (counter-clockwise, so a nose-up moment is
    negative, and in heave the mid-chord is at (0, h(t)))."""
    of = load_tool("openfoam_plate")
    K = 2 * math.pi / 4
    a = (THESIS_HEAVE_RATE if dof == "heave" else THESIS_PITCH_RATE) / K
    h = Theodorsen().frf(np.array([K]), 1.0)
    t = np.linspace(0.0, 6 * 2 * math.pi / K, 9001)
    e = -1j * a * np.exp(1j * K * t)       # a sin(K t) = Re(-i a e^{iKt})
    lift_h, moment_h = (h.h_pu, h.h_mu) if dof == "heave" else (h.h_ptheta, h.h_mtheta)
    lift = np.real(0.5 * complex(np.asarray(lift_h)[0]) * e)
    nose_up = np.real(0.5 * complex(np.asarray(moment_h)[0]) * e)
    drag = 0.04 + 0 * t
    heave = a * np.sin(K * t) if dof == "heave" else 0 * t
    mz = -nose_up - heave * drag
    out = of.derivatives(dof, K, a, {"t": t, "fx": drag, "fy": lift, "mz": mz}, discard=2)
    ref = derivatives_from_frf(np.array([K]), h)
    for name in of.DERIVATIVES[dof]:
        assert out[name]["openfoam"] == pytest.approx(float(np.asarray(getattr(ref, name))[0]), rel=1e-6), name
        assert abs(out[name]["relative_difference"]) < 1e-6


def test_the_sst_case_has_our_freestream_turbulence_and_spaldings_wall_function(tmp_path):
    """--turbulence sst: OpenFOAM's kOmegaSST with the freestream k, omega of our runs
    (bridge.cfd.turbulence.freestream_turbulence) and Spalding's law for nut on the plate; a laminar case
    writes no turbulence fields."""
    from bridge.cfd.turbulence import freestream_turbulence

    of = load_tool("openfoam_plate")
    args = dict(dof="heave", K=0.785, amplitude=0.01, thickness=0.02, edge=0.01, growth=1.05, end_time=8.0,
                write_interval=8.0, procs=2, max_co=1.0)
    of.write_case(tmp_path / "sst", reynolds=1e6, turbulence="sst", **args)
    props = (tmp_path / "sst" / "constant" / "turbulenceProperties").read_text()
    assert "simulationType RAS;" in props and "RASModel kOmegaSST;" in props
    k_inf, omega_inf = freestream_turbulence(1.0, 1e-6)
    for name, value, wall in (("k", k_inf, "kqRWallFunction"), ("omega", omega_inf, "omegaWallFunction"),
                              ("nut", 0.0, "nutUSpaldingWallFunction")):
        text = (tmp_path / "sst" / "0" / name).read_text()
        assert f"internalField uniform {value:.12g};" in text, name
        assert f"plate {{ type {wall};" in text, name
    assert "div(phi,omega)" in (tmp_path / "sst" / "system" / "fvSchemes").read_text()
    of.write_case(tmp_path / "lam", reynolds=1000.0, **args)
    assert "simulationType laminar;" in (tmp_path / "lam" / "constant" / "turbulenceProperties").read_text()
    assert not any((tmp_path / "lam" / "0" / n).exists() for n in ("k", "omega", "nut"))


def test_a_restart_from_the_same_time_reads_the_newer_force_file(tmp_path):
    """A case rerun from t = 0 after a killed start: OpenFOAM keeps the old force.dat and writes force_0.dat
    beside it; the newer file's series replaces the older one (a killed run's forces are not fitted)."""
    of = load_tool("openfoam_plate")
    folder = tmp_path / "postProcessing" / "forces" / "0"
    folder.mkdir(parents=True)

    def write(suffix, times, lift):
        rows = "".join(f"{t:g} ({2 * lift:g} {lift:g} 0) (0 0 0) (0 0 0)\n" for t in times)
        (folder / f"force{suffix}.dat").write_text("# Time total pressure viscous\n" + rows)
        mrows = "".join(f"{t:g} (0 0 {3 * lift:g}) (0 0 0) (0 0 0)\n" for t in times)
        (folder / f"moment{suffix}.dat").write_text("# Time total pressure viscous\n" + mrows)

    write("", [0.1, 0.2, 0.3], 1.0)            # the killed start
    write("_0", [0.1, 0.2, 0.3, 0.4], 2.0)     # the rerun
    f = of.read_forces(tmp_path)
    assert list(f["t"]) == [0.1, 0.2, 0.3, 0.4]
    assert list(f["fy"]) == [2.0] * 4 and list(f["fx"]) == [4.0] * 4 and list(f["mz"]) == [6.0] * 4


def test_the_static_case_holds_the_plate_at_its_angle_and_averages_the_coefficients(tmp_path):
    """--dof static: the plate's points turned nose-up (clockwise: negative degrees about z) along a smooth
    ramp to the angle and held past the end; the mesh deforms round it; the coefficients are the means over
    the averaging window, per 1/2 rho V^2 B."""
    of = load_tool("openfoam_plate")
    angle = math.radians(2.0)
    of.write_case(tmp_path / "s", "static", 1.0, 0.0, 1e6, 0.02, 0.01, 1.05, 20.0, 5.0, 2, 1.0, "sst",
                  angle=angle)
    text = (tmp_path / "s" / "0" / "pointDisplacement").read_text()
    assert "solidBodyMotionDisplacement" in text and "tabulated6DoFMotion" in text and "CofG (0 0 0);" in text
    assert "displacementLaplacian" in (tmp_path / "s" / "constant" / "dynamicMeshDict").read_text()
    control = (tmp_path / "s" / "system" / "controlDict").read_text()
    assert "fieldAverage" in control and "timeStart 15;" in control     # the pressure over the last quarter
    rows = (tmp_path / "s" / "constant" / "rotation.dat").read_text().splitlines()
    assert int(rows[0]) == len(rows) - 3 and rows[1] == "(" and rows[-1] == ")"
    table = np.array([of._numbers(r) for r in rows[2:-1]])        # t, translation, rotation (degrees)
    assert np.all(table[:, 1:6] == 0.0) and table[0, 0] == 0.0 and table[0, 6] == 0.0
    assert np.all(np.diff(table[:, 0]) > 0) and np.all(np.diff(table[:, 6]) <= 0)    # turning one way only
    assert table[-1, 0] > 20.0 and table[-1, 6] == pytest.approx(-2.0, abs=1e-12)
    ramp = table[np.searchsorted(table[:, 0], of.STATIC_RAMP), 6]
    assert ramp == pytest.approx(-2.0, abs=1e-12)                   # at the angle after the ramp
    t = np.linspace(0.0, 20.0, 2001)
    transient = np.exp(-t)                       # gone by the last quarter
    forces = {"t": t, "fx": 0.012 + transient, "fy": 0.5 * 0.9 * 2 * math.pi * angle + transient,
              "mz": -0.5 * 0.95 * math.pi * angle / 2 + transient}
    c = of.static_coefficients(angle, forces, 15.0)
    assert c["C_D"]["mean"] == pytest.approx(0.024, rel=1e-5)
    assert c["C_L"]["ratio"] == pytest.approx(0.9, rel=1e-5)
    assert c["C_M"]["ratio"] == pytest.approx(0.95, rel=1e-5)
    assert c["C_L"]["std"] < 1e-6
    with pytest.raises(SystemExit):
        of.static_coefficients(angle, forces, 21.0)


def _write_foam(path, cls, body: bytes, binary: bool):
    path.parent.mkdir(parents=True, exist_ok=True)
    head = (f"FoamFile\n{{\n    version 2.0;\n    format {'binary' if binary else 'ascii'};\n    class {cls};\n"
            f'    arch "LSB;label=32;scalar=64";\n    object {path.name};\n}}\n').encode()
    path.write_bytes(head + body)


def _foam_list(values: np.ndarray, binary: bool) -> bytes:
    n = values.shape[0]
    if binary:
        return f"{n}\n(".encode() + np.ascontiguousarray(values).tobytes() + b")\n"
    rows = [("(" + " ".join(repr(float(v)) for v in row) + ")") if values.ndim > 1 else str(row) for row in values]
    return f"{n}\n(\n".encode() + "\n".join(rows).encode() + b"\n)\n"


@pytest.mark.parametrize("binary", [True, False])
def test_the_plates_surface_pressure_is_read_from_the_case_as_openfoam_writes_it(tmp_path, binary):
    """A plate patch of 4 upper, 4 lower and 2 edge faces (quads spanning z), each face's cell holding a known
    pressure: the reader returns each side's faces along the chord with C_p = p / (1/2) (OpenFOAM's p per density,
    V = 1), in binary (as the tool's cases are written) and in ascii (foamFormatConvert's faceList)."""
    of = load_tool("openfoam_plate")
    xs = np.array([-0.5, -0.3, 0.0, 0.2, 0.5])        # uneven faces along the chord
    y = 0.01
    pts = []
    for yy in (y, -y):
        for x in xs:
            pts += [[x, yy, 0.0], [x, yy, 1.0]]
    pts = np.array(pts)
    n_side = xs.size

    def quad(side, k):          # face between chord stations k and k + 1 on one side
        a = 2 * (side * n_side + k)
        return [a, a + 2, a + 3, a + 1]

    faces = [quad(0, k) for k in range(4)] + [quad(1, k) for k in range(4)]
    faces += [[0, 1, 2 * n_side + 1, 2 * n_side], [2 * n_side - 2, 2 * n_side - 1, 4 * n_side - 1, 4 * n_side - 2]]
    first = 3                   # the plate's faces after three others (a degenerate, never read, internal face each)
    faces = [[0, 1, 2, 3]] * first + faces
    owner = np.array([0] * first + list(range(10)), dtype="<i4")
    p = np.array([-0.30, -0.20, -0.10, -0.05, 0.10, 0.08, 0.06, 0.04, 0.5, -0.01])
    case = tmp_path / "case"
    mesh = case / "constant" / "polyMesh"
    _write_foam(mesh / "points", "vectorField", _foam_list(pts.astype("<f8"), binary), binary)
    if binary:
        offsets = np.arange(len(faces) + 1, dtype="<i4") * 4
        _write_foam(mesh / "faces", "faceCompactList", _foam_list(offsets, True)
                    + _foam_list(np.array(faces, dtype="<i4").ravel(), True), True)
    else:
        body = f"{len(faces)}\n(\n".encode() + "\n".join("4(" + " ".join(map(str, f)) + ")" for f in faces).encode()
        _write_foam(mesh / "faces", "faceList", body + b"\n)\n", False)
    _write_foam(mesh / "owner", "labelList", _foam_list(owner, binary), binary)
    patches = [("inlet", "patch", 3, 0), ("plate", "wall", 10, first)]
    entries = "".join(f"    {n}\n    {{\n        type {k};\n        nFaces {m};\n        startFace {s};\n    }}\n"
                      for n, k, m, s in patches)
    (mesh / "boundary").write_text(f"FoamFile\n{{\n    format ascii;\n}}\n2\n(\n{entries})\n")
    for t, scale in (("5", 0.5), ("20", 1.0)):       # the latest time is read unless another is asked for
        _write_foam(case / t / "p", "volScalarField",
                    b"dimensions [0 2 -2 0 0 0 0];\ninternalField nonuniform List<scalar> "
                    + _foam_list((scale * p).astype("<f8"), binary) + b"boundaryField\n{\n}\n", binary)
    got = of.plate_surface_pressure(case)
    assert got["time"] == 20.0
    assert got["upper"]["x"] == pytest.approx([0.1, 0.35, 0.6, 0.85])
    assert got["upper"]["width"] == pytest.approx([0.2, 0.3, 0.2, 0.3])
    assert got["upper"]["cp"] == pytest.approx(2 * p[:4])
    assert got["lower"]["cp"] == pytest.approx(2 * p[4:8])
    assert of.plate_surface_pressure(case, "5")["lower"]["cp"] == pytest.approx(p[4:8])
    assert got["field"] == "p"
    loading = of.plate_loading(case, 2.0)["loading"]
    delta = 2 * (p[4:8] - p[:4])
    assert loading.lift == pytest.approx(np.sum(delta * [0.2, 0.3, 0.2, 0.3]))
    assert loading.moment == pytest.approx(-np.sum(delta * [0.2, 0.3, 0.2, 0.3] * (np.array([0.1, 0.35, 0.6, 0.85])
                                                                                   - 0.5)))
    # a time average written beside the instant's pressure is read instead
    _write_foam(case / "20" / "pMean", "volScalarField",
                b"dimensions [0 2 -2 0 0 0 0];\ninternalField nonuniform List<scalar> "
                + _foam_list((3.0 * p).astype("<f8"), binary) + b"boundaryField\n{\n}\n", binary)
    averaged = of.plate_surface_pressure(case)
    assert averaged["field"] == "pMean" and averaged["upper"]["cp"] == pytest.approx(6 * p[:4])


def test_the_eddy_viscosity_above_the_plate_is_read_from_the_cells_over_each_face(tmp_path):
    """A block of 4 x 5 rectangular cells (uneven rows) standing on the plate's upper side, each cell holding a
    known nut and velocity, written as OpenFOAM writes a mesh (owner and neighbour of every face; the front and back
faces left out, as they move no centre in x or y): each face's
    column gives its largest nut / nu below the asked height, and the face's own cell its height and its
    velocity along the chord of the plate turned nose-up by 2 degrees (u cos a - v sin a)."""
    of = load_tool("openfoam_plate")
    xs = np.array([-0.5, -0.3, 0.0, 0.2, 0.5])
    ys = 0.01 + np.array([0.0, 0.01, 0.03, 0.06, 0.1, 0.2])
    nx, ny = xs.size - 1, ys.size - 1

    def pid(i, j, k):
        return 2 * (j * (nx + 1) + i) + k

    def cid(i, j):
        return j * nx + i

    pts = np.array([[xs[i], ys[j], float(k)] for j in range(ny + 1) for i in range(nx + 1) for k in (0, 1)])
    faces, owner, neighbour = [], [], []
    for j in range(ny):                        # internal faces first: across x, then across y
        for i in range(1, nx):
            faces.append([pid(i, j, 0), pid(i, j + 1, 0), pid(i, j + 1, 1), pid(i, j, 1)])
            owner.append(cid(i - 1, j))
            neighbour.append(cid(i, j))
    for j in range(1, ny):
        for i in range(nx):
            faces.append([pid(i, j, 0), pid(i, j, 1), pid(i + 1, j, 1), pid(i + 1, j, 0)])
            owner.append(cid(i, j - 1))
            neighbour.append(cid(i, j))
    first = len(faces)
    for i in range(nx):                        # the plate under row 0, then the block's other sides
        faces.append([pid(i, 0, 0), pid(i, 0, 1), pid(i + 1, 0, 1), pid(i + 1, 0, 0)])
        owner.append(cid(i, 0))
    for i in range(nx):
        faces.append([pid(i, ny, 0), pid(i + 1, ny, 0), pid(i + 1, ny, 1), pid(i, ny, 1)])
        owner.append(cid(i, ny - 1))
    for j in range(ny):
        for i, side in ((0, 0), (nx, nx - 1)):
            faces.append([pid(i, j, 0), pid(i, j, 1), pid(i, j + 1, 1), pid(i, j + 1, 0)])
            owner.append(cid(side, j))
    case = tmp_path / "case"
    mesh = case / "constant" / "polyMesh"
    _write_foam(mesh / "points", "vectorField", _foam_list(pts.astype("<f8"), True), True)
    offsets = np.arange(len(faces) + 1, dtype="<i4") * 4
    _write_foam(mesh / "faces", "faceCompactList", _foam_list(offsets, True)
                + _foam_list(np.array(faces, dtype="<i4").ravel(), True), True)
    _write_foam(mesh / "owner", "labelList", _foam_list(np.array(owner, dtype="<i4"), True), True)
    _write_foam(mesh / "neighbour", "labelList", _foam_list(np.array(neighbour, dtype="<i4"), True), True)
    (mesh / "boundary").write_text(f"FoamFile\n{{\n    format ascii;\n}}\n1\n(\n    plate\n    {{\n        type wall;\n"
                                   f"        nFaces {nx};\n        startFace {first};\n    }}\n)\n")
    rng = np.random.default_rng(3)
    nut = rng.uniform(0.0, 1e-3, nx * ny)
    velocity = rng.uniform(-1.0, 1.0, (nx * ny, 3))
    head = b"dimensions [0 2 -1 0 0 0 0];\ninternalField nonuniform "
    _write_foam(case / "20" / "p", "volScalarField", head + b"List<scalar> " + _foam_list(nut, True), True)
    _write_foam(case / "20" / "nut", "volScalarField", head + b"List<scalar> " + _foam_list(nut, True), True)
    _write_foam(case / "20" / "U", "volVectorField", head + b"List<vector> " + _foam_list(velocity, True), True)
    nu = 1e-6
    got = of.plate_eddy_viscosity(case, 2.0, nu, height=0.05)
    assert got["x"] == pytest.approx([0.1, 0.35, 0.6, 0.85])
    rows_below = np.nonzero(0.5 * (ys[:-1] + ys[1:]) - 0.01 < 0.05)[0]     # rows 0-2 (centres 0.005, 0.02, 0.045)
    assert rows_below.tolist() == [0, 1, 2]
    want = [max(nut[cid(i, j)] for j in rows_below) / nu for i in range(nx)]
    assert got["nut_over_nu_max"] == pytest.approx(want)
    assert got["first_cell_height"] == pytest.approx([0.005] * nx)
    a = math.radians(2.0)
    assert got["first_cell_u"] == pytest.approx([velocity[cid(i, 0), 0] * math.cos(a) - velocity[cid(i, 0), 1]
                                                 * math.sin(a) for i in range(nx)])
