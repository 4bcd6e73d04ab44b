"""Conventions of derivative tables (issue 14, "Sign and normalisation conventions"): the general factor
rule of bridge.flutter.conventions, Theodorsen's flat plate written in every convention and read back to
one V_c, the closed forms typed independently of the conversion code, and how a convention is stated.

References: Theodorsen (1935), NACA Report 496: lift (up) and moment (nose-up) about mid-chord with h
down, L = pi rho b^2 (h'' + U a') + 2 pi rho U b C (h' + U a + b/2 a'),
M = -pi rho b^2 (U b/2 a' + b^2/8 a'') + pi rho U b^2 C (h' + U a + b/2 a');
Scanlan and Tomko (1971) for the half-chord form L = (1/2) rho U^2 (2b) [k H1 h'/U + k H2 b a'/U
+ k^2 H3 a + k^2 H4 h/b], M with (2 b^2) and A*, k = b w / U, h and L down; Simiu and Scanlan (1996) for
the B form (docs/reference_cases.md).  The section is the plate of docs/flutter.md (V_c = 114.48 m/s).
"""

import csv
import itertools
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import RHO, plate_section

from bridge.errors import InputError
from bridge.flutter.aerodynamics import DerivativeTable, QuasiSteady, Theodorsen, theodorsen_function
from bridge.flutter.conventions import (
    ARGUMENTS,
    DIRECTIONS,
    SCANLAN,
    SCANLAN_TOMKO,
    Convention,
    from_reduced_frequency,
)
from bridge.flutter.derivatives import DERIVATIVE_NAMES, FRF, FRF_NAMES, FlutterDerivatives, frf_from_derivatives
from bridge.flutter.determinant import solve_pair
from bridge.flutter.options import FlutterOptions

DOCS = Path(__file__).resolve().parents[2] / "docs" / "flutter.md"
VT = ("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4")
K_TABLE = np.linspace(0.18, 1.26, 200)          # U/(fB) = 5-35, as in test_tables.py
B_UP = Convention(vertical="up", lift="up", lateral="downwind", drag="downwind", pitch="nose_up",
                  reference_length="B")
# Theodorsen's own directions (h down, lift up) on the half chord, pitch nose-down: a mixed one
MIXED = Convention(vertical="down", lift="up", pitch="nose_down", moment="nose_down", reference_length="b")
CONVENTIONS = {  # name: (convention, argument column)
    "IABSE / Simiu-Scanlan, B, h and L down": (SCANLAN, "K"),
    "B, z and L up": (B_UP, "reduced_velocity"),
    "Scanlan & Tomko 1971, b, down": (SCANLAN_TOMKO, "k"),
    "mixed: h down, L up, nose-down, b": (MIXED, "reduced_velocity_omega")}


def write_table(path: Path, convention: Convention, argument: str, K: np.ndarray, columns: dict) -> Path:
    with path.open("w", newline="") as fh:
        fh.write(convention.header_line() + "\n")
        w = csv.writer(fh)
        names = [n for n in DERIVATIVE_NAMES if n in columns]
        w.writerow([argument] + [f"{n}*" for n in names])
        x = from_reduced_frequency(argument, K)
        for i in range(K.size):
            w.writerow([repr(float(x[i]))] + [repr(float(columns[n][i])) for n in names])
    return path


def critical_speed(aero) -> float:
    r = solve_pair(plate_section(0.4, 50.0, 0.7), aero, RHO, 200.0, min_speed_m_s=2.0)
    assert r.flutter
    return r.critical_speed_m_s


@pytest.fixture(scope="module")
def theodorsen_speed():
    return critical_speed(Theodorsen())


# ------------------------------------------------------------------------------ the rule itself
def test_the_rule_gives_back_the_scanlan_table_of_derivatives_py():
    # bridge.flutter.derivatives types its 9 signs by hand; the general rule (sign of the load x sign of
    # the motion x (l/B)^(n_F + d_x + 1)) must reproduce them for h, L down; p, D downwind; nose-up; B
    rng = np.random.default_rng(11)
    K = rng.uniform(0.1, 3.0, 7)
    d = {n: rng.normal(size=7) for n in DERIVATIVE_NAMES}
    ours, theirs = SCANLAN.frf(K, d), frf_from_derivatives(K, FlutterDerivatives(**d))
    for n in FRF_NAMES:
        np.testing.assert_allclose(getattr(ours, n), getattr(theirs, n), rtol=1e-15, atol=0)
    # and the half-chord powers: 2 for a force from a translation, 4 from pitch or for a moment from a
    # translation, 8 for the moment from pitch (the same derivative is that much larger on b)
    ratio = {n: SCANLAN.factor(n) / SCANLAN_TOMKO.factor(n) for n in DERIVATIVE_NAMES}
    assert {n for n, r in ratio.items() if r == 2} == {"H1", "H4", "H5", "H6", "P1", "P4", "P5", "P6"}
    assert {n for n, r in ratio.items() if r == 8} == {"A2", "A3"}
    assert {n for n, r in ratio.items() if r == 4} == {"H2", "H3", "P2", "P3", "A1", "A4", "A5", "A6"}
    # z and L up against down: exactly the terms with one vertical motion or one lift change sign
    flips = {n for n in DERIVATIVE_NAMES if SCANLAN.factor(n) / B_UP.factor(n) == -1}
    assert flips == {"H2", "H3", "H5", "H6", "A1", "A4", "P5", "P6"}


ALL = [Convention(**dict(zip(DIRECTIONS, d, strict=True)), reference_length=ref)
       for d in itertools.product(*(DIRECTIONS[k] for k in DIRECTIONS)) for ref in ("B", "b")]


def test_every_convention_round_trips_all_nine_frfs_through_a_csv(tmp_path):
    # registry test: 2^6 directions x 2 reference lengths, the four arguments in turn; all nine FRFs
    # non-zero (Theodorsen's four, the quasi-steady lateral five)
    K = np.array([0.2, 0.35, 0.6, 0.9, 1.3])
    qs = QuasiSteady(lift_coefficient=0.1, lift_slope_per_rad=5.0, drag_coefficient=0.3,
                     moment_coefficient=0.02, moment_slope_per_rad=1.1, drag_slope_per_rad=-0.4)
    h = FRF(*Theodorsen().frf(K, 1.0)[:4], *qs.frf(K, 1.0)[4:])
    assert len(ALL) == 128 and all(np.all(np.abs(getattr(h, n)) > 0) for n in FRF_NAMES)
    for i, c in enumerate(ALL):
        argument = list(ARGUMENTS)[i % 4]
        table = DerivativeTable.from_csv(write_table(tmp_path / f"c{i}.csv", c, argument, K, c.derivatives(K, h)))
        assert table.provides == FRF_NAMES
        back = table.frf(K, 1.0)
        for n in FRF_NAMES:
            np.testing.assert_allclose(getattr(back, n), getattr(h, n), rtol=1e-12, err_msg=f"{c} {n}")


# ------------------------------------------------------------------------------ Theodorsen in every convention
@pytest.mark.parametrize("name", list(CONVENTIONS))
def test_theodorsen_in_every_convention_gives_one_critical_speed(tmp_path, name, theodorsen_speed):
    convention, argument = CONVENTIONS[name]
    d = convention.derivatives(K_TABLE, Theodorsen().frf(K_TABLE, 1.0), VT)
    table = DerivativeTable.from_csv(write_table(tmp_path / "t.csv", convention, argument, K_TABLE, d))
    # the conversions are exact (signs, powers of 2); only the argument column's round-off (2 pi / x)
    # moves the spline's knots, by ~1e-16, and the dense table errs by ~1e-10 (test_tables.py)
    assert abs(critical_speed(table) / theodorsen_speed - 1) < 1e-6
    # read in the wrong convention the same numbers give another V_c (or none): the convention matters
    wrong = Convention(**{**convention.__dict__, "lift": "up" if convention.lift == "down" else "down"})
    lines = (tmp_path / "t.csv").read_text().splitlines()
    (tmp_path / "wrong.csv").write_text("\n".join([wrong.header_line()] + lines[1:]) + "\n")
    r = solve_pair(plate_section(0.4, 50.0, 0.7), DerivativeTable.from_csv(tmp_path / "wrong.csv"), RHO, 200.0,
                   min_speed_m_s=2.0)
    assert not r.flutter or abs(r.critical_speed_m_s / theodorsen_speed - 1) > 0.05


def closed_forms(K: np.ndarray, form: str) -> dict:
    """Theodorsen's derivatives typed from the lift and moment of the module docstring, NOT through the
    conversion code; C = F + i G at k = K/2."""
    C = theodorsen_function(K / 2)
    F, G, pi = C.real, C.imag, np.pi
    if form == "B down":            # docs/reference_cases.md (Simiu and Scanlan)
        return {"H1": -2 * pi * F / K, "H2": -(pi / (2 * K)) * (1 + F + 4 * G / K),
                "H3": -(pi / K**2) * (2 * F - K * G / 2), "H4": (pi / 2) * (1 + 4 * G / K),
                "A1": pi * F / (2 * K), "A2": (pi / (8 * K)) * (F - 1 + 4 * G / K),
                "A3": (pi / (2 * K**2)) * (K**2 / 32 + F - K * G / 4), "A4": -pi * G / (2 * K)}
    if form == "B up":              # z and L up: H2, H3 (lift) and A1, A4 (vertical motion) change sign
        d = closed_forms(K, "B down")
        return {n: (-v if n in ("H2", "H3", "A1", "A4") else v) for n, v in d.items()}
    if form == "b down":            # Scanlan and Tomko's normalisation; by hand: divide L (down) by
        k = K / 2                   # rho U^2 b and M by rho U^2 b^2, h/b and alpha terms of k^2 (...)
        return {"H1": -2 * pi * F / k, "H2": -(pi / k) * (1 + F + 2 * G / k), "H3": -(pi / k**2) * (2 * F - k * G),
                "H4": pi * (1 + 2 * G / k), "A1": pi * F / k, "A2": (pi / (2 * k)) * (F - 1 + 2 * G / k),
                "A3": (pi / k**2) * (k**2 / 8 + F - k * G / 2), "A4": -pi * G / k}
    raise ValueError(form)


@pytest.mark.parametrize("form, convention, argument", [("B down", SCANLAN, "reduced_velocity"),
                                                        ("B up", B_UP, "K"), ("b down", SCANLAN_TOMKO, "k")])
def test_independently_typed_closed_forms_give_theodorsens_critical_speed(tmp_path, form, convention, argument,
                                                                        theodorsen_speed):
    d = closed_forms(K_TABLE, form)
    # the conversion code agrees with the hand derivation term by term ...
    ours = convention.derivatives(K_TABLE, Theodorsen().frf(K_TABLE, 1.0), VT)
    for n in VT:
        np.testing.assert_allclose(ours[n], d[n], rtol=1e-12, err_msg=n)
    # ... and the typed table, read back, gives Theodorsen's V_c
    table = DerivativeTable.from_csv(write_table(tmp_path / "typed.csv", convention, argument, K_TABLE, d))
    assert abs(critical_speed(table) / theodorsen_speed - 1) < 1e-6


def test_the_conversion_table_in_the_docs_is_what_the_code_does():
    # docs/flutter.md, "Derivative tables: conventions": Theodorsen at U/(fB) = 4, 8, 12 in two forms
    text = DOCS.read_text().split("## Derivative tables: conventions")[1].split("\n## ")[0]
    forms = {"B down": SCANLAN, "B up": B_UP, "b down": SCANLAN_TOMKO}
    rows = re.findall(r"^\| (4|8|12) \| (B down|B up|b down) \|(.*)\|$", text, flags=re.M)
    assert len(rows) == 6
    for ur, form, cells in rows:
        K = 2 * np.pi / float(ur)
        d = forms[form].derivatives(K, Theodorsen().frf(K, 1.0), VT)
        printed = [float(c) for c in cells.split("|")]
        for n, p in zip(VT, printed, strict=True):
            assert abs(float(d[n]) - p) <= 5e-4 * abs(p) + 1e-12, (ur, form, n, float(d[n]), p)


# ------------------------------------------------------------------------------ stating a convention
def test_a_table_without_a_convention_is_refused_with_how_to_state_it(tmp_path):
    path = write_table(tmp_path / "t.csv", SCANLAN, "K", K_TABLE[:5], closed_forms(K_TABLE[:5], "B down"))
    lines = path.read_text().splitlines()
    bare = tmp_path / "bare.csv"
    bare.write_text("\n".join(lines[1:]) + "\n")
    with pytest.raises(InputError, match=r"must state its convention.*# convention: vertical=.*derivatives_convention"):
        DerivativeTable.from_csv(bare)
    # a partial statement names the keys it lacks
    part = tmp_path / "part.csv"
    part.write_text("# convention: vertical=down lift=down\n" + "\n".join(lines[1:]) + "\n")
    with pytest.raises(InputError, match="pitch, reference_length"):
        DerivativeTable.from_csv(part)
    # lateral columns need lateral and drag
    lat = tmp_path / "lat.csv"
    lat.write_text("# convention: vertical=down lift=down pitch=nose_up reference_length=B\n"
                   + lines[1] + ",P1,P4\n" + "\n".join(r + ",0.1,0.2" for r in lines[2:]) + "\n")
    with pytest.raises(InputError, match="lateral, drag"):
        DerivativeTable.from_csv(lat)
    # spaces around '=' and commas are accepted
    spaced = tmp_path / "spaced.csv"
    spaced.write_text("# convention: vertical = down, lift = down, pitch = nose_up, reference_length = B\n"
                      + "\n".join(lines[1:]) + "\n")
    assert DerivativeTable.from_csv(spaced).convention == Convention(vertical="down", lift="down", pitch="nose_up",
                                                                     reference_length="B")
    # bad words and values name themselves
    for line, match in (("# convention: vertical=sideways", "vertical"), ("# convention: up", "key=value"),
                        ("# convention: heave=down", "heave"),
                        ("# convention: vertical=down vertical=up", "stated twice")):
        bad = tmp_path / "bad.csv"
        bad.write_text(line + "\n" + "\n".join(lines[1:]) + "\n")
        with pytest.raises(InputError, match=match):
            DerivativeTable.from_csv(bad)


def test_scenario_keys_and_the_file_merge_and_a_conflict_is_an_error(tmp_path, theodorsen_speed):
    d = closed_forms(K_TABLE, "b down")
    path = write_table(tmp_path / "st.csv", SCANLAN_TOMKO, "k", K_TABLE, d)
    lines = path.read_text().splitlines()
    bare = tmp_path / "bare.csv"
    bare.write_text("\n".join(lines[1:]) + "\n")
    half = tmp_path / "half.csv"
    half.write_text("# convention: vertical=down lift=down\n" + "\n".join(lines[1:]) + "\n")

    def opts(path, **convention):
        return FlutterOptions.from_mapping({"aerodynamics": "derivatives", "derivatives_path": path.name,
                                            "derivatives_convention": convention}, "flutter")

    stated = dict(vertical="down", lift="down", pitch="nose_up", reference_length="b")
    # all in the scenario, or split between the file and the scenario, or stated by both alike
    for o in (opts(bare, **stated), opts(half, pitch="nose_up", reference_length="b"), opts(path, **stated)):
        assert abs(critical_speed(o.aerodynamic_model(tmp_path)) / theodorsen_speed - 1) < 1e-6
    # stated differently: an error naming the key and both values, not a silent choice
    with pytest.raises(InputError, match=r"reference_length.*says 'b'.*says 'B'"):
        opts(path, **{**stated, "reference_length": "B"}).aerodynamic_model(tmp_path)
    # the scenario table is validated like the other keys
    for bad, key in (({"heave": "down"}, "flutter.derivatives_convention.heave"),
                     ({"lift": "upward"}, "flutter.derivatives_convention.lift")):
        with pytest.raises(InputError) as err:
            FlutterOptions.from_mapping({"derivatives_convention": bad}, "flutter")
        assert err.value.key == key


def test_quasi_steady_lateral_derivatives_in_the_b_form_and_upwind():
    # Quasi-steady drag of a section swaying with pdot: D = (1/2) rho U^2 B (-2 C_D pdot/U), so in the B
    # form P1* = -2 C_D / K (Simiu and Scanlan 1996, quasi-steady P1*), typed here; on the half chord the
    # same load reads (1/2) rho U^2 (2b) [k P1 pdot/U]: P1 = -2 C_D / k = 2 x that.  Upwind sway and drag
    # change both signs: no change.
    K = np.array([0.3, 0.8])
    qs = QuasiSteady(lift_coefficient=0.0, lift_slope_per_rad=5.0, drag_coefficient=0.3, moment_coefficient=0.0,
                     moment_slope_per_rad=1.0)
    h = qs.frf(K, 1.0)
    np.testing.assert_allclose(SCANLAN.derivatives(K, h, ["P1"])["P1"], -2 * 0.3 / K, rtol=1e-14)
    np.testing.assert_allclose(SCANLAN_TOMKO.derivatives(K, h, ["P1"])["P1"], -2 * 0.3 / (K / 2), rtol=1e-14)
    upwind = Convention(**{**SCANLAN.__dict__, "lateral": "upwind", "drag": "upwind"})
    np.testing.assert_allclose(upwind.derivatives(K, h, ["P1"])["P1"], -2 * 0.3 / K, rtol=1e-14)
