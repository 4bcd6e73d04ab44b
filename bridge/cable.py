"""Cable statics of a three-span suspension bridge under dead load (thesis chapter 2).

Per cable (the reading of thesis Eq 2.3 in docs/thesis_errata.md): each of the two main cables carries
half the girder, ``w_b = mu_b / 2``, plus its own weight along its arc.  With y up and H the (constant)
horizontal cable force,

    H y'' = g (w_b + mu_c sqrt(1 + y'^2))                                            (Eq 2.3)

Main span: x from mid-span (y = y' = 0) to the pylon (x = L/2, y = h); state vector Z = [y, y', s]
(s = arc length) integrated by classical RK4 (Eq 2.6-2.7).  H is iterated from the parabolic start
value (Eq 2.4, per cable) by Eq 2.5, ``H1 = (g/h) int_0^{L/2} (L/2 - x) w(x) dx``, until
``|H1/H0 - 1| < 1e-6``.  Since ``H y(L/2) = int_0^{L/2} int_0^x w = int_0^{L/2} (L/2 - x) w dx`` for the
profile integrated with H, Eq 2.5 is evaluated as ``H1 = H0 y_H0(L/2) / h``: the same integral, with
RK4's fourth-order accuracy (the profile update Eq 2.8 is implied: the next RK4 pass recomputes y).

Side spans: shooting on the anchor slope alpha_0 (Eq 2.9-2.11) with the main-span H, from the anchor
(x = 0, y = 0, at the level of the mid-span low point as Eq 2.10 assumes) to the pylon top (x = L_s, y = h).
ERRATUM: with y up the cable is convex (y'' > 0), so the parabolic start value is
``alpha_0 = h/L_s - g w L_s / (2 H)``; the thesis's Eq 2.9-2.10 carry the opposite sign of the load term
(the shooting update Eq 2.11 converges from either, the correct start saves iterations).

Outputs: H per cable and for both cables, profiles, cable lengths, hanger lengths (cable minus the
horizontal girder axis), vertical reactions (Eq 2.12), the global equilibrium residual of Eq 2.13, and the
first vertical frequency estimate of Eq 3.2.

Hangers: equal panels from pylon to pylon (thesis 2.1.1), an even number of panels nearest the target
spacing (a hanger at mid-span); side spans likewise with their own whole number of panels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .config import GRAVITY_M_S2, Scenario
from .errors import ConvergenceError, InputError

__all__ = ["CableSpan", "CableSolution", "solve_cables", "integrate_rk4", "solve_main_span", "solve_side_span",
           "panel_count"]

H_TOLERANCE = 1e-6          # thesis 2.1.1: |H1/H0 - 1| < 1e-6
SHOOTING_TOLERANCE = 1e-10  # side span: |y(L_s) - h| / h
MAX_ITERATIONS = 200


def integrate_rk4(horizontal_force: float, girder_load: float, cable_mass: float, length: float,
                  steps: int, slope0: float = 0.0, g: float = GRAVITY_M_S2) -> tuple[np.ndarray, ...]:
    """Classical RK4 on Z = [y, y', s] from x = 0 (y = 0, y' = slope0) to x = ``length`` in ``steps`` steps.

    ``girder_load`` and ``cable_mass`` are masses per length (kg/m) carried by this cable: the girder's per
    horizontal metre, the cable's per metre of arc (Eq 2.3).  Returns x, y, y', s at the step nodes.
    """
    if steps < 1:
        raise InputError("cable.steps", steps, "must be >= 1")
    c = g / horizontal_force
    dx = length / steps

    def rhs(z: np.ndarray) -> np.ndarray:
        root = math.sqrt(1.0 + z[1] * z[1])
        return np.array([z[1], c * (girder_load + cable_mass * root), root])

    out = np.empty((steps + 1, 3))
    z = np.array([0.0, slope0, 0.0])
    out[0] = z
    for i in range(steps):
        k1 = rhs(z)
        k2 = rhs(z + 0.5 * dx * k1)
        k3 = rhs(z + 0.5 * dx * k2)
        k4 = rhs(z + dx * k3)
        z = z + (dx / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        out[i + 1] = z
    x = np.linspace(0.0, length, steps + 1)
    return x, out[:, 0], out[:, 1], out[:, 2]


def solve_main_span(half_span: float, sag: float, girder_load: float, cable_mass: float, steps: int,
                    tolerance: float = H_TOLERANCE, g: float = GRAVITY_M_S2) -> tuple[float, int, float, tuple]:
    """H of one cable over the main span by the iteration of Eq 2.4-2.5.

    Returns (H, iterations, last |H1/H0 - 1|, (x, y, y', s)).  Raises ConvergenceError with the last residual.
    """
    span = 2.0 * half_span
    h0 = g * (girder_load + cable_mass) * span**2 / (8.0 * sag)  # Eq 2.4 (per cable)
    residual = math.inf
    for it in range(1, MAX_ITERATIONS + 1):
        x, y, yp, s = integrate_rk4(h0, girder_load, cable_mass, half_span, steps, 0.0, g)
        h1 = h0 * y[-1] / sag  # Eq 2.5, see module docstring
        residual = abs(h1 / h0 - 1.0)
        h0 = h1
        if residual < tolerance:
            x, y, yp, s = integrate_rk4(h0, girder_load, cable_mass, half_span, steps, 0.0, g)
            return h0, it, residual, (x, y, yp, s)
    raise ConvergenceError("main-span H iteration (Eq 2.5)", MAX_ITERATIONS, residual, tolerance)


def solve_side_span(horizontal_force: float, side_span: float, rise: float, girder_load: float,
                    cable_mass: float, steps: int, tolerance: float = SHOOTING_TOLERANCE,
                    g: float = GRAVITY_M_S2) -> tuple[float, int, float, tuple]:
    """Anchor slope alpha_0 by shooting (Eq 2.11) so that y(L_s) = rise.  Returns (alpha_0, iterations,
    last |y(L_s) - h|/h, (x, y, y', s))."""
    w = g * (girder_load + cable_mass)
    alpha = rise / side_span - w * side_span / (2.0 * horizontal_force)  # parabolic start (Eq 2.10, sign fixed)
    residual = math.inf
    for it in range(1, MAX_ITERATIONS + 1):
        x, y, yp, s = integrate_rk4(horizontal_force, girder_load, cable_mass, side_span, steps, alpha, g)
        miss = rise - y[-1]
        residual = abs(miss) / rise
        if residual < tolerance:
            return alpha, it, residual, (x, y, yp, s)
        alpha += miss / side_span  # Eq 2.11
    raise ConvergenceError("side-span shooting on the anchor slope (Eq 2.11)", MAX_ITERATIONS, residual, tolerance)


def panel_count(span: float, target_spacing: float, even: bool) -> int:
    """Number of equal panels nearest ``target_spacing`` (even if asked, so a hanger sits at mid-span)."""
    n = max(1, round(span / target_spacing))
    if even:
        n = max(2, 2 * round(span / (2.0 * target_spacing)))
    return n


@dataclass(frozen=True)
class CableSpan:
    """One span of one cable at the RK4 nodes: global position ``z_m`` along the bridge (0 at the left
    anchor), absolute ``elevation_m`` above the pylon foundations, ``slope`` dy/dz, and the span's arc length."""

    name: str
    z_m: np.ndarray
    elevation_m: np.ndarray
    slope: np.ndarray
    length_m: float


@dataclass(frozen=True)
class CableSolution:
    """Dead-load state of the cable system; forces are per cable unless named ``_total`` / ``_both``."""

    horizontal_force_per_cable_N: float
    parabolic_estimate_total_N: float
    main_iterations: int
    main_residual: float
    side_iterations: int
    side_residual: float
    anchor_slope: float
    spans: tuple[CableSpan, CableSpan, CableSpan]   # left side span, main span, right side span
    hanger_z_m: np.ndarray
    hanger_cable_elevation_m: np.ndarray
    hanger_length_m: np.ndarray
    hanger_span: np.ndarray                          # 0 left side, 1 main, 2 right side
    main_panel_m: float
    side_panel_m: float
    v_pylon_main_per_cable_N: float
    v_pylon_side_per_cable_N: float
    v_anchor_per_cable_N: float
    total_weight_N: float
    equilibrium_residual: float
    first_vertical_frequency_estimate_hz: float
    girder_elevation_m: float
    steps_per_panel: int

    @property
    def horizontal_force_total_N(self) -> float:
        return 2.0 * self.horizontal_force_per_cable_N

    @property
    def v_pylon_per_cable_N(self) -> float:
        return self.v_pylon_main_per_cable_N + self.v_pylon_side_per_cable_N

    @property
    def main_cable_length_m(self) -> float:
        return self.spans[1].length_m

    @property
    def side_cable_length_m(self) -> float:
        return self.spans[0].length_m

    def cable_stress_Pa(self, area_m2: float) -> float:
        """Largest cable stress: at the pylon top, T = H sqrt(1 + y'^2) over the area."""
        slope = max(abs(self.spans[1].slope[-1]), abs(self.spans[0].slope[-1]))
        return self.horizontal_force_per_cable_N * math.sqrt(1.0 + slope**2) / area_m2


def solve_cables(scenario: Scenario, steps_per_panel: int = 8, tolerance: float = H_TOLERANCE) -> CableSolution:
    """Cable statics of the scenario's bridge (module docstring)."""
    if scenario.kind != "suspension_bridge":
        raise InputError("kind", scenario.kind, "cable statics need a suspension_bridge scenario")
    geo, cab, g = scenario.geometry, scenario.cable, GRAVITY_M_S2
    span, side, sag = geo.main_span_m, geo.side_span_m, geo.sag_m
    w_b = 0.5 * scenario.girder.mass_per_length_kg_m  # per cable, docs/thesis_errata.md
    mu_c, mu_cs = cab.mass_per_length_main_kg_m, cab.mass_per_length_side_kg_m

    n_main = panel_count(span, geo.hanger_spacing_target_m, even=True)
    n_side = panel_count(side, geo.hanger_spacing_target_m, even=False)
    half_steps = (n_main // 2) * steps_per_panel

    h, it_m, res_m, (x, y, yp, s) = solve_main_span(0.5 * span, sag, w_b, mu_c, half_steps, tolerance, g)
    alpha, it_s, res_s, (xs, ys, yps, ss) = solve_side_span(h, side, sag, w_b, mu_cs, n_side * steps_per_panel,
                                                            g=g)

    low = geo.cable_low_point_m
    # global coordinates: z = 0 at the left anchor, pylons at L_s and L_s + L, right anchor at L + 2 L_s
    left = CableSpan("side_left", xs.copy(), low + ys, yps.copy(), float(ss[-1]))
    z_mid = side + 0.5 * span
    zm = np.concatenate([z_mid - x[::-1], z_mid + x[1:]])
    main = CableSpan("main", zm, low + np.concatenate([y[::-1], y[1:]]),
                     np.concatenate([-yp[::-1], yp[1:]]), float(2.0 * s[-1]))
    right = CableSpan("side_right", span + 2 * side - xs[::-1], low + ys[::-1], -yps[::-1], float(ss[-1]))

    # hangers at the interior panel points of every span (pylons and anchors are supports, not hangers)
    k = steps_per_panel
    hz, he, hs = [], [], []
    for idx, sp in enumerate((left, main, right)):
        nodes = slice(k, len(sp.z_m) - 1, k)
        hz.append(sp.z_m[nodes])
        he.append(sp.elevation_m[nodes])
        hs.append(np.full(len(sp.z_m[nodes]), idx))
    hanger_z, hanger_el = np.concatenate(hz), np.concatenate(he)
    hanger_len = hanger_el - geo.girder_elevation_m

    # Eq 2.12 reactions per cable (upward on the cable) and the global check Eq 2.13 for both cables
    v_main = h * yp[-1]
    v_side = h * yps[-1]
    v_anchor = -h * alpha
    weight = g * (scenario.girder.mass_per_length_kg_m * (span + 2 * side) + 2 * mu_c * main.length_m
                  + 4 * mu_cs * left.length_m)
    supports = 2 * 2 * (v_main + v_side + v_anchor)  # two cables, two pylons/anchors each
    residual = abs(supports - weight) / weight

    h_parabolic_total = g * (scenario.girder.mass_per_length_kg_m + 2 * mu_c) * span**2 / (8 * sag)  # Eq 1.1/2.4
    m = scenario.deck_mass_per_length_kg_m
    f1 = 8.99 * math.sqrt(2 * h / (m * span**2)) / (2 * math.pi)  # Eq 3.2-3.3, H of both cables, m = mu

    return CableSolution(
        horizontal_force_per_cable_N=h, parabolic_estimate_total_N=h_parabolic_total,
        main_iterations=it_m, main_residual=res_m, side_iterations=it_s, side_residual=res_s,
        anchor_slope=alpha, spans=(left, main, right), hanger_z_m=hanger_z, hanger_cable_elevation_m=hanger_el,
        hanger_length_m=hanger_len, hanger_span=np.concatenate(hs), main_panel_m=span / n_main,
        side_panel_m=side / n_side, v_pylon_main_per_cable_N=v_main, v_pylon_side_per_cable_N=v_side,
        v_anchor_per_cable_N=v_anchor, total_weight_N=weight, equilibrium_residual=residual,
        first_vertical_frequency_estimate_hz=f1, girder_elevation_m=geo.girder_elevation_m,
        steps_per_panel=steps_per_panel)
