"""tools/bench_cells_to_accuracy.py: each grid sequence stops at its first grid within the tolerance of
DFG 2D-1's reference c_D (one more with --confirm), and a tolerance out of range stops it before any run."""

import pytest
from cfd_helpers import load_tool


def _runs(c_ds):
    calls = []

    def run(grid):
        calls.append(grid)
        return {"grid": str(grid), "cells": 10 * grid, "steps": grid, "wall_s": 1.0, "c_D": c_ds[grid],
                "error": c_ds[grid] / bench.REFERENCE_C_D - 1}
    return run, calls


bench = load_tool("bench_cells_to_accuracy")


def test_a_sequence_stops_at_its_first_grid_within_the_tolerance():
    c_ds = [5.40, 5.51, 5.60, 5.58, 5.5795]   # -3.2, -1.2, +0.4, 0.0, 0.0 %
    run, calls = _runs(c_ds)
    got = bench.sequence("x", list(range(5)), run, 0.01, confirm=False, say=lambda _: None)
    assert calls == [0, 1, 2] and got["first_within"] == 2
    run, calls = _runs(c_ds)
    got = bench.sequence("x", list(range(5)), run, 0.01, confirm=True, say=lambda _: None)
    assert calls == [0, 1, 2, 3] and got["first_within"] == 2
    run, calls = _runs(c_ds)
    assert bench.sequence("x", [0, 1], run, 0.01, confirm=False, say=lambda _: None)["first_within"] is None


def test_a_tolerance_out_of_range_is_refused_before_any_run(tmp_path, capsys):
    out = tmp_path / "b.json"
    with pytest.raises(SystemExit) as e:
        bench.main(["--tolerance", "0.5", "--json", str(out)])
    assert e.value.code == 2 and "--tolerance 0.5: allowed" in capsys.readouterr().err
    assert not out.exists()
