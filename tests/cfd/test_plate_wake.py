"""tools/plate_wake.py: its thin-aerofoil model is Theodorsen's problem when the wake travels at U, and its
wake analysis recovers the speed and growth of a travelling wave."""

import numpy as np
import pytest
from cfd_helpers import load_tool

from bridge.flutter.aerodynamics import Theodorsen
from bridge.flutter.derivatives import derivatives_from_frf


@pytest.mark.parametrize("reduced_velocity", [4.0, 8.0])
def test_thin_plate_model_converges_to_theodorsen(reduced_velocity):
    """Theodorsen (1935, NACA Report 496) closed forms as in VALIDATION: the lumped-vortex plate with a
    Kelvin wake at U converges at order 1/2 (leading-edge singularity); extrapolated, it lands on them."""
    pw = load_tool("plate_wake")
    K = 2 * np.pi / reduced_velocity
    ref = derivatives_from_frf(np.array([K]), Theodorsen().frf(np.array([K]), 1.0))
    runs = [pw.thin_plate_heave(K, panels=n) for n in (100, 200, 400)]
    for name, tol in (("H1", 3e-3), ("A1", 3e-3), ("H4", 2e-2), ("A4", 2e-2)):
        exact = float(np.asarray(getattr(ref, name))[0])
        a, b, c = (r[name] for r in runs)
        errors = [abs(v - exact) for v in (a, b, c)]
        assert errors[0] > errors[1] > errors[2], (name, errors)
        order = np.log2(abs((a - b) / (b - c)))
        assert 0.3 < order < 0.8, (name, order)
        assert abs(c + (c - b) / (2**order - 1) - exact) < tol * abs(exact), name


def test_wake_harmonic_recovers_a_travelling_wave():
    pw = load_tool("plate_wake")
    K, c0 = 0.8, 0.9
    t = np.linspace(0.0, 4 * 2 * np.pi / K, 129)[:-1]
    x = np.linspace(0.7, 7.5, 80)
    amplitude = 0.02 * (1 + 0.05 * x)
    wave = amplitude[None, :] * np.cos(K * (t[:, None] - x[None, :] / c0) + 0.3) + 0.01
    first, speed = pw.wake_harmonic(t, x, wave, K)
    np.testing.assert_allclose(np.abs(first), amplitude, rtol=1e-10)
    np.testing.assert_allclose(speed, c0, rtol=1e-3)   # the phase slope by central differences


@pytest.mark.slow   # 4 s: the tool end to end; its model is tested in the default run
def test_plate_wake_tool_runs_tiny(tmp_path, capsys):
    """End to end on the tiny preset, where the 2 % plate is under a cell thick: it says so and still writes
    its JSON and plot."""
    import json

    rows = load_tool("plate_wake").main(["--quality", "tiny", "--periods", "5", "--reduced-velocities", "4",
                                         "--panels", "60", "--out", str(tmp_path)])
    assert "WARNING: the 2 % plate is 0.5 cells thick" in capsys.readouterr().out
    saved = json.loads((tmp_path / "plate_wake.json").read_text())
    assert saved[0]["reduced_velocity"] == 4.0 and set(saved[0]["H1"]) >= {"cfd", "model_speed", "model_growth"}
    assert (tmp_path / "plate_wake.png").stat().st_size > 0 and rows[0]["wake_speed_mean"] > 0
    assert len(saved[0]["loading"]["ratio_re"]) == len(saved[0]["loading"]["x"])   # the overset pair's p jump
