"""The buffeting stage on a small bridge of four sine modes (no FEM: a ModeSet written here, the flutter stage's
result from the two-mode determinant of the same modes): what it hands to the result files, its speeds and its
input errors.  The real chain (cable, FEM, flutter, buffeting) on the shipped bridges: the slow test at the end."""

import json
from dataclasses import replace
from types import SimpleNamespace

import h5py
import numpy as np
import pytest

from bridge import datastore
from bridge.buffeting.loads import DeckModes
from bridge.buffeting.options import BuffetingOptions
from bridge.buffeting.stage import SPEED_FRACTION, run
from bridge.config import Scenario, load_scenario, with_aerodynamics
from bridge.errors import InputError
from bridge.flutter.aerodynamics import QuasiSteady, Theodorsen
from bridge.flutter.determinant import solve_pair
from bridge.flutter.modal import ModalModel
from bridge.flutter.options import FlutterOptions
from bridge.flutter.stage import FlutterStageResult
from bridge.pipeline import run_stages
from bridge.stages import RunOptions
from bridge.structure.modes import ModeSet

L, B, MU, J, RHO = 1200.0, 25.0, 15000.0, 1.2e6, 1.25
MODES = (("S-V1", "vertical", 1, 0.12), ("SS-V1", "vertical", 2, 0.17), ("S-T1", "torsional", 1, 0.32),
         ("S-L1", "lateral", 1, 0.07))
COEFFICIENTS = {"lift_coefficient": -0.1, "lift_slope_per_rad": 5.0, "drag_coefficient": 0.09,
                "moment_coefficient": 0.02, "moment_slope_per_rad": 1.1}


def small_bridge():
    """The fem stage's and the flutter stage's results for a simply supported deck of four sine modes."""
    z = np.linspace(0.0, L, 241)
    fields = {k: np.zeros((len(MODES), z.size)) for k in ("vertical", "torsional", "lateral")}
    for i, (_, kind, n, _) in enumerate(MODES):
        fields[kind][i] = np.sin(n * np.pi * z / L)
    labels = tuple(m[0] for m in MODES)
    deck = DeckModes(labels, z, fields["vertical"], fields["torsional"], fields["lateral"], L / 2)
    integrals = deck.integrals(L)
    integrals["ur"], integrals["rt"] = -integrals["ur"], -integrals["rt"]
    model = ModalModel(labels=labels, kinds=tuple(m[1] for m in MODES), symmetries=("S", "SS", "S", "S"),
                       frequencies_hz=[m[3] for m in MODES], damping_ratios=[0.005] * 4, mass_per_length_kg_m=MU,
                       inertia_per_length_kg_m2_m=J, deck_width_m=B, deck_length_m=L, **deck.integrals(L))
    n = len(MODES)
    mode_set = ModeSet(frequencies_hz=model.frequencies_hz, kinds=model.kinds, symmetries=model.symmetries,
                       labels=labels, energy_shares=np.zeros((n, 4)), deck_share=np.ones(n),
                       modal_masses=model.modal_masses, damping_ratios=model.damping_ratios, z_m=z,
                       U=fields["vertical"], Theta=fields["torsional"], V=-fields["lateral"], W=np.zeros((n, z.size)),
                       shapes=np.zeros((6, n)), deck_length_m=L, mid_span_z_m=L / 2)
    pair = solve_pair(model.subset([0, 2]), Theodorsen(), RHO, 150.0, n_speed=40)
    flutter = FlutterStageResult(model, "theodorsen", RHO, (pair,), pair, None)
    return {"fem": SimpleNamespace(data=SimpleNamespace(modes=mode_set)), "flutter": SimpleNamespace(data=flutter)}


def scenario(**buffeting) -> Scenario:
    flutter = FlutterOptions(aerodynamics="theodorsen", quasi_steady=QuasiSteady(**COEFFICIENTS))
    return Scenario(name="small", kind="suspension_bridge", description="", flutter=flutter,
                    buffeting=BuffetingOptions(frequency_steps=1001, **buffeting))


@pytest.fixture(scope="module")
def outputs():
    upstream = small_bridge()
    return upstream, run(scenario(), upstream, RunOptions())


def test_summary_hdf5_report_and_figures(outputs, tmp_path):
    upstream, out = outputs
    s = out.summary
    json.dumps(s, allow_nan=False)
    v_c = upstream["flutter"].data.governing.critical_speed_m_s
    assert s["buffeting.speed_limit_m_s"] == pytest.approx(v_c) and "two-mode flutter" in s["buffeting.speed_limit"]
    assert s["buffeting.max_speed_m_s"] == pytest.approx(SPEED_FRACTION * v_c)
    assert s["buffeting.reference_speed_m_s"] == 40.0 and s["buffeting.static_coefficients"] == "[flutter.quasi_steady]"
    for key in ("rms_vertical_midspan_m", "rms_torsional_midspan_rad", "rms_lateral_midspan_m", "max_rms_vertical_m"):
        assert s[f"buffeting.{key}"] > 0.0, key
    r = out.data.response
    assert 40.0 in r.speeds_m_s and np.all(np.diff(r.rms_midspan, axis=0) > 0)   # grows with the wind speed
    assert s["buffeting.rms_vertical_midspan_m"] == r.rms_midspan[list(r.speeds_m_s).index(40.0), 0]
    # wind uniform along a symmetric deck: symmetric and skew-symmetric modes are uncorrelated, the RMS symmetric
    np.testing.assert_allclose(r.rms_along_span, r.rms_along_span[:, :, ::-1], rtol=1e-9, atol=1e-12)
    assert r.modal_covariance[:, 0, 1].max() < 1e-12 * r.modal_covariance[:, 0, 0].min()
    path = tmp_path / "results.h5"
    with h5py.File(path, "w") as h5:
        out.write_h5(h5.create_group("buffeting"))
        datastore.write(h5.create_group("data"), out.data)        # what the stage cache keeps
    with h5py.File(path, "r") as h5:
        g = h5["buffeting"]
        for name, ds in g.items():
            assert "unit" in ds.attrs and ds.attrs["description"].strip(), name
        assert g["rms_vertical"].shape == (r.speeds_m_s.size, r.z_m.size)
        assert g["psd_midspan_torsional"].attrs["unit"] == "rad^2/Hz"
        back = datastore.read(h5["data"])
    np.testing.assert_array_equal(back.response.rms_along_span, r.rms_along_span)
    assert out.report.startswith("## Buffeting") and "**40.0**" in out.report
    assert set(out.figures) == {"buffeting_spectra.png", "buffeting_rms.png"}
    axes = out.figures["buffeting_rms.png"].axes
    assert [a.get_ylabel() for a in axes] == ["RMS vertical [m]", "RMS torsional [deg]", "RMS lateral [m]"]


def test_speeds_and_what_is_refused(outputs):
    upstream, _ = outputs
    v_c = upstream["flutter"].data.governing.critical_speed_m_s
    quick = run(scenario(reference_speed_m_s=500.0), upstream, RunOptions(quick=True))
    assert quick.summary["buffeting.rms_vertical_midspan_m"] is None and quick.data.response.speeds_m_s.size == 4
    for options, key in (({"max_speed_m_s": v_c + 1.0}, "buffeting.max_speed_m_s"),
                         ({"min_speed_m_s": SPEED_FRACTION * v_c + 1.0}, "buffeting.min_speed_m_s")):
        with pytest.raises(InputError) as err:
            run(scenario(**options), upstream, RunOptions(quick=True))
        assert err.value.key == key
    bare = replace(scenario(), flutter=FlutterOptions(aerodynamics="theodorsen"))    # no static coefficients
    with pytest.raises(InputError) as err:
        run(bare, upstream, RunOptions(quick=True))
    assert err.value.key == "buffeting.static_coefficients"
    with pytest.raises(InputError) as err:                                            # modes without shapes
        run(scenario(), {"flutter": upstream["flutter"]}, RunOptions(quick=True))
    assert err.value.key == "buffeting"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["great_belt", "model_a", "model_b", "model_c"])
def test_the_shipped_bridges_run_the_stage(name):
    sc = with_aerodynamics(load_scenario(name), "theodorsen")
    out = run_stages(sc, ["buffeting"], RunOptions(quick=True))
    s = out["buffeting"].summary
    assert list(out) == ["cable", "fem", "flutter", "buffeting"]
    assert np.all(out["buffeting"].data.response.rms_midspan > 0.0)
    assert s["buffeting.frequency_resolution_change_percent"] < 1.0
    # the summary's speed (40 m/s) is above Model C's flutter speed with Theodorsen's plate: no numbers then
    assert (s["buffeting.rms_vertical_midspan_m"] is None) == (s["buffeting.speed_limit_m_s"] <= 40.0)
