"""Figures of the FEM stage (matplotlib Figure objects, Agg; the caller saves them).

* :func:`mode_shape_figure`: U, Theta and lateral V along the deck for one mode, as thesis Fig 3.3-3.6;
* :func:`model_figure`: 3D line drawing of the frame model with one mode superimposed.
"""

from __future__ import annotations

import numpy as np

from .analysis import FemResult

__all__ = ["mode_shape_figure", "model_figure", "fem_figures"]


def _figure(size):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    return Figure(figsize=size)


def mode_shape_figure(result: FemResult, label: str):
    """Deck fields U (vertical), Theta (torsion) and V (lateral) of mode ``label`` along z."""
    m = result.modes
    i = m.index(label)
    fig = _figure((8, 3.4))
    ax = fig.subplots()
    ax.plot(m.z_m, m.U[i], label="U (vertical) [-]")
    ax.plot(m.z_m, m.Theta[i], label="Theta (torsion) [rad]")
    ax.plot(m.z_m, m.V[i], "--", label="V (lateral) [-]")
    for zp in result.model.pylon_z_m:
        ax.axvline(zp, color="k", lw=0.6)
    ax.set_xlabel("z along the deck [m]")
    ax.set_ylabel("normalised amplitude")
    ax.set_title(f"{result.scenario.name}: mode {i + 1} {label}, f = {m.frequencies_hz[i]:.4f} Hz")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def model_figure(result: FemResult, label: str, scale_m: float | None = None):
    """3D line drawing of the model (grey) and mode ``label`` (coloured), amplitude ``scale_m``
    (default 1.5 % of the main span) on the largest translation."""
    m, mod = result.modes, result.model
    i = m.index(label)
    shape = m.shapes[:, i].reshape(-1, 6)[:, :3]
    amp = np.abs(shape).max()
    scale = (scale_m if scale_m is not None else 0.015 * result.scenario.geometry.main_span_m) / amp
    fig = _figure((9, 5))
    ax = fig.add_subplot(projection="3d")
    # plot (z, x, y): along, across, up
    for pts, kw in ((mod.nodes, dict(color="0.7", lw=0.5)), (mod.nodes + scale * shape, dict(color="C3", lw=0.8))):
        seg = pts[mod.conn]                                   # (e, 2, 3); one polyline with NaN breaks
        line = np.concatenate([seg, np.full((len(seg), 1, 3), np.nan)], axis=1).reshape(-1, 3)
        ax.plot(line[:, 2], line[:, 0], line[:, 1], **kw)
    ax.set_xlabel("z [m]")
    ax.set_ylabel("x [m]")
    ax.set_zlabel("y [m]")
    ax.set_box_aspect((6, 1, 1))
    ax.set_title(f"{result.scenario.name}: mode {i + 1} {label}, f = {m.frequencies_hz[i]:.4f} Hz")
    return fig


def fem_figures(result: FemResult) -> dict:
    """Fig 3.3-3.6 equivalents (first three symmetric vertical and first symmetric torsional mode),
    the first lateral mode, and a 3D drawing with the first symmetric torsional mode."""
    m = result.modes
    out = {}
    picks = [m.labels[i] for i in m.first("vertical", "S", 3) + m.first("torsional", "S")
             + m.first("lateral", "S")]
    for lab in picks:
        out[f"fem_mode_{lab}.png"] = mode_shape_figure(result, lab)
    three_d = (m.first("torsional", "S") or m.first("vertical", "S") or [0])[0]
    out[f"fem_model_3d_{m.labels[three_d]}.png"] = model_figure(result, m.labels[three_d])
    return out
