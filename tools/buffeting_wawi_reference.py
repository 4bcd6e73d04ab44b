"""Reference numbers for the buffeting stage from an independent implementation of the same theory: wawi
(Kvåle, NTNU: https://github.com/knutankv/wawi, version 0.0.19 from the package index), which computes
multimode buffeting from beam elements, Kaimal or von Karman spectra, Davenport coherence, quasi-steady loads
(Øiseth et al. 2010, its loadmatrix_fe) with an admittance, and self-excited forces from aerodynamic
derivatives.  wawi is NOT a dependency of this project; run this in an environment of its own (wawi 0.0.19
calls numpy.trapz, which numpy 2.4 removed):

    python -m venv /tmp/wawienv && /tmp/wawienv/bin/pip install wawi==0.0.19 "numpy<2.4"
    /tmp/wawienv/bin/python tools/buffeting_wawi_reference.py --out tests/buffeting/data/wawi_reference.json

It writes the inputs and wawi's RMS displacements (mid-span and quarter span; vertical, torsional, lateral)
for two cases to that JSON file, which tests/buffeting/test_wawi.py reads: the test builds the same case
with bridge.buffeting and compares (within 2 %).  Nothing of bridge is imported here.

The case: a simply supported deck of span L on 600 beam elements, four sine modes (two vertical, one
torsional, one lateral) with their modal masses mu L / 2 and J L / 2, static coefficients on B (wawi's D =
B, so that its drag on D is ours on B), mean wind normal to the span.
* case "A": Kaimal spectra, Sears's admittance (|phi(k)| in wawi's Bq, an independent implementation
  here: Bessel functions and Theodorsen's C from scipy), quasi-steady self-excited forces (wawi's
  quasisteady_ads);
* case "B": von Karman spectra, no admittance, the flat plate's self-excited forces (wawi's flatplate_ads,
  Theodorsen), no lateral aerodynamic derivatives (as bridge.flutter.aerodynamics.Theodorsen).

wawi's parts used: generic_kaimal_matrix (turbulence at the nodes, one-sided per rad/s), windaction (the
modal load cross-spectra, wawi's element load vectors, evaluated on ``--load-points`` frequencies and
interpolated quadratically by wawi), compute_aero_matrices (K_ae, C_ae from the derivatives on
``--aero-points`` frequencies, interpolated by wawi), freqsim (S_r = H S_Q H^*) and var_from_modal (the
variance by numpy's trapezoidal rule over omega).  The FRF H = [-w^2 M + i w (C - C_ae) + K - K_ae]^-1 is
written out as wawi's Model.get_frf_fun writes it (wawi/model/_model.py), since wawi's Model needs a BEEF
element model.  wawi's axes: x along the span, y downwind, z up; its torsion theta_x is nose-DOWN (the
moment row of its Bq has -B C_M), so its twist DOF is minus ours; its bending rotations are the slopes
(theta_y = -du_z/dx, theta_z = du_y/dx) that its Hermitian element matrices need.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from importlib.metadata import version
from pathlib import Path

import numpy as np
from scipy.special import hankel2, j0, j1

CASE = {
    "span_m": 1200.0, "elements": 600, "deck_width_m": 25.0, "air_density_kg_m3": 1.25,
    "mass_per_length_kg_m": 15000.0, "inertia_per_length_kg_m2_m": 1.2e6,
    "modes": [  # label, kind, half-waves along the span, natural frequency [Hz], damping ratio
        {"label": "V1", "kind": "vertical", "half_waves": 1, "frequency_hz": 0.12, "damping_ratio": 0.005},
        {"label": "V2", "kind": "vertical", "half_waves": 2, "frequency_hz": 0.17, "damping_ratio": 0.005},
        {"label": "T1", "kind": "torsional", "half_waves": 1, "frequency_hz": 0.32, "damping_ratio": 0.01},
        {"label": "L1", "kind": "lateral", "half_waves": 1, "frequency_hz": 0.07, "damping_ratio": 0.005}],
    "static_coefficients": {"drag_coefficient": 0.09, "drag_slope_per_rad": -0.1, "lift_coefficient": -0.35,
                            "lift_slope_per_rad": 4.0, "moment_coefficient": 0.02, "moment_slope_per_rad": 0.5},
    "speeds_m_s": [15.0, 30.0, 45.0],
    "max_frequency_hz": 0.5,
    "stations": {"midspan": 0.5, "quarter_span": 0.25},   # as fractions of the span
    "cases": {
        "A": {"spectrum": "kaimal", "turbulence_intensity_u": 0.12, "turbulence_intensity_w": 0.06,
              "length_scale_u_m": 150.0, "length_scale_w_m": 12.5, "coherence_decay_u": 10.0,
              "coherence_decay_w": 6.5, "admittance": "sears", "self_excited": "quasi_steady"},
        "B": {"spectrum": "von_karman", "turbulence_intensity_u": 0.10, "turbulence_intensity_w": 0.06,
              "length_scale_u_m": 120.0, "length_scale_w_m": 10.0, "coherence_decay_u": 8.0,
              "coherence_decay_w": 6.0, "admittance": "none", "self_excited": "theodorsen"}},
}
DOFS = ("vertical", "torsional", "lateral")


class Node:
    """What wawi reads of a BEEF node."""

    def __init__(self, index: int, x: float):
        self.index, self.coordinates = index, np.array([x, 0.0, 0.0])
        self.global_dofs = np.arange(6 * index, 6 * index + 6)


class Element:
    """What wawi reads of a BEEF beam element along global x (local axes = global: T0 = I)."""

    def __init__(self, a: Node, b: Node):
        self.nodes = (a, b)
        self.L = float(b.coordinates[0] - a.coordinates[0])
        self.T0 = np.eye(3)
        self.global_dofs = np.concatenate([a.global_dofs, b.global_dofs])

    def get_cog(self) -> np.ndarray:
        return 0.5 * (self.nodes[0].coordinates + self.nodes[1].coordinates)


def mode_shapes(case: dict, x: np.ndarray) -> np.ndarray:
    """phi (6 n_nodes, N) in wawi's DOFs (module docstring)."""
    L = case["span_m"]
    phi = np.zeros((6 * x.size, len(case["modes"])))
    for i, m in enumerate(case["modes"]):
        k = m["half_waves"] * np.pi / L
        s, ds = np.sin(k * x), k * np.cos(k * x)
        if m["kind"] == "vertical":
            phi[2::6, i], phi[4::6, i] = s, -ds
        elif m["kind"] == "lateral":
            phi[1::6, i], phi[5::6, i] = s, ds
        else:
            phi[3::6, i] = -s                       # theta_x nose-down = -(nose-up twist)
    return phi


def sears_magnitude(reduced_frequency: np.ndarray) -> np.ndarray:
    """|phi(k)| of Sears's function at k = pi f B / V (f B / V given), written out independently."""
    k = np.pi * np.asarray(reduced_frequency, dtype=float)
    if k <= 0.0:
        return 1.0
    C = hankel2(1, k) / (hankel2(1, k) + 1j * hankel2(0, k))
    return abs((j0(k) - 1j * j1(k)) * C + 1j * j1(k))


def run_case(case: dict, name: str, speed: float, load_points: int, aero_points: int, steps: int) -> dict:
    from wawi.structural import freqsim, var_from_modal
    from wawi.wind import (
        ADs,
        LoadCoefficients,
        compute_aero_matrices,
        flatplate_ads,
        generic_kaimal_matrix,
        quasisteady_ads,
        windaction,
    )

    c = case["cases"][name]
    L, B, rho = case["span_m"], case["deck_width_m"], case["air_density_kg_m3"]
    x = np.linspace(0.0, L, case["elements"] + 1)
    nodes = [Node(i, xi) for i, xi in enumerate(x)]
    elements = [Element(a, b) for a, b in zip(nodes[:-1], nodes[1:], strict=True)]
    phi = mode_shapes(case, x)
    T_wind = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])   # wind x = global y (downwind)
    sc = case["static_coefficients"]
    lc = {"Cd": sc["drag_coefficient"], "dCd": sc["drag_slope_per_rad"], "Cl": sc["lift_coefficient"],
          "dCl": sc["lift_slope_per_rad"], "Cm": sc["moment_coefficient"], "dCm": sc["moment_slope_per_rad"]}
    sigma = speed * np.array([c["turbulence_intensity_u"], 0.0, c["turbulence_intensity_w"]])
    Lx = np.array([c["length_scale_u_m"], c["length_scale_u_m"], c["length_scale_w_m"]])
    A = np.array([6.8, 9.4, 9.4])
    C = np.zeros((3, 3))
    C[1, 0], C[1, 2] = c["coherence_decay_u"], c["coherence_decay_w"]   # span = wind y axis
    kind = "kaimal" if c["spectrum"] == "kaimal" else "vonKarman"

    def wind(_coordinates):
        return speed

    def turbulence(omega_k):
        return generic_kaimal_matrix(omega_k, nodes, T_wind, A, sigma, C, Lx, wind, spectrum_type=kind)

    def admittance(fB_over_V):
        return np.full((4, 3), sears_magnitude(fB_over_V) if c["admittance"] == "sears" else 1.0)

    # our grid f = 0 ... f_max (odd count); wawi's spectra divide by f, so its first point is 1e-9 rad/s
    omega = 2 * np.pi * np.linspace(0.0, case["max_frequency_hz"], steps)
    omega[0] = 1e-9
    omega_load = np.concatenate([[1e-9], np.linspace(omega[-1] / (load_points - 1), omega[-1], load_points - 1)])
    Sqq = windaction(omega, turbulence, {"deck": lc}, elements, T_wind, phi, {"deck": B}, {"deck": B}, wind,
                     omega_reduced=omega_load, rho=rho, print_progress=False,
                     section_lookup={"deck": elements}, nodes=nodes, admittance={"deck": admittance})(omega)
    ad = quasisteady_ads(B, B, LoadCoefficients(**lc)) if c["self_excited"] == "quasi_steady" else flatplate_ads()
    omega_aero = np.concatenate([[1e-9], np.linspace(omega[-1] / (aero_points - 1), omega[-1], aero_points - 1)])
    Kae, Cae = compute_aero_matrices(speed, ADs(**ad), B, elements, T_wind, phi, omega_reduced=omega_aero, rho=rho)
    mu, J = case["mass_per_length_kg_m"], case["inertia_per_length_kg_m2_m"]
    m = np.array([(J if md["kind"] == "torsional" else mu) * L / 2 for md in case["modes"]])
    wn = np.array([2 * np.pi * md["frequency_hz"] for md in case["modes"]])
    zeta = np.array([md["damping_ratio"] for md in case["modes"]])
    M, K, Cs = np.diag(m), np.diag(m * wn**2), np.diag(2 * m * zeta * wn)
    H = np.stack([np.linalg.inv(-w**2 * M + 1j * w * (Cs - Cae(w)) + K - Kae(w)) for w in omega], axis=2)
    Srr = freqsim(Sqq, H)
    out = {}
    for station, fraction in case["stations"].items():
        i = int(round(fraction * case["elements"]))
        rows = phi[[6 * i + 2, 6 * i + 3, 6 * i + 1], :]              # u_z, theta_x, u_y at the node
        out[station] = dict(zip(DOFS, np.sqrt(var_from_modal(omega, Srr, rows)).tolist(), strict=True))
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=Path("tests/buffeting/data/wawi_reference.json"))
    p.add_argument("--steps", type=int, default=4001, help="frequencies 0 ... max_frequency_hz (odd)")
    p.add_argument("--load-points", type=int, default=401, help="frequencies of wawi's windaction")
    p.add_argument("--aero-points", type=int, default=121, help="frequencies of wawi's aero matrices")
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    results = {}
    for name in CASE["cases"]:
        results[name] = []
        for speed in CASE["speeds_m_s"]:
            results[name].append(run_case(CASE, name, speed, args.load_points, args.aero_points, args.steps))
            print(f"case {name}, V = {speed:g} m/s: {results[name][-1]} ({time.perf_counter() - t0:.0f} s)",
                  file=sys.stderr, flush=True)
    record = {"command": " ".join(["/tmp/wawienv/bin/python", "tools/buffeting_wawi_reference.py", *sys.argv[1:]]),
              "wawi_version": version("wawi"), "numpy_version": np.__version__,
              "frequency_steps": args.steps, "load_points": args.load_points, "aero_points": args.aero_points,
              "inputs": CASE, "rms": results,
              "note": "RMS of the vertical [m], torsional [rad] and lateral [m] displacement per case, speed "
                      "(inputs.speeds_m_s) and station (fractions of the span); tools/buffeting_wawi_reference.py"}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=1) + "\n")
    print(f"wrote {args.out} in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
