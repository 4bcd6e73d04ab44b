"""The CFD tools run end to end with tiny options (speed is not asserted: benchmarks are separate)."""

import io
import json

import numpy as np
import pytest
from cfd_helpers import load_tool


def test_bench_cfd_runs_tiny(tmp_path):
    out = tmp_path / "bench.json"
    res = load_tool("bench_cfd").main(["--sizes", "32x16", "--repeats", "1", "--steps", "1", "--numpy-steps", "1",
                                   "--bandwidth-mb", "8", "--json", str(out)])
    row = res["sizes"]["32x16"]
    assert row["steps"]["warp_step"] > 0 and row["steps"]["numpy_step"] > 0 and row["steps"]["speedup"] > 0
    assert set(row["warp_parts"]) >= {"predict_u", "predict_v", "poisson", "project"}
    assert json.loads(out.read_text())["bytes_per_cell_step"] > 0


def test_progress_note_writes_a_line_per_fraction_with_the_time_left():
    from types import SimpleNamespace

    from bridge.cfd import ProgressNote

    lines = io.StringIO()
    note = ProgressNote("case", 2.0, fraction=0.25, stream=lines)
    for n in range(201):
        note(SimpleNamespace(t=0.01 * n, n_steps=n))
    out = lines.getvalue().splitlines()
    assert len(out) == 4, out   # at t = 0.5, 1, 1.5, 2
    assert out[0].startswith("case: t = 0.5 of 2 (25 %), 50 steps, about ") and out[-1].endswith(" 0 s left")
    with pytest.raises(ValueError, match="fraction"):
        ProgressNote("case", 1.0, fraction=0.0)
    # the aero stage's form: lines to a callable, with the case's own detail before the time left
    said = []
    note = ProgressNote("heave", 1.0, fraction=0.5, sink=said.append, detail=lambda sim: f"{sim.n_steps // 10} periods")
    for n in range(11):
        note(SimpleNamespace(t=0.1 * n, n_steps=n))
    assert len(said) == 2 and said[0].startswith("heave: t = 0.5 of 1 (50 %), 5 steps, 0 periods, about ")
    # a run resumed at t = 1.2 of 2: a line at every quarter of the 0.8 left, not only at 1.5 and 2
    lines = io.StringIO()
    note = ProgressNote("case", 2.0, fraction=0.25, stream=lines)
    for n in range(120, 201):
        note(SimpleNamespace(t=0.01 * n, n_steps=n))
    out = lines.getvalue().splitlines()
    assert [line.split(" of ")[0] for line in out] == ["case: t = 1.4", "case: t = 1.6", "case: t = 1.8",
                                                       "case: t = 2"], out
    # first called with nothing left (a run resumed at its end): it returns (it looped for ever before) and is quiet
    lines = io.StringIO()
    ProgressNote("case", 2.0, stream=lines)(SimpleNamespace(t=2.0, n_steps=7))
    assert lines.getvalue() == ""


def test_validate_cfd_runs_tiny(tmp_path, capsys):
    out = tmp_path / "v.jsonl"
    (res,) = load_tool("validate_cfd").main(["dfg", "--ppd", "6", "--t-end", "0.05", "--out", str(out)])
    assert np.isfinite(res["c_D"]) and res["cells"] == 132 * 25  # 2.2 x 0.41 at h = 0.1/6
    assert "DFG D/6: t = " in capsys.readouterr().err   # progress on stderr
    (res,) = load_tool("validate_cfd").main(["cylinder", "--re", "20", "--ppd", "4", "--t-end", "0.1",
                                             "--out", str(out)])
    assert np.isfinite(res["C_D"])
    (res,) = load_tool("validate_cfd").main(["heave", "--shape", "deck", "--ppd", "6", "--t-end", "0.5",
                                             "--window", "0.4", "--out", str(out)])
    assert res["shape"] == "deck" and np.all(np.isfinite(res["first_harmonic_amplitude"]))
    assert len(out.read_text().splitlines()) == 3
    # --ny-shift: one run per shift, the channel keeps its height with more (or fewer) cells across
    shifted = load_tool("validate_cfd").main(["dfg", "--ppd", "6", "--t-end", "0.02", "--ny-shift", "-1", "2",
                                              "--out", str(out)])
    assert [r["ny"] for r in shifted] == [24, 27] and [r["ny_shift"] for r in shifted] == [-1, 2]
    with pytest.raises(SystemExit):  # no cells left: refused before any run
        load_tool("validate_cfd").main(["dfg", "--ppd", "6", "--ny-shift", "-25", "--out", str(out)])
    assert len(out.read_text().splitlines()) == 5
    # the sensitivity options reach the run: walls refined (more rows than the 25 of h), slip walls, a longer
    # channel, and the variant recorded with the result
    (res,) = load_tool("validate_cfd").main(["dfg", "--ppd", "6", "--t-end", "0.02", "--wall-cell", "0.25", "--walls",
                                             "slip", "--channel-length", "3.3", "--out", str(tmp_path / "s.jsonl")])
    assert res["ny"] > 25 and res["nx"] == 198 and res["variant"]["walls"] == "slip"


def test_the_period_peaks_of_a_growing_sine_are_its_envelope():
    t = np.linspace(0.0, 4.0, 4001)
    envelope = 1.0 + 0.1 * t
    peaks = load_tool("validate_cfd")._period_peaks(t, 0.2 + envelope * np.sin(2 * np.pi * t), window=2.0)
    assert len(peaks) == 3                                   # whole periods between up-crossings only
    starts, values = np.array(peaks).T
    assert np.allclose(np.diff(starts), 1.0, atol=0.01)
    assert np.allclose(values, 0.2 + 1.0 + 0.1 * (starts + 0.25), atol=0.01)   # each at its quarter period


@pytest.mark.slow   # 5 s: out of the default run, which must stay under 2 minutes
def test_dfg2_starts_from_a_saved_background_and_reaches_the_same_forces(tmp_path, capsys):
    """--save-state / --start-from: a run restarted from its own background at t = 0.1 (the body grid set from
    it) gives the drag of the run that went through, once its settling (0.05) is left out of the window; a
    finer body grid starts from the same file; a file that does not fit the run is refused before any run."""
    tool, out, state = load_tool("validate_cfd"), str(tmp_path / "v.jsonl"), tmp_path / "state.h5"
    common = ["dfg2", "--overset", "12", "--threads", "1", "--out", out]
    (first,) = tool.main([*common, "--ppd", "24", "--t-end", "0.1", "--window", "0.05", "--save-state", str(state)])
    assert state.exists()
    (through,) = tool.main([*common, "--ppd", "24", "--t-end", "0.2", "--window", "0.05"])
    (again,) = tool.main([*common, "--ppd", "24", "--t-end", "0.2", "--window", "0.05", "--start-from", str(state)])
    assert again["t_start"] == pytest.approx(first["t_end"]) and through["t_start"] == 0.0
    assert again["steps"] < through["steps"]
    assert again["c_D_max"] == pytest.approx(through["c_D_max"], rel=0.01)
    assert (tmp_path / "dfg2_ppd24_bg12_restarted.h5").exists() and (tmp_path / "dfg2_ppd24_bg12.h5").exists()
    peaks = through["c_L_max_per_period"]   # none yet (the shedding has not started): a list of whole periods
    assert isinstance(peaks, list) and all(len(p) == 2 for p in peaks)
    (finer,) = tool.main([*common, "--ppd", "36", "--t-end", "0.15", "--window", "0.02", "--start-from", str(state)])
    assert finer["t_start"] == pytest.approx(first["t_end"]) and np.isfinite(finer["c_D_max"])
    capsys.readouterr()
    for argv, option in ((["--overset", "16", "--t-end", "0.2", "--window", "0.05"], "--start-from"),
                         (["--overset", "12", "--t-end", "0.12", "--window", "0.05"], "--t-end"),
                         (["--overset", "12", "--t-end", "0.2", "--window", "0.05", "--cfl", "0.3"], "--start-from")):
        with pytest.raises(SystemExit) as exc:
            tool.main(["dfg2", "--ppd", "24", *argv, "--start-from", str(state), "--out", str(tmp_path / "no")])
        assert exc.value.code == 2 and option in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:   # the single grid has no background to save
        tool.main(["dfg2", "--ppd", "6", "--save-state", str(tmp_path / "s.h5"), "--out", str(tmp_path / "no")])
    assert exc.value.code == 2 and "--save-state" in capsys.readouterr().err
    assert not (tmp_path / "no").exists() and not (tmp_path / "s.h5").exists()


@pytest.mark.parametrize("tool, argv, option", [
    ("validate_cfd", ["dfg", "--ppd", "0"], "--ppd"),
    ("validate_cfd", ["cylinder", "--re", "-5"], "--re"),
    ("validate_cfd", ["dfg", "--t-end", "-1"], "--t-end"),
    ("validate_cfd", ["cylinder", "--window", "0"], "--window"),
    ("validate_cfd", ["dfg", "--threads", "0"], "--threads"),
    ("validate_cfd", ["cylinder", "--domain", "10", "20", "1"], "--domain"),
    ("validate_cfd", ["dfg", "--advection", "upwind"], "--advection"),
    ("bench_cfd", ["--sizes", "0x0"], "--sizes"),
    ("bench_cfd", ["--sizes", "abc"], "--sizes"),
    ("bench_cfd", ["--repeats", "0"], "--repeats"),
    ("bench_cfd", ["--steps", "0"], "--steps"),
])
def test_cfd_tools_refuse_bad_input_naming_the_option(tmp_path, capsys, tool, argv, option):
    out = tmp_path / "result"
    out_flag = "--out" if tool == "validate_cfd" else "--json"
    with pytest.raises(SystemExit) as exc:
        load_tool(tool).main([*argv, out_flag, str(out)])
    assert exc.value.code == 2
    assert option in capsys.readouterr().err
    assert not out.exists()  # nothing written
