"""Figures of the FEM stage (matplotlib Figure objects, Agg; the caller saves them).

* :func:`mode_shape_figure`: U, Theta and lateral V along the deck for one mode, as thesis Fig 3.3-3.6;
* :func:`model_figure`: elevation and plan of the frame model with one mode superimposed.

File names come from :func:`mode_shape_file_name` / :func:`model_file_name`, so that another stage
adding the shape of a mode (the flutter stage plots its governing pair) uses the same name and does
not draw a figure twice.
"""

from __future__ import annotations

import numpy as np

from .analysis import FemResult

__all__ = ["mode_shape_figure", "model_figure", "fem_figures", "mode_shape_file_name", "model_file_name"]

# What the normalisation of Eq 4.31-4.32 sets to 1, by mode kind (bridge.structure.modes).
_NORMALISED = {"vertical": "max U = 1 (Eq 4.31)", "torsional": "max Theta = 1 (Eq 4.32)",
               "lateral": "max V = 1", "longitudinal": "max W = 1", "cable": "max |translation| = 1"}


def _figure(size, **kw):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    return Figure(figsize=size, **kw)


def mode_shape_file_name(label: str) -> str:
    return f"fem_mode_{label}.png"


def model_file_name(label: str) -> str:
    return f"fem_model_{label}.png"


def mode_shape_figure(result: FemResult, label: str, note: str = ""):
    """Deck fields U (vertical), Theta (torsion) and V (lateral) of mode ``label`` along z.

    One axis, one quantity: the normalised (dimensionless) mode shape of Eq 4.31-4.32, whose modal
    coordinate carries the unit (m, or rad for a torsional mode).  So for a torsional mode U and V are
    metres per radian of twist, for a vertical mode Theta is radians per metre of deflection; the title
    says which field is normalised to 1.  ``note`` is appended to the title (e.g. why the mode is shown).
    """
    m = result.modes
    i = m.index(label)
    fig = _figure((8, 3.6), layout="constrained")
    ax = fig.subplots()
    ax.plot(m.z_m, m.U[i], label="U: vertical deck displacement")
    ax.plot(m.z_m, m.Theta[i], label="Theta: deck torsion")
    ax.plot(m.z_m, m.V[i], "--", label="V: lateral deck displacement")
    for zp in result.model.pylon_z_m:
        ax.axvline(zp, color="k", lw=0.6)
    ax.set_xlabel("z along the deck [m]")
    ax.set_ylabel("normalised mode shape [-]")
    units = ("modal coordinate in rad: U, V in m per rad" if m.kinds[i] == "torsional"
             else "modal coordinate in m: Theta in rad per m")
    ax.set_title(f"{result.scenario.name}: mode {i + 1} {label}, f = {m.frequencies_hz[i]:.4f} Hz"
                 f"{', ' + note if note else ''}\nnormalised to {_NORMALISED[m.kinds[i]]}; {units} "
                 "(vertical lines: pylons)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def _polyline(points: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Segments ``conn`` of ``points`` as one (k, 3) polyline with NaN breaks (one plot call)."""
    seg = points[conn]                                                # (e, 2, 3)
    return np.concatenate([seg, np.full((len(seg), 1, 3), np.nan)], axis=1).reshape(-1, 3)


def model_figure(result: FemResult, label: str, deck_amplitude_m: float | None = None):
    """Elevation (z, y) and plan (z, x) of the model, undeformed (grey) and in mode ``label``.

    Two 2D views instead of one 3D drawing: the bridge is 100 times longer than wide, so a 3D box either
    squeezes the cross-section to a line (the mode invisible, tick labels on top of each other) or the
    span; in elevation vertical bending shows directly and torsion as the two cable planes and deck
    edges moving apart (drawn in two colours), in plan the lateral motion.  The mode is scaled so that
    its largest deck displacement (girder axis or deck edge) is ``deck_amplitude_m`` (default 4 % of the
    main span); the factor is in the title.
    """
    m, mod = result.modes, result.model
    i = m.index(label)
    shape = m.shapes[:, i].reshape(-1, 6)[:, :3]
    deck = np.concatenate([mod.girder_nodes, [slave for slave, _ in mod.links]])
    amplitude = deck_amplitude_m if deck_amplitude_m is not None else 0.04 * result.scenario.geometry.main_span_m
    scale = amplitude / np.abs(shape[deck]).max()
    moved = mod.nodes + scale * shape
    # deck edges: the rigid-link nodes at the hanger bottoms, per side, in ascending z
    edges = []
    for side in (-1.0, 1.0):
        nodes = [s for s, _ in mod.links if np.sign(mod.nodes[s, 0]) == side]
        edges.append(np.array(sorted(nodes, key=lambda n: mod.nodes[n, 2])))
    side_of_element = np.sign(mod.nodes[mod.conn].mean(axis=1)[:, 0])
    girder = mod.group == 0                                           # GROUPS[0] == "girder"

    fig = _figure((10, 6.2), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    for ax, (h, v) in zip(axes, ((2, 1), (2, 0)), strict=True):      # (horizontal, vertical) coordinate
        base = _polyline(mod.nodes, mod.conn)
        ax.plot(base[:, h], base[:, v], color="0.8", lw=0.5)
        for side, colour in ((-1.0, "C0"), (1.0, "C3")):
            line = _polyline(moved, mod.conn[(side_of_element == side) & ~girder])
            ax.plot(line[:, h], line[:, v], color=colour, lw=0.6, alpha=0.8)
            edge = moved[edges[0 if side < 0 else 1]]
            ax.plot(edge[:, h], edge[:, v], color=colour, lw=2.0,
                    label=f"deck edge and cable plane at x {'<' if side < 0 else '>'} 0")
        axis = moved[mod.girder_nodes]
        ax.plot(axis[:, h], axis[:, v], color="k", lw=2.0, label="girder axis")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("y (elevation) [m]")
    axes[1].set_ylabel("x (across) [m]")
    axes[1].set_xlabel("z along the bridge [m]")
    axes[0].legend(fontsize=8, loc="upper center", ncol=3)
    axes[0].set_title(f"{result.scenario.name}: mode {i + 1} {label}, f = {m.frequencies_hz[i]:.4f} Hz; "
                      f"elevation (top) and plan (bottom), grey undeformed\ndisplacements drawn x {scale:.3g} "
                      f"(largest deck displacement {amplitude:.0f} m on the drawing)", fontsize=10)
    return fig


def fem_figures(result: FemResult) -> dict:
    """Fig 3.3-3.6 equivalents (first three symmetric vertical and first symmetric torsional mode),
    the first lateral mode, and elevation and plan of the model in the first symmetric torsional mode."""
    m = result.modes
    out = {}
    picks = [m.labels[i] for i in m.first("vertical", "S", 3) + m.first("torsional", "S")
             + m.first("lateral", "S")]
    for lab in picks:
        out[mode_shape_file_name(lab)] = mode_shape_figure(result, lab)
    shown = (m.first("torsional", "S") or m.first("vertical", "S") or [0])[0]
    out[model_file_name(m.labels[shown])] = model_figure(result, m.labels[shown])
    return out
