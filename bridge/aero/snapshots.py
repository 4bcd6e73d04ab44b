"""Flow snapshots of a CFD case: vorticity and pressure at the end of the run, as a PNG and as files ParaView
opens (XDMF 2 describing a rectilinear grid, the fields in an HDF5 file beside it).

:func:`flow_snapshot` takes the solver's staggered fields (``bridge.cfd.grids``: u on x-faces, v on y-faces,
p in cells, ``GHOST`` layers around) and returns cell-centred u, v, p and the vorticity
dv/dx - du/dy (second-order differences on the stretched grid), with the cells inside the body masked (NaN).
:func:`snapshot_files` turns one into ``{name.png: Figure, name.h5: bytes, name.xdmf: bytes}``, which a stage
hands over with its figures (written into the result folder, listed in the report).
"""

from __future__ import annotations

import io
import math

import numpy as np

__all__ = ["cell_centred", "flow_snapshot", "snapshot_files"]


def cell_centred(grid, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cell-centred u, v (ny, nx) of the staggered storage arrays (ghosts included) and the vorticity
    dv/dx - du/dy by second-order differences on the (stretched) grid."""
    from bridge.cfd.grids import GHOST as g

    nx, ny = grid.nx, grid.ny
    uc = 0.5 * (u[g:g + ny, g:g + nx] + u[g:g + ny, g + 1:g + nx + 1])
    vc = 0.5 * (v[g:g + ny, g:g + nx] + v[g + 1:g + ny + 1, g:g + nx])
    return uc, vc, np.gradient(vc, grid.x_centres, axis=1) - np.gradient(uc, grid.y_centres, axis=0)


def flow_snapshot(grid, u: np.ndarray, v: np.ndarray, p: np.ndarray, polygons, pose, t: float) -> dict:
    """Cell-centred fields of one instant.  ``u``, ``v``, ``p``: storage arrays with ghosts; ``polygons``: the
    body's parts in the body frame; ``pose`` (x, y, theta counter-clockwise) of the body frame at ``t``."""
    from matplotlib.path import Path as MplPath

    from bridge.cfd.grids import GHOST as g

    uc, vc, vort = cell_centred(grid, u, v)
    pc = np.array(p[g:g + grid.ny, g:g + grid.nx], dtype=float)
    xc, yc = grid.x_centres, grid.y_centres
    c, s = math.cos(pose[2]), math.sin(pose[2])
    X, Y = np.meshgrid(xc, yc)
    points = np.column_stack([X.ravel(), Y.ravel()])
    inside = np.zeros(points.shape[0], dtype=bool)
    outlines = []
    for poly in polygons:
        verts = np.asarray(poly.vertices, dtype=float) @ np.array([[c, s], [-s, c]]) + np.array(pose[:2])
        outlines.append(verts)
        inside |= MplPath(verts).contains_points(points)
    inside = inside.reshape(X.shape)
    fields = {"u": uc, "v": vc, "p": pc - np.nanmean(np.where(inside, np.nan, pc)), "vorticity": vort}
    for f in fields.values():
        f[inside] = np.nan
    return {"t": float(t), "x_faces": np.asarray(grid.x_faces, dtype=float),
            "y_faces": np.asarray(grid.y_faces, dtype=float), "outlines": outlines, **fields}


def _xdmf(name: str, snap: dict) -> bytes:
    ny, nx = snap["vorticity"].shape
    item = '<DataItem Dimensions="{dims}" NumberType="Float" Precision="8" Format="HDF">{h5}:/{path}</DataItem>'
    attrs = "\n".join(
        f'   <Attribute Name="{f}" AttributeType="Scalar" Center="Cell">\n    '
        + item.format(dims=f"{ny} {nx}", h5=f"{name}.h5", path=f) + "\n   </Attribute>"
        for f in ("vorticity", "p", "u", "v"))
    text = f"""<?xml version="1.0" ?>
<Xdmf Version="2.0">
 <Domain>
  <Grid Name="{name}" GridType="Uniform">
   <Time Value="{snap['t']:.10g}"/>
   <Topology TopologyType="2DRectMesh" NumberOfElements="{ny + 1} {nx + 1}"/>
   <Geometry GeometryType="VXVY">
    {item.format(dims=nx + 1, h5=f"{name}.h5", path="x_faces")}
    {item.format(dims=ny + 1, h5=f"{name}.h5", path="y_faces")}
   </Geometry>
{attrs}
  </Grid>
 </Domain>
</Xdmf>
"""
    return text.encode()


def _h5_bytes(snap: dict) -> bytes:
    import h5py

    buf = io.BytesIO()
    with h5py.File(buf, "w") as h5:
        h5.attrs["t"] = snap["t"]
        h5.attrs["units"] = "lengths in chords B, velocities in V, pressure in rho V^2 (mean over the fluid removed)"
        for name in ("x_faces", "y_faces", "u", "v", "p", "vorticity"):
            h5.create_dataset(name, data=snap[name])
        for i, verts in enumerate(snap["outlines"]):
            h5.create_dataset(f"body/{i}", data=verts)
    return buf.getvalue()


def snapshot_files(name: str, snap: dict, title: str, view: tuple[float, float, float, float] = (-1.0, 4.0, -1.0, 1.0)
                   ) -> dict:
    """``{name.png: Figure, name.h5: bytes, name.xdmf: bytes}``: vorticity and pressure around the body
    (``view``: x0, x1, y0, y1 in chords) and the whole field for ParaView."""
    from matplotlib.figure import Figure

    xc = 0.5 * (snap["x_faces"][1:] + snap["x_faces"][:-1])
    yc = 0.5 * (snap["y_faces"][1:] + snap["y_faces"][:-1])
    fig = Figure(figsize=(9.0, 5.2), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    ix = (xc >= view[0]) & (xc <= view[1])
    iy = (yc >= view[2]) & (yc <= view[3])
    for ax, field, cmap, label in ((axes[0], "vorticity", "RdBu_r", "vorticity omega B / V [-]"),
                                   (axes[1], "p", "viridis", "pressure p / (rho V^2) [-]")):
        data = snap[field][np.ix_(iy, ix)]
        finite = data[np.isfinite(data)]
        lim = float(np.percentile(np.abs(finite), 99)) if finite.size else 1.0
        kw = {"vmin": -lim, "vmax": lim} if field == "vorticity" else {}
        m = ax.pcolormesh(xc[ix], yc[iy], data, cmap=cmap, shading="nearest", **kw)
        for verts in snap["outlines"]:
            ax.fill(verts[:, 0], verts[:, 1], color="0.3")
        ax.set_aspect("equal")
        ax.set_ylabel("y / B [-]")
        fig.colorbar(m, ax=ax, label=label, shrink=0.9)
    axes[1].set_xlabel("x / B [-] (wind from the left)")
    axes[0].set_title(f"{title}, t V / B = {snap['t']:.1f}", fontsize=9)
    return {f"{name}.png": fig, f"{name}.h5": _h5_bytes(snap), f"{name}.xdmf": _xdmf(name, snap)}
