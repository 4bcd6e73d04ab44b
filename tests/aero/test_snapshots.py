"""Flow snapshots (bridge/aero/snapshots.py): cell-centred fields from the staggered storage, the vorticity of
a rigid rotation (2 Omega, exact for a linear field), the body masked, and files ParaView can read (the XDMF
names datasets that exist in the HDF5 file beside it)."""

import io
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from bridge.aero.snapshots import flow_snapshot, snapshot_files
from bridge.cfd import CartesianGrid, flat_plate, stretched_faces
from bridge.cfd.grids import GHOST


def test_a_rigid_rotation_has_vorticity_two_omega_and_the_files_agree():
    x = np.linspace(-1.0, 2.0, 61)
    y = stretched_faces(-1.0, 1.0, (-0.2, 0.2), 0.02, 1.1)
    grid = CartesianGrid(x, y)
    g, om = GHOST, 0.7
    u, v, p = (np.zeros(grid.storage_shape(f)) for f in "uvp")
    yc_u = grid.storage_y_centres()                                    # u faces: x faces, cell-centre rows
    xf_u = x[0] + (np.arange(u.shape[1]) - g) * grid.dx
    u[:] = -om * yc_u[:, None] + 0 * xf_u[None, :]
    xc_v = x[0] + (np.arange(v.shape[1]) - g + 0.5) * grid.dx         # v faces: cell-centre columns, y faces
    v[:] = om * xc_v[None, :] + 0 * grid.storage_y_faces()[:, None]
    plate = flat_plate(1.0, 0.1)
    snap = flow_snapshot(grid, u, v, p, [plate], (0.5, 0.0, 0.3), t=3.0)
    vort = snap["vorticity"]
    inside = np.isnan(vort)
    assert 0 < inside.sum() < 0.05 * vort.size                         # the plate's cells, nothing else
    np.testing.assert_allclose(vort[~inside], 2 * om, rtol=1e-10)
    X, Y = np.meshgrid(grid.x_centres, grid.y_centres)
    np.testing.assert_allclose(snap["u"][~inside], -om * Y[~inside], rtol=1e-12, atol=1e-12)
    files = snapshot_files("flow", snap, "test")
    root = ET.fromstring(files["flow.xdmf"].decode())
    with h5py.File(io.BytesIO(files["flow.h5"]), "r") as h5:
        for item in root.iter("DataItem"):
            name, path = item.text.strip().split(":")
            assert name == "flow.h5"
            dims = tuple(int(d) for d in item.attrib["Dimensions"].split())
            assert h5[path].shape == dims, path
        assert h5.attrs["t"] == 3.0
    assert "flow.png" in files


def test_the_overset_picture_shows_the_body_grids_own_cells():
    """The flow picture was drawn from the coarse background alone, the deck's own grid lost (a new user's
    "blocky" picture): the body grid's fields are drawn over it, placed by the pose, with the pressure
    brought to the background's level (each grid keeps its own constant)."""
    from matplotlib.collections import QuadMesh

    from bridge.aero.snapshots import body_grid_snapshot

    g, om, pose = GHOST, 0.7, (0.1, -0.05, 0.2)
    background = CartesianGrid(np.linspace(-1.0, 2.0, 31), np.linspace(-1.0, 1.0, 21))
    body = CartesianGrid(np.linspace(-0.6, 0.6, 49), np.linspace(-0.3, 0.3, 25))

    def fields(grid, level, shift):
        """A rigid rotation (vorticity 2 om) and a pressure linear in the world's x, plus ``level``; ``shift``
        maps the grid's cell centres to world x."""
        u, v, p = (np.zeros(grid.storage_shape(f)) for f in "uvp")
        u[:] = -om * grid.storage_y_centres()[:, None]
        v[:] = om * (grid.x_faces[0] + (np.arange(v.shape[1]) - g + 0.5) * grid.dx)[None, :]
        xc = grid.x_faces[0] + (np.arange(p.shape[1]) - g + 0.5) * grid.dx
        yc = grid.storage_y_centres()
        p[:] = level + 0.1 * shift(xc[None, :], yc[:, None])
        return u, v, p

    c, s = np.cos(pose[2]), np.sin(pose[2])
    plate = flat_plate(0.5, 0.05)
    snap = flow_snapshot(background, *fields(background, 0.0, lambda x, y: x + 0 * y), [plate], pose, t=1.0)
    world_x = lambda x, y: pose[0] + c * x - s * y   # noqa: E731 - body coordinates to the world's x
    bg = body_grid_snapshot(snap, body, *fields(body, 5.0, world_x), [plate], pose)
    assert bg["x_corners"].shape == (25, 49)
    np.testing.assert_allclose(bg["x_corners"][0, 0], pose[0] + c * -0.6 - s * -0.3)
    inside = np.isnan(bg["vorticity"])
    assert 0 < inside.sum() < 0.2 * inside.size
    np.testing.assert_allclose(bg["vorticity"][~inside], 2 * om, rtol=1e-10)
    # the body grid's pressure at the background's level: both the same linear field plus one constant (the
    # body grid's own 5.0 gone), to within the background's cell used for the match
    xs = bg["x_corners"]
    X = 0.25 * (xs[:-1, :-1] + xs[1:, :-1] + xs[:-1, 1:] + xs[1:, 1:])
    level_body = np.nanmean(bg["p"] - 0.1 * X)
    level_background = np.nanmean(snap["p"] - 0.1 * np.meshgrid(background.x_centres, background.y_centres)[0])
    assert abs(level_body - level_background) < 0.1 * background.dx
    files = snapshot_files("flow", {**snap, "body_grid": bg}, "test")
    fig = files["flow.png"]
    assert all(sum(isinstance(c_, QuadMesh) for c_ in ax.collections) == 2 for ax in fig.axes[:2])
    root = ET.fromstring(files["flow.xdmf"].decode())
    assert len(list(root.iter("Grid"))) == 2
    with h5py.File(io.BytesIO(files["flow.h5"]), "r") as h5:
        for item in root.iter("DataItem"):
            name, path = item.text.strip().split(":")
            assert h5[path].shape == tuple(int(d) for d in item.attrib["Dimensions"].split()), path
