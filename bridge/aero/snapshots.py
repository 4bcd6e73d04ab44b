"""Flow snapshots of a CFD case: vorticity and pressure at the end of the run, as a PNG and as files ParaView
opens (XDMF 2 describing a rectilinear grid, the fields in an HDF5 file beside it).

:func:`flow_snapshot` takes the solver's staggered fields (``bridge.cfd.grids``: u on x-faces, v on y-faces,
p in cells, ``GHOST`` layers around) and returns cell-centred u, v, p and the vorticity
dv/dx - du/dy (second-order differences on the stretched grid), with the cells inside the body masked (NaN).
On the overset pair :func:`body_grid_snapshot` adds the body grid's own fields, where the section's detail
is (the background holds the body grid's flow only at its own, coarser, resolution).
:func:`snapshot_files` turns one into ``{name.png: Figure, name.h5: bytes, name.xdmf: bytes}``, which a stage
hands over with its figures (written into the result folder, listed in the report).
"""

from __future__ import annotations

import io
import math

import numpy as np

__all__ = ["cell_centred", "flow_snapshot", "body_grid_snapshot", "snapshot_files"]


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


def body_grid_snapshot(snap: dict, grid, u: np.ndarray, v: np.ndarray, p: np.ndarray, polygons, pose) -> dict:
    """The body grid's vorticity and pressure for the picture of the background's snapshot ``snap``.

    ``u``, ``v``, ``p``: the body grid's storage arrays (its state is the absolute velocity in the body's axes,
    ``bridge.cfd.overset``; its vorticity is the same scalar in either frame); ``pose`` (x, y, theta
    counter-clockwise) places its cell corners (``x_corners``, ``y_corners``, each (ny + 1, nx + 1)) where the
    body is.  Each grid keeps its pressure up to a constant of its own: the body grid's is shifted to the
    background's on the body grid's outermost two rings of cells, where both solve the same flow."""
    own = flow_snapshot(grid, u, v, p, polygons, (0.0, 0.0, 0.0), snap["t"])
    c, s = math.cos(pose[2]), math.sin(pose[2])
    X, Y = np.meshgrid(grid.x_faces, grid.y_faces)
    xs, ys = pose[0] + c * X - s * Y, pose[1] + s * X + c * Y
    Xc, Yc = np.meshgrid(grid.x_centres, grid.y_centres)
    ring = np.zeros(Xc.shape, dtype=bool)
    ring[:2, :] = ring[-2:, :] = ring[:, :2] = ring[:, -2:] = True
    wx, wy = pose[0] + c * Xc[ring] - s * Yc[ring], pose[1] + s * Xc[ring] + c * Yc[ring]
    ix = np.clip(np.searchsorted(snap["x_faces"], wx) - 1, 0, snap["p"].shape[1] - 1)
    iy = np.clip(np.searchsorted(snap["y_faces"], wy) - 1, 0, snap["p"].shape[0] - 1)
    offset = np.nanmean(snap["p"][iy, ix] - own["p"][ring])
    return {"x_corners": xs, "y_corners": ys, "vorticity": own["vorticity"],
            "p": own["p"] + (offset if np.isfinite(offset) else 0.0)}


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
{_xdmf_body_grid(name, snap)} </Domain>
</Xdmf>
"""
    return text.encode()


def _xdmf_body_grid(name: str, snap: dict) -> str:
    """The body grid of an overset snapshot as a second, curvilinear grid (its corners where the body is)."""
    if "body_grid" not in snap:
        return ""
    ny, nx = snap["body_grid"]["vorticity"].shape
    item = '<DataItem Dimensions="{dims}" NumberType="Float" Precision="8" Format="HDF">{h5}:/{path}</DataItem>'
    attrs = "\n".join(
        f'   <Attribute Name="{f}" AttributeType="Scalar" Center="Cell">\n    '
        + item.format(dims=f"{ny} {nx}", h5=f"{name}.h5", path=f"body_grid/{f}") + "\n   </Attribute>"
        for f in ("vorticity", "p"))
    return f"""  <Grid Name="{name} body grid" GridType="Uniform">
   <Time Value="{snap['t']:.10g}"/>
   <Topology TopologyType="2DSMesh" NumberOfElements="{ny + 1} {nx + 1}"/>
   <Geometry GeometryType="X_Y">
    {item.format(dims=f"{ny + 1} {nx + 1}", h5=f"{name}.h5", path="body_grid/x_corners")}
    {item.format(dims=f"{ny + 1} {nx + 1}", h5=f"{name}.h5", path="body_grid/y_corners")}
   </Geometry>
{attrs}
  </Grid>
"""


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
        for name, values in snap.get("body_grid", {}).items():
            h5.create_dataset(f"body_grid/{name}", data=values)
    return buf.getvalue()


def snapshot_files(name: str, snap: dict, title: str, view: tuple[float, float, float, float] = (-1.0, 4.0, -1.0, 1.0)
                   ) -> dict:
    """``{name.png: Figure, name.h5: bytes, name.xdmf: bytes}``: vorticity and pressure around the body
    (``view``: x0, x1, y0, y1 in chords; on an overset pair the body grid's own cells drawn over the
    background's, its edge dashed) and the whole field for ParaView (the body grid as a second grid)."""
    from matplotlib.figure import Figure

    xc = 0.5 * (snap["x_faces"][1:] + snap["x_faces"][:-1])
    yc = 0.5 * (snap["y_faces"][1:] + snap["y_faces"][:-1])
    fig = Figure(figsize=(9.0, 5.2), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    ix = (xc >= view[0]) & (xc <= view[1])
    iy = (yc >= view[2]) & (yc <= view[3])
    body = snap.get("body_grid")
    for ax, field, cmap, label in ((axes[0], "vorticity", "RdBu_r", "vorticity omega B / V [-]"),
                                   (axes[1], "p", "viridis", "pressure p / (rho V^2) [-]")):
        data = snap[field][np.ix_(iy, ix)]
        finite = np.concatenate([data[np.isfinite(data)]] + ([] if body is None else
                                                             [body[field][np.isfinite(body[field])]]))
        if field == "vorticity":
            lim = float(np.percentile(np.abs(finite), 99)) if finite.size else 1.0
            kw = {"vmin": -lim, "vmax": lim}
        else:
            kw = {"vmin": float(np.percentile(finite, 0.5)), "vmax": float(np.percentile(finite, 99.5))} \
                if finite.size else {}
        m = ax.pcolormesh(xc[ix], yc[iy], data, cmap=cmap, shading="nearest", **kw)
        if body is not None:   # the body grid's own cells over the background's, and its edge dashed
            ax.pcolormesh(body["x_corners"], body["y_corners"], body[field], cmap=cmap, shading="flat", **kw)
            xs, ys = body["x_corners"], body["y_corners"]
            edge_x = np.concatenate([xs[0, :], xs[:, -1], xs[-1, ::-1], xs[::-1, 0]])
            edge_y = np.concatenate([ys[0, :], ys[:, -1], ys[-1, ::-1], ys[::-1, 0]])
            ax.plot(edge_x, edge_y, "k--", lw=0.5)
        for verts in snap["outlines"]:
            ax.fill(verts[:, 0], verts[:, 1], color="0.3")
        ax.set_xlim(max(view[0], float(snap["x_faces"][0])), min(view[1], float(snap["x_faces"][-1])))
        ax.set_ylim(max(view[2], float(snap["y_faces"][0])), min(view[3], float(snap["y_faces"][-1])))
        ax.set_aspect("equal")
        ax.set_ylabel("y / B [-]")
        fig.colorbar(m, ax=ax, label=label, shrink=0.9)
    axes[1].set_xlabel("x / B [-] (wind from the left)")
    axes[0].set_title(f"{title}, t V / B = {snap['t']:.1f}", fontsize=9)
    return {f"{name}.png": fig, f"{name}.h5": _h5_bytes(snap), f"{name}.xdmf": _xdmf(name, snap)}
