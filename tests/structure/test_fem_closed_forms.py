"""Frequencies of straight beams and strings against closed forms, with the observed convergence order
(log-log slope over three refinements).  Sources: docs/reference_cases.md "Structures"; Blevins, Formulas for
Natural Frequency and Mode Shape (1979), tables 8-1 and 8-2; taut string f_n = (n / 2L) sqrt(T/m)."""

from __future__ import annotations

import numpy as np
import pytest
from fem_helpers import DEVICES, KIND_CABLE, frequencies, line_model, node_dofs, observed_order, props_row

L, EI, M_LEN, GJ, POLAR = 100.0, 3.0e9, 500.0, 2.0e9, 4.0e4
REFINEMENTS = (4, 8, 16)
V_PLANE, W_PLANE, TWIST = (1, 3), (0, 4), (5,)   # (u_y, theta_x), (u_x, theta_y), theta_z for a beam along z


def beam(n: int, ei_vertical=EI, ei_lateral=2 * EI, axial=0.0):
    return line_model(n, L, props_row(ea=1e12, ei2=ei_vertical, ei3=ei_lateral, gj=GJ, mass=M_LEN,
                                      polar=POLAR, axial=axial))


def plane_dofs(n: int, plane) -> np.ndarray:
    return node_dofs(range(n + 1), plane)


@pytest.mark.parametrize("plane, ei", [(V_PLANE, EI), (W_PLANE, 2 * EI)], ids=["vertical", "lateral"])
def test_simply_supported_beam_fourth_order(plane, ei):
    errors = []
    for n in REFINEMENTS:
        nodes, conn, es = beam(n)
        f = frequencies(nodes, conn, es, node_dofs([0, n], plane[:1]), plane_dofs(n, plane), n_modes=3)
        exact = np.array([k * k * np.pi / (2 * L * L) * np.sqrt(ei / M_LEN) for k in (1, 2, 3)])
        errors.append(abs(f[2] / exact[2] - 1.0))
        assert np.allclose(f, exact, rtol=2e-2)
    assert errors[-1] < 2e-4
    assert 3.6 < observed_order([L / n for n in REFINEMENTS], errors) < 4.4


@pytest.mark.parametrize("device", DEVICES)
def test_cantilever_beta_L(device):
    """beta_1 L = 1.8751, beta_2 L = 4.6941 (Blevins 1979), f = (beta L)^2 / (2 pi L^2) sqrt(EI/m)."""
    exact_beta = np.array([1.875104069, 4.694091133])
    errors = []
    for n in REFINEMENTS:
        nodes, conn, es = beam(n)
        f = frequencies(nodes, conn, es, node_dofs([0], range(6)), plane_dofs(n, V_PLANE), 2, device)
        beta = np.sqrt(2 * np.pi * f * L * L / np.sqrt(EI / M_LEN))
        errors.append(abs(beta[1] / exact_beta[1] - 1.0))
    assert beta == pytest.approx([1.8751, 4.6941], abs=1e-4)
    assert 3.6 < observed_order([L / n for n in REFINEMENTS], errors) < 4.4


def test_torsion_fixed_fixed_second_order():
    errors = []
    for n in REFINEMENTS:
        nodes, conn, es = beam(n)
        f = frequencies(nodes, conn, es, node_dofs([0, n], TWIST), plane_dofs(n, TWIST), n_modes=2)
        exact = np.array([1.0, 2.0]) / (2 * L) * np.sqrt(GJ / POLAR)
        errors.append(abs(f[1] / exact[1] - 1.0))
        assert np.allclose(f, exact, rtol=0.15)
    assert 1.8 < observed_order([L / n for n in REFINEMENTS], errors) < 2.2


@pytest.mark.parametrize("n_elements", [8, 32])
def test_taut_string_cable_elements(n_elements):
    """Cable elements carry transverse stiffness only through tension: f_n = (n/2L) sqrt(T/m)."""
    tension = 4.0e6
    nodes, conn, es = line_model(n_elements, L, props_row(ea=1e10, mass=M_LEN, axial=tension, kind=KIND_CABLE))
    f = frequencies(nodes, conn, es, node_dofs([0, n_elements], (0, 1, 2)),
                    node_dofs(range(n_elements + 1), (1,)), n_modes=3)
    exact = np.arange(1, 4) / (2 * L) * np.sqrt(tension / M_LEN)
    assert np.allclose(f, exact, rtol=0.08 if n_elements == 8 else 0.005)


def test_taut_string_second_order():
    tension, errors = 4.0e6, []
    for n in REFINEMENTS:
        nodes, conn, es = line_model(n, L, props_row(ea=1e10, mass=M_LEN, axial=tension, kind=KIND_CABLE))
        f = frequencies(nodes, conn, es, node_dofs([0, n], (0, 1, 2)), node_dofs(range(n + 1), (0,)), n_modes=1)
        errors.append(abs(f[0] / (np.sqrt(tension / M_LEN) / (2 * L)) - 1.0))
    assert 1.8 < observed_order([L / n for n in REFINEMENTS], errors) < 2.2


def test_untensioned_cable_has_no_transverse_frequency():
    """The classic mistake the string test catches: without geometric stiffness a cable is a mechanism."""
    n = 8
    nodes, conn, es = line_model(n, L, props_row(ea=1e10, mass=M_LEN, axial=0.0, kind=KIND_CABLE))
    f = frequencies(nodes, conn, es, node_dofs([0, n], (0, 1, 2)), node_dofs(range(n + 1), (1,)), n_modes=1)
    assert f[0] < 1e-6


def test_beam_geometric_stiffness_under_tension():
    """Simply supported beam with axial tension N: omega^2 = (k^4 EI + k^2 N)/m, k = n pi / L."""
    tension = 5.0e6
    nodes, conn, es = beam(32, axial=tension)
    f = frequencies(nodes, conn, es, node_dofs([0, 32], (1,)), plane_dofs(32, V_PLANE), n_modes=3)
    k = np.arange(1, 4) * np.pi / L
    exact = np.sqrt((k**4 * EI + k**2 * tension) / M_LEN) / (2 * np.pi)
    assert np.allclose(f, exact, rtol=1e-4)
    assert not np.allclose(f, np.sqrt(k**4 * EI / M_LEN) / (2 * np.pi), rtol=1e-2)  # tension matters here


@pytest.mark.parametrize("lambda2", [10.0, 40.0, 150.0])
def test_irvine_caughey_sagging_cable(lambda2):
    """First symmetric in-plane mode of a shallow sagging cable (Irvine & Caughey 1974; docs/reference_cases.md):
    tan(w/2) = w/2 - (4/lambda^2)(w/2)^3, w = omega L sqrt(m/H), lambda^2 = (m g L/H)^2 L/(H L_e/EA).
    Checks the elastic (EA) and geometric (H) stiffness of the cable elements working together; the
    antisymmetric mode (w = 2 pi) does not stretch the cable and is independent of lambda^2."""
    from scipy.optimize import brentq

    from bridge.structure.elements import ElementSet

    span, mass, sag, g, n = 200.0, 100.0, 4.0, 9.81, 64
    H = mass * g * span**2 / (8 * sag)
    length_e = span * (1 + 8 * (sag / span) ** 2)
    ea = lambda2 / (8 * sag / span) ** 2 * H * length_e / span
    x = np.linspace(0.0, span, n + 1)
    y = -4 * sag * x * (span - x) / span**2
    nodes = np.stack([np.zeros_like(x), y, x], axis=1)
    slope = np.diff(y) / np.diff(x)
    props = np.array([props_row(ea=ea, mass=mass, axial=H * np.sqrt(1 + s * s), kind=KIND_CABLE) for s in slope])
    es = ElementSet(nodes[:-1].copy(), nodes[1:].copy(), np.tile([1.0, 0.0, 0.0], (n, 1)), props)
    conn = np.stack([np.arange(n), np.arange(1, n + 1)], axis=1)
    f = frequencies(nodes, conn, es, node_dofs([0, n], (0, 1, 2)), node_dofs(range(n + 1), (1, 2)), n_modes=2)
    scale = np.sqrt(H / mass) / span / (2 * np.pi)
    root = brentq(lambda w: np.tan(w / 2) - w / 2 + 4 / lambda2 * (w / 2) ** 3, 1.0001 * np.pi, 2.9999 * np.pi)
    f_sym, f_anti = root * scale, 2 * np.pi * scale
    assert min(abs(f / f_sym - 1.0)) < 5e-3
    assert min(abs(f / f_anti - 1.0)) < 5e-3
