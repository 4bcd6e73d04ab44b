"""3D frame model of a three-span suspension bridge in its dead-load state (thesis chapter 3).

Coordinates as in thesis 3.1 / Fig 3.1: z along the bridge (0 at the left anchor, the girder end),
y up (0 at the pylon foundations), x across.  Units SI.

What is modelled (thesis 3.1-3.2; readings in docs/thesis_errata.md):
* Two main cables at x = +-B_c/2 (B_c = geometry.cable_plane_spacing_m) through the cable statics
  solution (:mod:`bridge.cable`): anchors (z = 0 and z = L_tot) to the pylon tops and across the main
  span, one node per hanger plus ``n_sub - 1`` intermediate nodes per hanger panel.  Panel points
  (hangers, pylon tops, anchors) lie on the RK4 profile; between them the cable is the funicular
  polygon of its own weight (the girder load reaches the cable only through the hangers).
  Cable elements are 2-node cable/truss elements (:mod:`kernels.fem`, kind 1): EA/L plus the string
  geometric stiffness of their dead-load tension; no bending or torsion stiffness (thesis 3.2.1
  "no significant bending and torsional stiffness"; zero here, so rotations of cable-only nodes are not
  DOFs of the model).  Side-span cables use mass_per_length_side_kg_m, as the statics do (the thesis
  used main-span properties everywhere for simplicity); the area is the main-span area everywhere.
* Hangers: the pair of parallel hangers as one element of area ``hanger.area_m2`` (thesis 3.2.2)
  from the cable node to a slave node at girder level in the cable plane; one cable element each.
* Girder: Bernoulli-Euler beam on the bridge axis (x = 0, y = girder_elevation_m), horizontal, no
  camber, the section of Table 3.3: EI_yy (vertical bending), EI_xx (lateral), G I_zz (St Venant
  torsion), mass mu_b, polar mass moment J_b; rotary inertia for bending rho_eff I with
  rho_eff = mu_b / A_b (the same density reproduces J_b = rho (I_xx + I_yy) of Eq 3.1).  It spans the
  whole deck length L_tot = L + 2 L_s (anchor block to anchor block, continuous through the pylons).
* Rigid links (ABAQUS kinematic coupling): each hanger's lower node is a slave of the girder node at
  the same z; all six of its DOFs follow the master: u_s = u_m + theta_m x r, theta_s = theta_m.
* Pylons: two legs per pylon in the cable planes (x = +-B_c/2), lower leg section from the foundation
  to girder level, upper leg section above it to the saddle (y = pylon_height_m), cross beams between
  the legs at ``pylon.cross_beam_elevations_m`` (lowest one: lower cross-beam section; all others,
  extra beams of Models B and C included: upper cross-beam section).  Box sections of Table 3.2;
  concrete of Table 3.1.  Leg axes: section side a along the bridge, b across (config.BoxSection).
  The cable passes over the saddle: the leg top node is a cable node of both the side and main span.
  Leg compression = vertical cable reactions (from the chord tensions) plus the leg and half the
  cross-beam weights above each element; the cross beams carry no axial force.

Supports (the thesis does not state them; chosen to follow the real bridge):
* cable anchors: all translations fixed; pylon feet: all six DOFs fixed (rigid foundations);
* girder at both ends (anchor blocks): vertical, lateral, longitudinal and torsional rotation fixed,
  bending rotations free (the hydraulic buffers of the Great Belt girder are taken as rigid for the
  short-duration dynamic loading, which is how they are designed to act);
* girder at each pylon: vertical, lateral and torsional rotation fixed (bearing pair on the pylon
  cross beam, taken as rigid ground); free longitudinally and in both bending rotations.

Dead-load state (geometric stiffness):
* cable segment tension T = H sqrt(1 + s^2) with s the chord slope of the straight segment: the
  horizontal component is H in every segment, so horizontal nodal equilibrium is exact;
* hanger tension from vertical equilibrium of its cable node: F = H (s_right - s_left) - W_node,
  W_node = weight of half of each adjacent cable segment; at cable nodes without hanger the same
  balance is the equilibrium residual ``cable_node_residual_N`` (reported, ~0 by construction of the
  funicular sub-polygon), and the
  hanger tensions add up to the girder weight (``hanger_weight_residual``, reported);
* the hanger's own weight is not added to its tension (< 0.5 % of it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..cable import CableSolution
from ..config import GRAVITY_M_S2, BoxSection, Scenario
from ..errors import InputError
from .elements import (
    KIND_BEAM,
    KIND_CABLE,
    N_PROPS,
    PROP_AXIAL,
    PROP_EA,
    PROP_EI2,
    PROP_EI3,
    PROP_GJ,
    PROP_KIND,
    PROP_MASS,
    PROP_POLAR,
    PROP_ROT2,
    PROP_ROT3,
    ElementSet,
)

__all__ = ["FrameModel", "build_model", "GROUPS"]

GROUPS = ("girder", "cable", "hanger", "pylon_lower_leg", "pylon_upper_leg", "pylon_cross_beam")
UP = np.array([0.0, 1.0, 0.0])
ALONG = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class FrameModel:
    """Nodes, elements and constraints of the frame model (see the module docstring).

    nodes (n, 3) [x, y, z]; conn (e, 2) node indices; group (e,) index into GROUPS; elements: the
    ElementSet handed to the kernel; fixed: (node, dof) pairs held at zero; links: (slave, master)
    node pairs of the rigid links; rotational (n,) bool: node has rotational DOFs (touched by a beam);
    girder_nodes: girder node indices in ascending z; girder_z: their z.
    """

    nodes: np.ndarray
    conn: np.ndarray
    group: np.ndarray
    elements: ElementSet
    fixed: tuple[tuple[int, int], ...]
    links: tuple[tuple[int, int], ...]
    rotational: np.ndarray
    girder_nodes: np.ndarray
    girder_z: np.ndarray
    cable_nodes: np.ndarray           # (2, n_z): cable node per side (x<0, x>0) at every girder z
    hanger_tension_N: np.ndarray
    cable_tension_N: np.ndarray       # per cable element in conn order of the cable group
    cable_node_residual_N: float      # max |vertical imbalance| at cable nodes without hanger
    hanger_weight_residual: float     # |sum hanger tensions - girder weight| / girder weight
    pylon_top_compression_N: float    # per leg, from the cable chords
    deck_length_m: float
    mid_span_z_m: float
    pylon_z_m: tuple[float, float]
    n_sub: int

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_elements(self) -> int:
        return len(self.conn)


class _Builder:
    def __init__(self):
        self.nodes: list[np.ndarray] = []
        self.xa, self.xb, self.ov, self.props, self.conn, self.group = [], [], [], [], [], []

    def node(self, x: float, y: float, z: float) -> int:
        self.nodes.append(np.array([x, y, z], dtype=np.float64))
        return len(self.nodes) - 1

    def element(self, a: int, b: int, orient: np.ndarray, props: np.ndarray, group: str) -> None:
        self.xa.append(self.nodes[a])
        self.xb.append(self.nodes[b])
        self.ov.append(orient)
        self.props.append(props)
        self.conn.append((a, b))
        self.group.append(GROUPS.index(group))


def _beam_props(E: float, G: float, area: float, i2: float, i3: float, torsion: float, mass: float,
                density: float, polar: float | None = None, axial: float = 0.0) -> np.ndarray:
    """Beam property row: i2 bends with deflection along local e2, i3 along e3."""
    p = np.zeros(N_PROPS)
    p[PROP_EA], p[PROP_EI2], p[PROP_EI3], p[PROP_GJ] = E * area, E * i2, E * i3, G * torsion
    p[PROP_MASS], p[PROP_ROT2], p[PROP_ROT3] = mass, density * i2, density * i3
    p[PROP_POLAR] = density * (i2 + i3) if polar is None else polar
    p[PROP_AXIAL], p[PROP_KIND] = axial, KIND_BEAM
    return p


def _cable_props(E: float, area: float, mass: float, tension: float) -> np.ndarray:
    p = np.zeros(N_PROPS)
    p[PROP_EA], p[PROP_MASS], p[PROP_AXIAL], p[PROP_KIND] = E * area, mass, tension, KIND_CABLE
    return p


def _subdivide(points: np.ndarray, n: int) -> np.ndarray:
    t = np.arange(n) / n
    inner = (points[:-1, None] + (points[1:] - points[:-1])[:, None] * t[None, :]).ravel()
    return np.append(inner, points[-1])


def _levels(breaks: list[float], max_len: float) -> np.ndarray:
    """Sorted unique levels with every gap split into pieces no longer than max_len."""
    b = np.unique(np.round(np.asarray(breaks, dtype=np.float64), 9))
    out = [b[0]]
    for lo, hi in zip(b[:-1], b[1:], strict=False):
        k = max(1, int(np.ceil((hi - lo) / max_len - 1e-9)))
        out.extend(lo + (hi - lo) * np.arange(1, k + 1) / k)
    return np.array(out)


def build_model(scenario: Scenario, cables: CableSolution, n_sub: int = 4) -> FrameModel:
    """Frame model of ``scenario`` in the dead-load state ``cables``; ``n_sub`` elements per hanger panel
    (girder and cables), pylon elements no longer than a main-span panel / n_sub."""
    if n_sub < 1:
        raise InputError("fem.elements_per_panel", n_sub, "must be >= 1")
    geo, gir, cab, han, pyl = scenario.geometry, scenario.girder, scenario.cable, scenario.hanger, scenario.pylon
    g = GRAVITY_M_S2
    steel_g, cab_m, han_m = scenario.material(gir.material), scenario.material(cab.material), \
        scenario.material(han.material)
    conc = scenario.material(pyl.material)
    H = cables.horizontal_force_per_cable_N
    side, span = geo.side_span_m, geo.main_span_m
    total = span + 2.0 * side
    z_pylons = (side, side + span)
    y_g = geo.girder_elevation_m
    half_b = 0.5 * geo.cable_plane_spacing_m

    # ---- z grid: panel points (ends, pylons, hangers) subdivided
    panel_points = np.unique(np.round(np.concatenate([[0.0, side, side + span, total], cables.hanger_z_m]), 9))
    z = _subdivide(panel_points, n_sub)
    nz = len(z)
    is_hanger = np.isin(np.arange(nz), np.searchsorted(z, np.round(cables.hanger_z_m, 9)))
    i_pylon = [int(np.argmin(abs(z - zp))) for zp in z_pylons]

    # cable node elevations: the statics elevation at panel points (hangers, pylons, anchors); between
    # them the funicular polygon of the cable's own weight (exact nodal equilibrium, see _sub_polygon)
    panel_y = np.empty(len(panel_points))
    for sp, (lo, hi) in zip(cables.spans, ((0.0, side), (side, side + span), (side + span, total)), strict=False):
        sel = (panel_points >= lo - 1e-9) & (panel_points <= hi + 1e-9)
        panel_y[sel] = np.interp(panel_points[sel], sp.z_m, sp.elevation_m)  # panel points are RK4 nodes
    mass_of_panel = np.where((panel_points[:-1] >= side - 1e-9) & (panel_points[1:] <= side + span + 1e-9),
                             cab.mass_per_length_main_kg_m, cab.mass_per_length_side_kg_m)
    cable_y = _sub_polygon(panel_points, panel_y, n_sub, H, mass_of_panel * g)

    b = _Builder()
    # ---- girder
    girder = np.array([b.node(0.0, y_g, zz) for zz in z])
    rho_eff = gir.mass_per_length_kg_m / gir.area_m2
    gprops = _beam_props(steel_g.youngs_modulus_Pa, steel_g.shear_modulus_Pa, gir.area_m2,
                         gir.i_vertical_m4, gir.i_lateral_m4, gir.torsion_constant_m4, gir.mass_per_length_kg_m,
                         rho_eff, polar=gir.mass_moment_of_inertia_kg_m2_m)
    for i in range(nz - 1):
        b.element(girder[i], girder[i + 1], UP, gprops, "girder")

    # ---- pylon legs (nodes first so the cable can share the top node)
    beams = pyl.cross_beam_elevations_m
    levels = _levels([0.0, y_g, geo.pylon_height_m, *beams], cables.main_panel_m / n_sub)
    legs = {}  # (pylon index, side) -> node indices per level
    for ip, zp in enumerate(z_pylons):
        for s, xs in enumerate((-half_b, half_b)):
            legs[ip, s] = np.array([b.node(xs, yy, zp) for yy in levels])

    # ---- cables (two planes) with chord tensions
    cable_nodes = np.empty((2, nz), dtype=int)
    dz = np.diff(z)
    chord = np.diff(cable_y) / dz
    seg_len = np.hypot(dz, np.diff(cable_y))
    seg_tension = H * np.sqrt(1.0 + chord**2)
    seg_mass = np.where((z[:-1] >= z_pylons[0] - 1e-9) & (z[1:] <= z_pylons[1] + 1e-9),
                        cab.mass_per_length_main_kg_m, cab.mass_per_length_side_kg_m)
    node_weight = np.zeros(nz)
    node_weight[:-1] += 0.5 * g * seg_mass * seg_len
    node_weight[1:] += 0.5 * g * seg_mass * seg_len
    imbalance = np.zeros(nz)
    imbalance[1:-1] = H * (chord[1:] - chord[:-1]) - node_weight[1:-1]   # upward pull needed from below
    hanger_tension = imbalance[is_hanger]
    free_nodes = ~is_hanger
    free_nodes[[0, nz - 1, *i_pylon]] = False
    node_residual = float(np.max(np.abs(imbalance[free_nodes]))) if free_nodes.any() else 0.0
    girder_weight_per_cable = 0.5 * g * gir.mass_per_length_kg_m * total
    # hangers carry the girder between the supports; the girder's supported ends take half a panel each
    weight_residual = abs(hanger_tension.sum() - 0.5 * g * gir.mass_per_length_kg_m *
                          _hanger_tributary(z, is_hanger, i_pylon)) / girder_weight_per_cable
    if np.any(hanger_tension <= 0.0):
        raise InputError("cable statics", float(hanger_tension.min()), "hanger tensions must be > 0")

    top_level = len(levels) - 1
    for s, xs in enumerate((-half_b, half_b)):
        for i in range(nz):
            if i in i_pylon:
                cable_nodes[s, i] = legs[i_pylon.index(i), s][top_level]
            else:
                cable_nodes[s, i] = b.node(xs, cable_y[i], z[i])
        for i in range(nz - 1):
            b.element(cable_nodes[s, i], cable_nodes[s, i + 1], UP,
                      _cable_props(cab_m.youngs_modulus_Pa, cab.area_m2, seg_mass[i], seg_tension[i]), "cable")

    # ---- hangers and rigid links
    links = []
    for s, xs in enumerate((-half_b, half_b)):
        for i in np.flatnonzero(is_hanger):
            slave = b.node(xs, y_g, z[i])
            links.append((slave, int(girder[i])))
            b.element(slave, cable_nodes[s, i], ALONG,
                      _cable_props(han_m.youngs_modulus_Pa, han.area_m2, han.area_m2 * han.density_kg_m3,
                                   imbalance[i]), "hanger")

    # ---- pylon elements: legs and cross beams, with compression from the cable chords
    v_top = H * (abs(chord[i_pylon[0] - 1]) + abs(chord[i_pylon[0]]))
    G_c, E_c, rho_c = conc.shear_modulus_Pa, conc.youngs_modulus_Pa, conc.density_kg_m3
    sec_cross = [pyl.lower_cross_beam] + [pyl.upper_cross_beam] * (len(beams) - 1)
    cross_weight = [g * rho_c * sec.area_m2 * 2 * half_b for sec in sec_cross]

    def leg_section(y_mid: float) -> BoxSection:
        return pyl.lower_leg if y_mid < y_g else pyl.upper_leg

    # compression at each level: cable + leg weight above + half the cross beams at or above
    seg_weight = np.array([g * rho_c * leg_section(0.5 * (lo + hi)).area_m2 * (hi - lo)
                           for lo, hi in zip(levels[:-1], levels[1:], strict=False)])
    for ip in range(2):
        for s in range(2):
            nodes = legs[ip, s]
            for k in range(len(levels) - 1):
                y_mid = 0.5 * (levels[k] + levels[k + 1])
                above = seg_weight[k + 1:].sum() + 0.5 * seg_weight[k] + 0.5 * sum(
                    w for w, yb in zip(cross_weight, beams, strict=False) if yb > y_mid)
                sec = leg_section(y_mid)
                # legs: local e1 up, e2 = global z (along the bridge), e3 = global x (across);
                # deflection along z bends about the axis parallel to side b (across): i_about_b
                props = _beam_props(E_c, G_c, sec.area_m2, sec.i_about_b_m4, sec.i_about_a_m4,
                                    sec.torsion_constant_m4, rho_c * sec.area_m2, rho_c,
                                    axial=-(v_top + above))
                b.element(nodes[k], nodes[k + 1], ALONG, props,
                          "pylon_lower_leg" if sec is pyl.lower_leg else "pylon_upper_leg")
        for yb, sec in zip(beams, sec_cross, strict=False):
            k = int(np.argmin(abs(levels - yb)))
            a_node, b_node = legs[ip, 0][k], legs[ip, 1][k]
            n_cb = 4
            xs = np.linspace(-half_b, half_b, n_cb + 1)
            chain = [a_node] + [b.node(x, levels[k], z_pylons[ip]) for x in xs[1:-1]] + [b_node]
            # cross beams: e1 across, e2 up; vertical deflection bends about the axis parallel to a
            props = _beam_props(E_c, G_c, sec.area_m2, sec.i_about_a_m4, sec.i_about_b_m4,
                                sec.torsion_constant_m4, rho_c * sec.area_m2, rho_c)
            for c0, c1 in zip(chain[:-1], chain[1:], strict=False):
                b.element(c0, c1, UP, props, "pylon_cross_beam")

    nodes = np.array(b.nodes)
    conn = np.array(b.conn, dtype=int)
    group = np.array(b.group, dtype=int)
    elements = ElementSet(np.array(b.xa), np.array(b.xb), np.array(b.ov), np.array(b.props))

    rotational = np.zeros(len(nodes), dtype=bool)
    beam = elements.props[:, PROP_KIND] == KIND_BEAM
    rotational[conn[beam].ravel()] = True

    fixed: list[tuple[int, int]] = []
    for s in range(2):
        for end in (cable_nodes[s, 0], cable_nodes[s, -1]):
            fixed += [(int(end), d) for d in range(3)]
    for ip in range(2):
        for s in range(2):
            fixed += [(int(legs[ip, s][0]), d) for d in range(6)]
    for end in (girder[0], girder[-1]):
        fixed += [(int(end), d) for d in (0, 1, 2, 5)]
    for i in i_pylon:
        fixed += [(int(girder[i]), d) for d in (0, 1, 5)]

    return FrameModel(
        nodes=nodes, conn=conn, group=group, elements=elements, fixed=tuple(fixed), links=tuple(links),
        rotational=rotational, girder_nodes=girder, girder_z=z.copy(), cable_nodes=cable_nodes,
        hanger_tension_N=hanger_tension, cable_tension_N=seg_tension, cable_node_residual_N=node_residual,
        hanger_weight_residual=weight_residual, pylon_top_compression_N=v_top, deck_length_m=total,
        mid_span_z_m=side + 0.5 * span, pylon_z_m=z_pylons, n_sub=n_sub)


def _sub_polygon(points: np.ndarray, y: np.ndarray, n_sub: int, H: float, weight_per_length: np.ndarray,
                 iterations: int = 20) -> np.ndarray:
    """Elevations at the ``n_sub`` equal sub-divisions of each panel such that every intermediate node
    is in vertical equilibrium under half the weight of its two adjacent straight segments with the
    horizontal force H: the kink H (s_{k+1} - s_k) equals the nodal weight (funicular polygon of the
    self weight, fixed-point iteration on the segment lengths)."""
    out = [np.array([y[0]])]
    for p in range(len(points) - 1):
        dz = (points[p + 1] - points[p]) / n_sub
        slope = np.full(n_sub, (y[p + 1] - y[p]) / (points[p + 1] - points[p]))
        for _ in range(iterations):
            seg_w = weight_per_length[p] * dz * np.sqrt(1.0 + slope**2)
            kinks = 0.5 * (seg_w[:-1] + seg_w[1:]) / H
            rel = np.concatenate([[0.0], np.cumsum(kinks)])
            s0 = ((y[p + 1] - y[p]) / dz - rel.sum()) / n_sub   # closure: sum(s_k dz) = rise
            slope = s0 + rel
        out.append(y[p] + dz * np.cumsum(slope))
        out[-1][-1] = y[p + 1]
    return np.concatenate(out)


def _hanger_tributary(z: np.ndarray, is_hanger: np.ndarray, i_pylon: list[int]) -> float:
    """Girder length carried by the hangers: half the distance to the neighbouring panel point (hanger,
    pylon or girder end) on each side of every hanger."""
    points = np.flatnonzero(is_hanger | np.isin(np.arange(len(z)), [0, len(z) - 1, *i_pylon]))
    total = 0.0
    for k in range(1, len(points) - 1):
        if is_hanger[points[k]]:
            total += 0.5 * (z[points[k + 1]] - z[points[k - 1]])
    return total
