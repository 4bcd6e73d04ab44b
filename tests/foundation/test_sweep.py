"""Sweeps: cases from spans x varied keys, resumable, one HDF5 table."""

import h5py
import numpy as np

from bridge.sweep import main, plan_cases


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
