"""Sweeps: cases from spans x varied keys, resumable, one HDF5 table."""

import h5py
import numpy as np
import pytest

import bridge.sweep as sweep
from bridge.sweep import main, plan_cases, run_shared_stages


def test_plan_is_the_cartesian_product():
    cases = plan_cases("great_belt", [1624.0, 2000.0], {"girder.mass_per_length_kg_m": [14000, 16000]})
    assert len(cases) == 4 and len({c.name for c in cases}) == 4


def test_sweep_runs_resumes_and_tabulates(tmp_path, capsys):
    args = ["great_belt", "--main-span", "1624,3000", "--stages", "cable", "--out", str(tmp_path), "--workers", "1",
            "--vary", "girder.mass_per_length_kg_m=14780,20000"]
    assert main(args) == 0
    assert capsys.readouterr().err.count(": done") == 4
    assert main(args) == 0
    assert capsys.readouterr().err.count(": skipped") == 4
    with h5py.File(tmp_path / "sweep_great_belt" / "sweep.h5") as h5:
        span = h5["inputs/main_span_m"][:]
        h = h5["results/cable.horizontal_force_total_N"][:]
        mass = h5["inputs/girder.mass_per_length_kg_m"][:]
    assert sorted(span) == [1624, 1624, 3000, 3000]
    # heavier girder -> larger H at the same span; longer span -> larger H
    for L in (1624, 3000):
        light, heavy = h[(span == L) & (mass == 14780)][0], h[(span == L) & (mass == 20000)][0]
        assert heavy > light
    assert np.all(h[span == 3000] > h[span == 1624].max())
    assert (tmp_path / "sweep_great_belt" / "sweep.png").is_file()


def test_sweep_bad_key_is_input_error(tmp_path, capsys):
    assert main(["great_belt", "--vary", "girder.colour=1,2", "--out", str(tmp_path)]) == 2
    assert "girder.colour" in capsys.readouterr().err


def test_collect_tolerates_mixed_numeric_and_text_values(tmp_path):
    """A key that is a number in one case and "none" in another (a pair without flutter) becomes NaN."""
    import json

    from bridge.sweep import collect

    cases = plan_cases("great_belt", [1624.0, 2000.0], {})
    for c, v in zip(cases, [86.5, "none"], strict=True):
        (tmp_path / "cases" / c.name).mkdir(parents=True)
        (tmp_path / "cases" / c.name / "summary.json").write_text(json.dumps(
            {"scenario.main_span_m": c.main_span_m, "flutter.critical_speed_m_s": v}))
    collect(cases, tmp_path / "cases", tmp_path, None)
    with h5py.File(tmp_path / "sweep.h5") as h5:
        got = h5["results/flutter.critical_speed_m_s"][:]
    assert got[0] == 86.5 and np.isnan(got[1])


def test_a_stage_the_cases_share_runs_once_before_they_start(tmp_path, monkeypatch):
    """Three spans of one deck share its CFD (the aero stage): it is run once, not by each case at once (two
    workers missing the cache together each computed it, on one core each); two grids are two CFDs; a
    bridge with thin-plate aerodynamics has none."""
    calls = []
    monkeypatch.setattr("bridge.pipeline.run_stages", lambda sc, stages, options:
                        calls.append((sc.geometry.main_span_m, sc.aero.cells_per_chord, stages)))
    quiet = lambda m: None  # noqa: E731
    assert run_shared_stages(plan_cases("great_belt_body_fitted", [1624.0, 2000.0, 3000.0], {}), None, False,
                             tmp_path, quiet) == 1
    assert calls == [(1624.0, 0, ["aero"])]
    calls.clear()
    assert run_shared_stages(plan_cases("great_belt_body_fitted", [2000.0], {"aero.cells_per_chord": [0, 24]}),
                             None, False, tmp_path, quiet) == 2
    assert [c[1] for c in calls] == [0, 24]
    calls.clear()
    assert run_shared_stages(plan_cases("great_belt", [1624.0, 2000.0], {}, "theodorsen"), None, False,
                             tmp_path, quiet) == 0 and calls == []


def test_the_sweep_runs_the_shared_stages_first_unless_the_cache_is_off(tmp_path, monkeypatch):
    seen = []
    monkeypatch.setattr(sweep, "run_shared_stages", lambda cases, stages, quick, cache_dir, say, scheduler:
                        seen.append((len(cases), cache_dir)))
    args = ["great_belt", "--main-span", "1624,2000", "--stages", "cable", "--workers", "1", "--out", str(tmp_path)]
    assert main(args) == 0 and seen == [(2, tmp_path / ".cache")]
    assert main([*args, "--no-cache", "--name", "again"]) == 0 and len(seen) == 1


def test_the_cases_read_the_shared_stage_that_ran_once_and_a_resumed_sweep_runs_it_no_more(tmp_path, monkeypatch):
    """End to end with a stand-in for the aero stage (counted): it runs once for two spans, under the cache key each
    case then looks up (both say "from the cache: aero"); its error reaches the cases; rerun with every case
    finished and the cache emptied, nothing is computed again; Ctrl-C in it stops the sweep."""
    import shutil

    import bridge.pipeline as pipeline
    from bridge.stages import StageOutput
    from bridge.sweep import run_sweep

    real, runs, fail = pipeline.resolve_stage, [], []

    def aero(scenario, outputs, options):
        runs.append(scenario.geometry.main_span_m)
        if fail:
            raise fail[0]
        return StageOutput(summary={"aero.section": "stand-in"}, write_h5=lambda g: None, report="## Aero\n")

    monkeypatch.setattr(pipeline, "resolve_stage", lambda name: aero if name == "aero" else real(name))
    cases = plan_cases("great_belt_body_fitted", [1624.0, 2000.0], {})
    said = []
    status = run_sweep(cases, tmp_path / "s", ["aero"], False, 1, None, said.append, cache_dir=tmp_path / "cache")
    assert runs == [1624.0], runs
    assert all(v.startswith("done") and "from the cache: aero" in v for v in status.values()), status
    shutil.rmtree(tmp_path / "cache")
    status = run_sweep(cases, tmp_path / "s", ["aero"], False, 1, None, said.append, cache_dir=tmp_path / "cache")
    assert runs == [1624.0] and set(status.values()) == {"skipped"}
    fail.append(RuntimeError("no grid"))
    status = run_sweep(cases, tmp_path / "t", ["aero"], False, 1, None, said.append, cache_dir=tmp_path / "cache")
    assert all("no grid" in v for v in status.values()) and any("no grid" in m for m in said)
    fail[0] = KeyboardInterrupt()
    with pytest.raises(KeyboardInterrupt):
        run_sweep(cases, tmp_path / "u", ["aero"], False, 1, None, said.append, cache_dir=tmp_path / "cache")
