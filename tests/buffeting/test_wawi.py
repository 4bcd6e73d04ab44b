"""The buffeting response against an independent implementation of the same theory, wawi 0.0.19 (Kvåle, NTNU),
on the same inputs: RMS displacements within 2 %.

wawi is not a dependency: its numbers were recorded once by tools/buffeting_wawi_reference.py (the command is
in the data file) with the inputs beside them; this test builds the same case from those inputs with
bridge.buffeting.  The cases: a simply supported deck, two vertical, one torsional and one lateral sine mode,
(A) Kaimal spectra, Sears's admittance and quasi-steady self-excited forces, (B) von Karman spectra, no
admittance and the flat plate's (Theodorsen's) self-excited forces.
"""

import json
from pathlib import Path

import numpy as np
import pytest

from bridge.buffeting.admittance import Admittance
from bridge.buffeting.loads import DeckModes
from bridge.buffeting.response import buffeting_response, frequency_grid
from bridge.buffeting.wind import Turbulence
from bridge.flutter.aerodynamics import QuasiSteady, Theodorsen
from bridge.flutter.modal import ModalModel

RECORD = json.loads((Path(__file__).parent / "data" / "wawi_reference.json").read_text())
DOFS = ("vertical", "torsional", "lateral")


def ours(name: str, self_excited: bool = True) -> dict[str, np.ndarray]:
    """Our RMS at each station of the record, (n_V, 3), for case ``name``."""
    inp = RECORD["inputs"]
    L = inp["span_m"]
    z = np.linspace(0.0, L, inp["elements"] + 1)
    fields = {k: np.zeros((len(inp["modes"]), z.size)) for k in DOFS}
    for i, m in enumerate(inp["modes"]):
        fields[m["kind"]][i] = np.sin(m["half_waves"] * np.pi * z / L)
    labels = tuple(m["label"] for m in inp["modes"])
    modes = DeckModes(labels, z, fields["vertical"], fields["torsional"], fields["lateral"], L / 2)
    model = ModalModel(labels=labels, kinds=tuple(m["kind"] for m in inp["modes"]),
                       symmetries=("S",) * len(labels), frequencies_hz=[m["frequency_hz"] for m in inp["modes"]],
                       damping_ratios=[m["damping_ratio"] for m in inp["modes"]],
                       mass_per_length_kg_m=inp["mass_per_length_kg_m"],
                       inertia_per_length_kg_m2_m=inp["inertia_per_length_kg_m2_m"],
                       deck_width_m=inp["deck_width_m"], deck_length_m=L, **modes.integrals(L))
    c = inp["cases"][name]
    coefficients = QuasiSteady(**inp["static_coefficients"])
    aero = coefficients if c["self_excited"] == "quasi_steady" else Theodorsen()
    turbulence = Turbulence(c["spectrum"], c["turbulence_intensity_u"], c["turbulence_intensity_w"],
                            c["length_scale_u_m"], c["length_scale_w_m"], c["coherence_decay_u"],
                            c["coherence_decay_w"])
    f = frequency_grid(inp["max_frequency_hz"], RECORD["frequency_steps"])
    r = buffeting_response(model, modes, aero, inp["air_density_kg_m3"], coefficients, turbulence,
                           Admittance(c["admittance"]), inp["speeds_m_s"], f, self_excited=self_excited)
    out = {}
    for station, fraction in inp["stations"].items():
        phi = modes.at(fraction * L)
        out[station] = np.sqrt(np.einsum("ki,vij,kj->vk", phi, r.modal_covariance, phi))
    return out


def theirs(name: str) -> dict[str, np.ndarray]:
    runs = RECORD["rms"][name]
    return {station: np.array([[run[station][d] for d in DOFS] for run in runs])
            for station in RECORD["inputs"]["stations"]}


def test_the_record_is_wawis():
    assert RECORD["wawi_version"] == "0.0.19" and RECORD["command"].startswith("/tmp/wawienv/bin/python tools/")


@pytest.mark.parametrize("name", ["A", "B"])
def test_rms_responses_agree_with_wawi_within_2_percent(name):
    mine, reference = ours(name), theirs(name)
    for station in reference:
        assert np.all(reference[station] > 0)
        np.testing.assert_allclose(mine[station], reference[station], rtol=0.02, err_msg=station)


def test_without_the_self_excited_forces_the_comparison_fails():
    # the control: the band is narrow enough to see the aerodynamic damping and stiffness
    mine, reference = ours("A", self_excited=False), theirs("A")
    assert np.max(np.abs(mine["midspan"] / reference["midspan"] - 1)) > 0.1
