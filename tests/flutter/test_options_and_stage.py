"""Scenario tables of the flutter package ([flutter], [section], [modal]) and the pipeline stage."""

from types import SimpleNamespace

import h5py
import numpy as np
import pytest
from matplotlib.figure import Figure

from bridge.errors import InputError
from bridge.flutter.aerodynamics import QuasiSteady, Theodorsen
from bridge.flutter.modal import ModalModel
from bridge.flutter.options import FlutterOptions
from bridge.flutter.section import SectionModel
from bridge.flutter.stage import run
from bridge.stages import RunOptions, StageOutput

SECTION = dict(mass_per_length_kg_m=20_000.0, inertia_per_length_kg_m2_m=20_000.0 * 7.0**2,
               heave_frequency_hz=0.1, pitch_frequency_hz=0.25, deck_width_m=30.0)


def test_flutter_options_defaults_and_validation():
    o = FlutterOptions.from_mapping({}, "flutter")
    assert o.aerodynamics == "theodorsen" and o.pairs == "all" and o.max_speed_m_s == 150.0
    assert isinstance(o.aerodynamic_model(), Theodorsen)
    for bad, key in [({"aerodynamics": "vortex_lattice"}, "flutter.aerodynamics"),
                     ({"max_speed_m_s": -5}, "flutter.max_speed_m_s"),
                     ({"pairs": "some"}, "flutter.pairs"), ({"speed_steps": 3}, "flutter.speed_steps"),
                     ({"colour": "red"}, "flutter.colour"), ({"aerodynamics": "table"}, "flutter.table_path"),
                     ({"aerodynamics": "quasi_steady", "quasi_steady": {"lift_coefficient": 0.1}},
                      "flutter.quasi_steady.lift_slope_per_rad"),
                     ({"air_density_kg_m3": "heavy"}, "flutter.air_density_kg_m3")]:
        with pytest.raises(InputError) as err:
            FlutterOptions.from_mapping(bad, "flutter")
        assert err.value.key == key, (bad, err.value)
    qs = FlutterOptions.from_mapping({"aerodynamics": "quasi_steady", "quasi_steady": {
        "lift_coefficient": 0.1, "lift_slope_per_rad": 5.5, "drag_coefficient": 0.08, "moment_coefficient": 0.02,
        "moment_slope_per_rad": 1.3}}, "flutter")
    assert isinstance(qs.aerodynamic_model(), QuasiSteady)


def test_section_and_modal_tables_name_the_bad_key():
    assert SectionModel.from_mapping(SECTION, "section").modal_model().n_modes == 2
    for bad, key in [({**SECTION, "heave_damping_ratio": -0.01}, "section.heave_damping_ratio"),
                     ({k: v for k, v in SECTION.items() if k != "deck_width_m"}, "section.deck_width_m"),
                     ({**SECTION, "pitch_frequency_hz": 0}, "section.pitch_frequency_hz"),
                     ({**SECTION, "spring": 1}, "section.spring")]:
        with pytest.raises(InputError) as err:
            SectionModel.from_mapping(bad, "section")
        assert err.value.key == key
    modal = dict(bending_frequency_hz=0.1, torsion_frequency_hz=0.28, a_jj=0.308, a_kk=0.239, a_jk=0.038,
                 mass_per_length_kg_m=23_000.0, inertia_per_length_kg_m2_m=2.5e6, deck_width_m=31.0,
                 deck_length_m=2694.0)
    m = ModalModel.from_mapping(modal, "modal")
    # Eq 4.33: m_j = mu L a_jj, m_k = J L a_kk
    np.testing.assert_allclose(m.modal_masses, [23_000.0 * 2694.0 * 0.308, 2.5e6 * 2694.0 * 0.239])
    with pytest.raises(InputError) as err:
        ModalModel.from_mapping({**modal, "torsion_damping_ratio": -0.1}, "bridge.modal")
    assert err.value.key == "bridge.modal.torsion_damping_ratio"   # the key the user typed


def _scenario(**kw):
    base = dict(kind="section", section=SectionModel(**SECTION), flutter=FlutterOptions(max_speed_m_s=120.0),
                modal=None, air=SimpleNamespace(density_kg_m3=1.225), source_path=None)
    base.update(kw)
    return SimpleNamespace(**base)


def test_stage_on_a_section_writes_summary_hdf5_report_and_figures(tmp_path):
    out = run(_scenario(), {}, RunOptions(quick=True))
    assert isinstance(out, StageOutput)
    s = out.summary
    assert s["flutter.flutter"] is True and s["flutter.mode_pair"] == "heave+pitch"
    assert abs(s["flutter.multimode_critical_speed_m_s"] / s["flutter.critical_speed_m_s"] - 1) < 0.005
    assert np.isclose(s["flutter.reduced_frequency"],
                      2 * np.pi * s["flutter.frequency_hz"] * 30.0 / s["flutter.critical_speed_m_s"])
    with h5py.File(tmp_path / "r.h5", "w") as f:
        out.write_h5(f.create_group("flutter"))
    with h5py.File(tmp_path / "r.h5", "r") as f:
        g = f["flutter"]
        assert g["pairs/critical_speed_m_s"][0] == pytest.approx(s["flutter.critical_speed_m_s"])
        assert g["multimode/damping_ratio"].shape == (g["multimode/speed_m_s"].shape[0], 2)
        assert g["determinant_map/f1"].shape == g["determinant_map/reduced_frequency"].shape
    assert out.report.startswith("## Flutter")
    assert set(out.figures) == {"flutter_determinant.png", "flutter_damping.png"}
    assert all(isinstance(f, Figure) for f in out.figures.values())


def test_stage_takes_fem_modes_first_and_needs_some_modes():
    fem_modes = ModalModel.from_two_modes(bending_frequency_hz=0.12, torsion_frequency_hz=0.3, a_jj=0.345,
                                          a_kk=0.161, a_jk=0.2, mass_per_length_kg_m=23_000.0,
                                          inertia_per_length_kg_m2_m=2.5e6, deck_width_m=31.0,
                                          deck_length_m=2694.0)
    fem = SimpleNamespace(data=SimpleNamespace(modal_model=fem_modes))
    out = run(_scenario(kind="suspension_bridge", section=None, flutter=FlutterOptions(max_speed_m_s=150.0)),
              {"fem": fem}, RunOptions(quick=True))
    assert out.summary["flutter.mode_pair"] == "S-V1+S-T1"
    with pytest.raises(InputError, match="needs modes"):
        run(_scenario(kind="suspension_bridge", section=None), {}, RunOptions(quick=True))


def test_stage_reports_no_flutter_below_the_maximum_speed():
    out = run(_scenario(flutter=FlutterOptions(max_speed_m_s=20.0, multimode=False)), {}, RunOptions(quick=True))
    assert out.summary["flutter.flutter"] is False and out.summary["flutter.critical_speed_m_s"] is None
    assert "No flutter" in out.report and "20 m/s" in out.report


def test_stage_reads_an_frf_table_relative_to_the_scenario_file(tmp_path):
    from bridge.flutter.derivatives import FRF

    omega, speed = np.linspace(0.05, 40.0, 800), np.array([5.0, 200.0])
    Om, V = np.meshgrid(omega, speed, indexing="ij")
    h = Theodorsen().frf(Om, V)
    with h5py.File(tmp_path / "aero.h5", "w") as f:
        g = f.create_group("frf")
        g["reduced_frequency"], g["speed_m_s"] = omega, speed
        for name in FRF._fields:
            g[name] = getattr(h, name)
    table = FlutterOptions.from_mapping({"aerodynamics": "table", "table_path": "aero.h5", "table_group": "frf",
                                         "max_speed_m_s": 120.0, "min_speed_m_s": 10.0}, "flutter")
    direct = run(_scenario(flutter=FlutterOptions(max_speed_m_s=120.0, min_speed_m_s=10.0)), {},
                 RunOptions(quick=True))
    tabled = run(_scenario(flutter=table, source_path=str(tmp_path / "plate.toml")), {}, RunOptions(quick=True))
    v_direct, v_table = direct.summary["flutter.critical_speed_m_s"], tabled.summary["flutter.critical_speed_m_s"]
    assert abs(v_table / v_direct - 1) < 0.005
    assert abs(tabled.summary["flutter.multimode_critical_speed_m_s"] / v_direct - 1) < 0.005


def test_derivative_csv_header_and_cells_are_checked(tmp_path):
    from bridge.flutter.aerodynamics import DerivativeTable

    good = tmp_path / "d.csv"
    convention = "# convention: vertical=down lift=down pitch=nose_up reference_length=B\n"
    good.write_text(convention + "K,H1,H2,H3,H4,A1,A2,A3,A4\n0.5,1,2,3,4,5,6,7,8\n1.0,1,2,3,4,5,6,7,8\n")
    assert DerivativeTable.from_csv(good).omega_range == (0.5, 1.0)
    for text in ("K,H1,H2\n0.5,1,2\n1.0,1,2\n", "K,H1,H2,H3,H4,A1,A2,A3,A4\n0.5,1,2,3,4,5,6,7,x\n1,1,2,3,4,5,6,7,8\n"):
        bad = tmp_path / "bad.csv"
        bad.write_text(convention + text)
        with pytest.raises(InputError):
            DerivativeTable.from_csv(bad)
    with pytest.raises(InputError, match="derivatives_path"):
        DerivativeTable.from_csv(tmp_path / "missing.csv")
