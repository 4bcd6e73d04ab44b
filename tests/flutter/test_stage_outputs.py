"""What the stages hand to the result files: HDF5 attributes, strict-JSON summaries, and the figures
(axis labels with units, the p-k damping plot, the governing pair's mode shapes).

The stages run in memory (quick) through ``bridge.pipeline.run_stages``; the HDF5 file is written here
from each output's ``write_h5``, the way ``bridge.results`` does it.
"""

import json
import re
from dataclasses import replace

import h5py
import numpy as np
import pytest

from bridge.config import load_scenario, with_aerodynamics
from bridge.pipeline import run_stages
from bridge.stages import RunOptions

# great_belt: cable -> fem -> flutter (Theodorsen's aerodynamics: the stages' outputs, not the CFD's, are
# checked here; tests/aero checks the aero stage's); great_belt_thesis_modes: kind "modal", the flutter stage
# alone (no flutter below 150 m/s: the no-solution paths).
SCENARIOS = ("great_belt", "great_belt_thesis_modes")


def theodorsen(name: str):
    return with_aerodynamics(load_scenario(name), "theodorsen")


@pytest.fixture(scope="module")
def outputs():
    return {name: run_stages(theodorsen(name), None, RunOptions(quick=True)) for name in SCENARIOS}


@pytest.mark.parametrize("name", SCENARIOS)
def test_every_dataset_has_a_unit_and_a_description(outputs, tmp_path, name):
    path = tmp_path / "results.h5"
    with h5py.File(path, "w") as h5:
        for stage, out in outputs[name].items():
            out.write_h5(h5.create_group(stage))
    datasets = []
    with h5py.File(path, "r") as h5:
        h5.visititems(lambda key, obj: datasets.append((key, dict(obj.attrs)))
                      if isinstance(obj, h5py.Dataset) else None)
    assert {k.split("/")[0] for k, _ in datasets} == set(outputs[name])   # every stage wrote datasets
    for key, attrs in datasets:
        assert "unit" in attrs, key
        assert isinstance(attrs.get("description"), str) and attrs["description"].strip(), key
    units = dict((k, a["unit"]) for k, a in datasets)
    assert units["flutter/pairs/critical_speed_m_s"] == "m/s" and units["flutter/modal/labels"] == ""
    if name == "great_belt":
        assert units["fem/frequencies_hz"] == "Hz" and units["fem/uu"] == "1" and units["fem/labels"] == ""


def _strict(summary: dict) -> None:
    json.dumps(summary, allow_nan=False)                 # raises on NaN or inf
    for key, value in summary.items():
        assert value != "none", key
        assert value is None or isinstance(value, (bool, int, float, str)), key


@pytest.mark.parametrize("name", SCENARIOS)
def test_summaries_are_strict_json_with_none_for_missing_numbers(outputs, name):
    for out in outputs[name].values():
        _strict(out.summary)
    s = outputs[name]["flutter"].summary
    assert isinstance(s["flutter.flutter"], bool)
    pairs = outputs[name]["flutter"].data.pairs
    for r in pairs:
        v = s[f"flutter.pair_{r.pair[0]}+{r.pair[1]}.critical_speed_m_s"]
        assert (v is None) == (not r.flutter)
    if name == "great_belt_thesis_modes":                # no flutter below 150 m/s
        assert s["flutter.flutter"] is False and s["flutter.critical_speed_m_s"] is None
        assert s["flutter.mode_pair"] is None and s["flutter.multimode_critical_speed_m_s"] is None


def test_divergence_speed_beyond_the_search_is_none_not_nan():
    sc = load_scenario("great_belt_thesis_modes")        # static divergence at 103 m/s: search to 60 only
    sc = replace(sc, flutter=replace(sc.flutter, max_speed_m_s=60.0))
    s = run_stages(sc, None, RunOptions(quick=True))["flutter"].summary
    _strict(s)
    assert s["flutter.divergence_speed_m_s"] is None


def _axes_with_data(fig):
    return [ax for ax in fig.get_axes() if ax.has_data()]


def test_every_axis_of_every_figure_is_one_quantity_with_one_unit(outputs):
    unit = re.compile(r"^[^\[\]]+ \[[^\[\]]+\]$")        # "what [unit]", exactly one bracket pair
    for name in SCENARIOS:
        for stage, out in outputs[name].items():
            for fname, fig in out.figures.items():
                for ax in _axes_with_data(fig):
                    labels = [ax.get_ylabel()] + ([ax.get_xlabel()] if ax.get_xlabel() else [])
                    for text in labels:
                        assert unit.match(text), (stage, fname, text)
                    legend = ax.get_legend()
                    for t in legend.get_texts() if legend else []:
                        assert "[" not in t.get_text(), (fname, t.get_text())   # no units mixed in a legend
                # shared x axes label the bottom panel only
                assert any(ax.get_xlabel() for ax in _axes_with_data(fig)), fname


def test_damping_plot_highlights_the_unstable_branch_and_leaves_out_non_oscillatory_points(outputs):
    m = outputs["great_belt"]["flutter"].data.multimode
    assert m.flutter and m.unstable_mode
    # the +-1 plateaus are exactly the points where the tracked eigenvalue is real (frequency 0); the other
    # non-oscillatory points have no root on the tracked branch: NaN in both (the modes' last bits, which
    # differ between machines, decide whether two overdamped roots collapse onto one branch there)
    osc, zeta = m.oscillatory, m.damping_ratio
    real = ~osc & np.isfinite(m.frequency_hz)
    assert real.any()
    np.testing.assert_array_equal(np.abs(zeta[real]), 1.0)
    np.testing.assert_array_equal(m.frequency_hz[real], 0.0)
    lost = ~osc & ~real
    assert np.all(np.isnan(zeta[lost]))
    assert np.all(np.abs(zeta[osc]) < 1.0)
    ax_damping = outputs["great_belt"]["flutter"].figures["flutter_damping.png"].get_axes()[0]
    branches = [line for line in ax_damping.get_lines() if len(line.get_xdata()) == m.speed_m_s.size]
    assert len(branches) == len(m.labels)               # one line per mode (V_c, V_D lines aside)
    for line in branches:
        y = np.asarray(line.get_ydata(), dtype=float)
        assert not np.any(np.abs(y[np.isfinite(y)]) == 1.0), line.get_label()
    key = [line for line in branches if line.get_label() == f"{m.unstable_mode}: goes unstable"]
    assert len(key) == 1
    others = [line for line in branches if line is not key[0]]
    assert all(line.get_linewidth() < key[0].get_linewidth() and line.get_color() == "0.65" for line in others)


def test_flutter_stage_plots_the_governing_pair_when_the_fem_ran():
    out = run_stages(theodorsen("model_c"), None, RunOptions(quick=True))
    fem, flutter = out["fem"].figures, out["flutter"].figures
    pair = out["flutter"].data.governing.pair
    assert pair == ("SS-V1", "SS-T1")                  # skew-symmetric: the fem stage plots S modes only
    for label in pair:
        assert f"fem_mode_{label}.png" in flutter
    assert not set(fem) & set(flutter)                 # no figure drawn twice under one name


def test_flutter_stage_without_fem_draws_no_mode_shapes(outputs):
    figs = outputs["great_belt_thesis_modes"]["flutter"].figures
    assert set(figs) == {"flutter_determinant.png", "flutter_damping.png"}
