"""The thesis's Table 5.2 / 5.3 (rate FRFs of the Great Belt deck at Omega ~ 0.5) beside Theodorsen's thin plate
and the project's CFD.

    python tools/thesis_table_5_3.py [out/great_belt_cfd/results.h5]

The thesis (5.3) moved the deck at V = 50 m/s, w = 0.8 rad/s and at V = 25 m/s, w = 0.4 rad/s (the same
Omega = w B / V = 0.496 with B = 31 m) and reports |H_xdot| = sqrt(2) rms and the phase phi, H_xdot =
|H| (cos phi - i sin phi) (Eq 5.13-5.14), in N s/m^2, N s/m, N s/m, N s.  Dimensional analysis: with the
normalised FRFs h_xy of Eq 4.37 depending on Omega alone, H_pudot = h_pu (rho V^2 / 2) / (i w) grows like V
at fixed Omega, so the two columns should differ by a factor 2 in every amplitude and not at all in the
phases; the thesis's amplitudes differ by 3-9 %.  This tool prints, for both speeds, the thesis's values,
Theodorsen's (flat plate, mid-chord axis) and, given a results.h5 with an ``/aero`` group, the CFD's (the
stage's derivative table at Omega = 0.496), and the normalised |h_xy| each implies.  The phases are printed
twice: phi of the rate FRF (what Eq 5.12 defines) and phi of H_x = i w H_xdot, the phase against the
displacement (Eq 5.8: phi_x = phi_xdot - pi/2).  The thesis's V = 25 m/s phases lie within 0.2 rad of
Theodorsen's displacement phases and about pi/2 from its rate phases: the thesis seems to have measured them
against the displacement.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bridge.flutter.aerodynamics import Theodorsen  # noqa: E402
from bridge.flutter.derivatives import FRF  # noqa: E402

RHO, B = 1.225, 31.0
CASES = ((25.0, 0.4), (50.0, 0.8))
# thesis Table 5.3: amplitude at (V = 25, w = 0.4), (V = 50, w = 0.8); phases [rad] likewise
THESIS = {"h_pu": ((1.95e3, 1.77e3), (1.645, 1.275)), "h_mu": ((1.66e4, 1.52e4), (1.717, 1.510)),
          "h_ptheta": ((3.95e4, 4.16e4), (-0.073, -0.400)), "h_mtheta": ((3.49e5, 3.39e5), (0.253, 0.174))}
POWER = {"h_pu": 0, "h_mu": 1, "h_ptheta": 1, "h_mtheta": 2}   # B^n of Eq 4.37
UNIT = {"h_pu": "N s/m^2", "h_mu": "N s/m", "h_ptheta": "N s/m", "h_mtheta": "N s"}


def rate_frf(h: complex, name: str, V: float, w: float) -> complex:
    """H_xdot = H_x / (i w), H_x = h (rho V^2 / 2) B^n (Eq 4.37, Eq 5.4 corrected)."""
    return h * 0.5 * RHO * V**2 * B ** POWER[name] / (1j * w)


def normalised(amplitude: float, phase: float, name: str, V: float, w: float) -> complex:
    """h_xy from the thesis's |H_xdot| and phi (Eq 5.14, 5.4 corrected, 4.37)."""
    H = amplitude * (np.cos(phase) - 1j * np.sin(phase))
    return H * 1j * w / (0.5 * RHO * V**2 * B ** POWER[name])


def cfd_model(path: Path):
    import h5py

    from bridge.flutter.derivatives import derivatives_from_frf
    from bridge.flutter.tables import DerivativeTable

    with h5py.File(path, "r") as h5:
        g = h5["aero"]
        K = g["reduced_frequency"][()]
        frf = FRF(**{n: g[n][()] for n in ("h_pu", "h_ptheta", "h_mu", "h_mtheta")})
        label = f"CFD ({g.attrs['section'][:40]}, {g.attrs['quality']}, Re {g.attrs['reynolds']:g})"
    return DerivativeTable(K, derivatives_from_frf(K, frf)), label, (float(K.min()), float(K.max()))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("results", nargs="?", type=Path, help="a results.h5 with an /aero group (optional)")
    args = ap.parse_args(argv)
    models = [(Theodorsen(), "Theodorsen (flat plate)")]
    if args.results:
        model, label, krange = cfd_model(args.results)
        omega = CASES[0][1] * B / CASES[0][0]
        if not krange[0] <= omega <= krange[1]:
            print(f"the CFD table covers Omega {krange[0]:.3f}-{krange[1]:.3f}, not {omega:.3f}", file=sys.stderr)
            return 2
        models.append((model, label))
    print("| FRF | source | V [m/s], w [rad/s] | abs(H_xdot) | phi [rad] | phi of H_x (to the displacement) [rad] "
          "| abs(h_xy) normalised (Eq 4.37) |")
    print("|---|---|---|---|---|---|---|")
    for name, (amps, phases) in THESIS.items():
        for (V, w), a, ph in zip(CASES, amps, phases, strict=True):
            h = normalised(a, ph, name, V, w)
            print(f"| {name} | thesis Table 5.3 | {V:g}, {w:g} | {a:.3g} {UNIT[name]} | {ph:+.3f} | | {abs(h):.3f} |")
        for model, label in models:
            for V, w in CASES:
                h = complex(np.asarray(getattr(model.frf(np.array([w * B / V]), V), name)).ravel()[0])
                H = rate_frf(h, name, V, w)
                print(f"| {name} | {label} | {V:g}, {w:g} | {abs(H):.3g} {UNIT[name]} | {-np.angle(H):+.3f} "
                      f"| {-np.angle(H * 1j * w):+.3f} | {abs(h):.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
