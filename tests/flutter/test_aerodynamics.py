"""Aerodynamic models and the h_xy <-> Scanlan conversions.

Sources: Theodorsen (1935), NACA Report 496 (C(k) and the plate forces); Scanlan and Tomko (1971)
(flutter derivatives); the check values are collected in docs/reference_cases.md.
"""

import numpy as np
import pytest

from bridge.errors import InputError
from bridge.flutter.aerodynamics import FRFTable, QuasiSteady, Theodorsen, theodorsen_function
from bridge.flutter.derivatives import FRF, FlutterDerivatives, derivatives_from_frf, frf_from_derivatives


@pytest.mark.parametrize("k, expected", [(0.1, 0.8319 - 0.1723j), (0.2, 0.7276 - 0.1886j),
                                         (0.5, 0.5979 - 0.1507j), (1.0, 0.5394 - 0.1003j)])
def test_theodorsen_function_matches_published_values(k, expected):
    C = theodorsen_function(k)
    assert abs(C.real - expected.real) <= 5e-5 and abs(C.imag - expected.imag) <= 5e-5


def _closed_forms(K):
    """Scanlan-form Theodorsen derivatives as printed in docs/reference_cases.md (h, L positive down)."""
    C = theodorsen_function(K / 2)
    F, G = C.real, C.imag
    pi = np.pi
    return FlutterDerivatives(
        H1=-2 * pi * F / K, H2=-(pi / (2 * K)) * (1 + F + 4 * G / K), H3=-(pi / K**2) * (2 * F - K * G / 2),
        H4=(pi / 2) * (1 + 4 * G / K), A1=pi * F / (2 * K), A2=(pi / (8 * K)) * (F - 1 + 4 * G / K),
        A3=(pi / (2 * K**2)) * (K**2 / 32 + F - K * G / 4), A4=-pi * G / (2 * K))


def test_direct_theodorsen_frf_equals_closed_form_derivatives_after_conversion():
    # The direct h_xy (derived from Theodorsen's lift and moment with u = -h) and the printed H*/A*
    # closed forms are independent derivations; the conversion must make them agree to round-off.
    K = np.linspace(0.05, 4.0, 57)
    d = derivatives_from_frf(K, Theodorsen().frf(K, 10.0))
    ref = _closed_forms(K)
    for name in FlutterDerivatives._fields:   # the ten lateral ones are zero on both sides (no drag)
        np.testing.assert_allclose(getattr(d, name), getattr(ref, name), rtol=1e-12, atol=1e-12, err_msg=name)


CHECK_TABLE = {  # U/(fB): H1* H2* H3* H4* A1* A2* A3* A4*  (docs/reference_cases.md)
    4: (-2.222, -1.255, -1.533, 1.099, 0.556, -0.186, 0.432, 0.118),
    8: (-5.019, -1.563, -6.723, 0.242, 1.255, -0.609, 1.730, 0.332),
    12: (-8.226, -0.839, -16.26, -0.637, 2.056, -1.290, 4.115, 0.552),
}


@pytest.mark.parametrize("reduced_velocity", sorted(CHECK_TABLE))
def test_theodorsen_derivatives_reproduce_check_table(reduced_velocity):
    # To the printed digits, allowing one unit in the last place: at U/(fB) = 12 the table prints
    # H1* = -8.226 and A3* = 4.115 where the closed forms give -8.2255 and 4.1145 (rounding of the source).
    K = 2 * np.pi / reduced_velocity
    d = derivatives_from_frf(np.array([K]), Theodorsen().frf(K, 1.0))
    for name, printed in zip(FlutterDerivatives._fields[:8], CHECK_TABLE[reduced_velocity], strict=True):
        decimals = len(f"{printed}".split(".")[1])
        assert abs(getattr(d, name)[0] - printed) <= 1.0 * 10.0**-decimals, (name, getattr(d, name)[0], printed)


def test_static_limit_lift_and_moment_slopes():
    h = Theodorsen().frf(1e-9, 1.0)
    assert abs(h.h_ptheta - 2 * np.pi) < 1e-6 and abs(h.h_mtheta - np.pi / 2) < 1e-6


def test_quasi_steady_is_theodorsen_low_frequency_limit():
    # with C_L' = 2 pi, C_M' = pi/2, C_D = 0 the quasi-steady FRFs are Theodorsen's first-order terms
    qs = QuasiSteady(lift_coefficient=0.0, lift_slope_per_rad=2 * np.pi, drag_coefficient=0.0,
                     moment_coefficient=0.0, moment_slope_per_rad=np.pi / 2)
    Om = np.array([1e-4, 1e-3])
    a, b = qs.frf(Om, 1.0), Theodorsen().frf(Om, 1.0)
    for name in FRF._fields:
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=0.02, atol=1e-7, err_msg=name)


def test_conversion_round_trip_is_identity():
    rng = np.random.default_rng(1)
    K = rng.uniform(0.1, 3.0, 20)
    h = FRF(*(rng.normal(size=20) + 1j * rng.normal(size=20) for _ in range(4)))
    back = frf_from_derivatives(K, derivatives_from_frf(K, h))
    for name in FRF._fields:
        np.testing.assert_allclose(getattr(back, name), getattr(h, name), rtol=1e-13, atol=1e-14)
    d = FlutterDerivatives(*(rng.normal(size=20) for _ in range(8)))
    again = derivatives_from_frf(K, frf_from_derivatives(K, d))
    for name in FlutterDerivatives._fields:
        np.testing.assert_allclose(getattr(again, name), getattr(d, name), rtol=1e-13, atol=1e-13)


def test_sign_convention_flips_exactly_four_derivatives():
    # docs/reference_cases.md: with h and L positive UP, H2*, H3*, A1*, A4* change sign.  Build h_xy from a set of
    # derivatives, flip the heave axis (u -> -u, p -> -p) by hand, and read the derivatives again.
    K = np.array([0.7])
    d = FlutterDerivatives(*(np.array([v]) for v in (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0)))
    h = frf_from_derivatives(K, d)
    up = FRF(h_pu=h.h_pu, h_ptheta=-h.h_ptheta, h_mu=-h.h_mu, h_mtheta=h.h_mtheta)
    flipped = derivatives_from_frf(K, up)
    signs = {n: np.sign(getattr(flipped, n)[0] / getattr(d, n)[0]) for n in FlutterDerivatives._fields[:8]}
    assert {n for n, s in signs.items() if s < 0} == {"H2", "H3", "A1", "A4"}


def _table(omega, speed):
    Om, V = np.meshgrid(omega, speed, indexing="ij")
    return FRFTable(omega, speed, Theodorsen().frf(Om, V))


def test_frf_table_interpolates_inside_and_refuses_outside():
    table = _table(np.linspace(0.1, 3.0, 300), np.array([5.0, 100.0]))
    Om = np.array([0.37, 1.234, 2.9])
    got, ref = table.frf(Om, 50.0), Theodorsen().frf(Om, 50.0)
    for name in FRF._fields:
        np.testing.assert_allclose(getattr(got, name), getattr(ref, name), rtol=2e-4, atol=2e-4)
    with pytest.raises(InputError, match="reduced_frequency"):
        table.frf(3.5, 50.0)
    with pytest.raises(InputError, match="reduced_frequency"):
        table.frf(0.05, 50.0)
    with pytest.raises(InputError, match="speed_m_s"):
        table.frf(1.0, 120.0)


def test_frf_table_round_trip_through_hdf5(tmp_path):
    import h5py

    omega, speed = np.linspace(0.1, 3.0, 30), np.array([10.0, 60.0])
    Om, V = np.meshgrid(omega, speed, indexing="ij")
    h = Theodorsen().frf(Om, V)
    path = tmp_path / "aero.h5"
    with h5py.File(path, "w") as f:
        g = f.create_group("frf")
        g["reduced_frequency"], g["speed_m_s"] = omega, speed
        for name in FRF._fields:
            g[name] = getattr(h, name)
    table = FRFTable.from_hdf5(path, "frf")
    np.testing.assert_allclose(table.frf(omega[3], 10.0).h_mtheta, h.h_mtheta[3, 0], rtol=1e-14)
    with pytest.raises(InputError):
        FRFTable.from_hdf5(path, "missing_group")
