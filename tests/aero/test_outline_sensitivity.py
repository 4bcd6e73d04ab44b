"""tools/outline_sensitivity.py: each ASSUMED dimension of the deck's outline changed alone, its V_c beside the
outline as assumed (the CFD itself is the aero stage's, tested elsewhere; here the tool's wiring)."""

import json
import sys
from dataclasses import fields
from pathlib import Path

import pytest

from bridge.cfd.sections import great_belt_section
from bridge.errors import InputError
from bridge.pipeline import stage_keys
from bridge.stages import StageOutput

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "cfd"))
from cfd_helpers import load_tool  # noqa: E402


def _fake_run(calls):
    """run_stages' stand-in: records the scenario it gets and answers a V_c that grows with the nose height."""
    def run(scenario, stages, options):
        calls.append(scenario)
        section = scenario.deck_section or great_belt_section()
        summary = {"flutter.critical_speed_m_s": 100.0 * section.nose_height_fraction,
                   "flutter.frequency_hz": 0.2, "flutter.mode_pair": "S-V1+S-T1",
                   "flutter.multimode_critical_speed_m_s": None}
        return {"flutter": StageOutput(summary=summary, write_h5=lambda g: None, report="")}
    return run


def test_each_outline_changes_one_dimension_and_its_v_c_is_compared_with_the_assumed_one(tmp_path, monkeypatch):
    tool = load_tool("outline_sensitivity")
    calls = []
    monkeypatch.setattr(tool, "run_stages", _fake_run(calls))
    out = tmp_path / "s.json"
    assert tool.main(["great_belt_body_fitted", "--out", str(out)]) == 0
    base = great_belt_section()
    assert calls[0].deck_section is None        # the scenario as it is: its default outline
    assert len(calls) == 1 + len(tool.DEFAULT_CHANGES)
    for scenario, (name, value) in zip(calls[1:], tool.DEFAULT_CHANGES.items(), strict=True):
        changed = [f.name for f in fields(base) if getattr(scenario.deck_section, f.name) != getattr(base, f.name)]
        assert changed == [name] and getattr(scenario.deck_section, name) == value
        # a changed outline is other aerodynamics: the aero stage's cache key differs, so it is computed afresh
        assert stage_keys(scenario, ["flutter"])["aero"] != stage_keys(calls[0], ["flutter"])["aero"]
    result = json.loads(out.read_text())
    nose = next(r for r in result["rows"] if r["change"].startswith("nose_height_fraction"))
    assert nose["flutter.critical_speed_m_s"] == pytest.approx(70.0)
    assert "| nose_height_fraction 0.8 -> 0.7 | 70.0 | -12.5 % |" in result["table"]


@pytest.mark.parametrize("args, message", [(["--change", "keel_depth=1"], "--change"),
                                           (["--change", "chord_m=30"], "--change"),
                                           (["--change", "railing_height_m=2"], "--change"),
                                           (["--change", "cross_fall=0", "cross_fall=0.01"], "twice"),
                                           (["--change", "cross_fall=steep"], "--change"),
                                           (["--change", "cross_fall=0.9"], "cross_fall")])
def test_bad_input_names_the_field_and_writes_nothing(tmp_path, monkeypatch, capsys, args, message):
    tool = load_tool("outline_sensitivity")
    calls = []
    monkeypatch.setattr(tool, "run_stages", _fake_run(calls))
    out = tmp_path / "s.json"
    assert tool.main(["great_belt_body_fitted", "--out", str(out), *args]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists() and not calls


def test_an_outline_that_cannot_be_computed_is_said_and_the_others_are_kept(tmp_path, monkeypatch):
    tool = load_tool("outline_sensitivity")
    calls = []
    fake = _fake_run(calls)

    def run(scenario, stages, options):
        if scenario.deck_section is not None and scenario.deck_section.cross_fall == 0.0:
            raise InputError("deck_section", "the outline", "cannot be meshed here")
        return fake(scenario, stages, options)
    monkeypatch.setattr(tool, "run_stages", run)
    out = tmp_path / "s.json"
    assert tool.main(["great_belt_body_fitted", "--out", str(out)]) == 1
    rows = json.loads(out.read_text())["rows"]
    assert len(rows) == 1 + len(tool.DEFAULT_CHANGES)
    bad = [r for r in rows if r.get("error")]
    assert [r["change"] for r in bad] == ["cross_fall 0.02 -> 0"] and "cannot be meshed" in bad[0]["error"]
    assert all(r["flutter.critical_speed_m_s"] is not None for r in rows if not r.get("error"))


def test_a_scenario_without_cfd_aerodynamics_is_refused(tmp_path, monkeypatch, capsys):
    """With thin-plate aerodynamics the outline changes nothing: every row would show the same V_c."""
    tool = load_tool("outline_sensitivity")
    calls = []
    monkeypatch.setattr(tool, "run_stages", _fake_run(calls))
    out = tmp_path / "s.json"
    assert tool.main(["thin_plate_section", "--out", str(out)]) == 2
    assert "cfd" in capsys.readouterr().err and not out.exists() and not calls
