"""A multi-frequency run (a sum of sines) identifies the same FRFs as single-frequency runs (issue: within
3 %), and the options that ask for one are checked."""


import numpy as np
import pytest

from bridge.aero.forced_motion import THESIS_HEAVE_RATE, THESIS_PITCH_RATE, ForcedCase, run_case, whole_periods
from bridge.aero.frequency_response import forced_motion_response
from bridge.aero.options import AeroOptions
from bridge.aero.presets import QUALITY, section_polygons
from bridge.cfd.sections import FlatPlate
from bridge.errors import InputError

# 4 % plate, 24 cells per chord, dy = dx / 4 (4 cells thick), 4 chords of wake: coarse, but a resolved body
COARSE = QUALITY["tiny"].with_(name="coarse", cells_per_chord=24, dy_over_dx=0.25, upstream=1.0,
                             downstream=4.0, half_height=1.5, core_half_height=0.1, reynolds=1000.0, periods=4,
                             discard_periods=2, settle_time=16.0)


def _frfs(case, q):
    rec = run_case(section_polygons(FlatPlate(1.0, 0.04))[0], case, q)
    sel = whole_periods(rec, case, q)
    out = forced_motion_response(rec.t[sel], rec.motion[sel], list(case.reduced_frequencies), dof=case.dof,
                                 speed_m_s=1.0, deck_width_m=1.0, air_density_kg_m3=1.0, lift=rec.lift[sel],
                                 moment=rec.moment[sel], fundamental=case.fundamental)
    return [{n: complex(getattr(r.frf, n)) for n in r.provides} for r in out]


@pytest.mark.slow  # ~4 min each (six CFD runs): runs in CI with -m slow
@pytest.mark.parametrize("grid, tolerance", [("single", 0.20), ("overset", 0.03)])
def test_a_multi_frequency_run_agrees_with_single_frequency_runs(grid, tolerance):
    """U/(fB) = 8 and 4 (K = 0.785, 1.571) in one heave and one pitch run against one run each.

    Overset pair (the plate in a body grid moving with it): the issue's target, 3 %; measured 0.0-0.9 %.
    Single grid: a check of the machinery only (frequencies, phases, windows, fit), which would put the
    FRFs wrong by their own size if broken: 20 %; measured 1.5-7.7 % (h_mu at K = 1.571: 17 %, its small
    real part), because the moving immersed boundary's error depends on the path the body takes through
    the cells (docs/aero.md, multi-frequency)."""
    q = COARSE.with_(overset=grid == "overset")
    Ks = (2 * np.pi / 8, 2 * np.pi / 4)
    for dof, rate in (("heave", THESIS_HEAVE_RATE), ("pitch", THESIS_PITCH_RATE)):
        multi = _frfs(ForcedCase.multi_frequency(dof, Ks, rate), q)
        for K, got in zip(Ks, multi, strict=True):
            (single,) = _frfs(ForcedCase.thesis(dof, K), q)
            for name, h in single.items():
                assert abs(got[name] - h) < tolerance * abs(h), (dof, K, name, got[name], h)


def test_multi_frequency_case_and_options():
    case = ForcedCase.multi_frequency("pitch", (0.5, 1.0, 1.5), 0.03)
    assert case.fundamental == 0.5
    # each sine carries a single run's rate; Schroeder's phases keep the sum well below the three peaking together
    t = np.linspace(0.0, 4 * np.pi, 4001)
    assert max(abs(case.rate(x)) for x in t) < 0.9 * 3 * 0.03
    assert [a * k for a, k in zip(case.amplitudes, case.reduced_frequencies, strict=True)] == pytest.approx([0.03] * 3)
    opts = AeroOptions(excitation="multi", reduced_velocities=(16.0, 8.0, 5.333, 4.0))
    assert opts.reduced_velocities == pytest.approx((4.0, 16 / 3, 8.0, 16.0))
    with pytest.raises(InputError, match="whole numbers"):
        AeroOptions(excitation="multi", reduced_velocities=(16.0, 6.0))
    with pytest.raises(InputError, match="single, multi"):
        AeroOptions(excitation="several")
