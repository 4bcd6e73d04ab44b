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
