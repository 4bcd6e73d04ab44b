"""The scenario command end to end: files, schema, summary keys, comparison table."""

import json

import h5py
import pytest

from bridge.scenario import main


def test_cable_stage_end_to_end(tmp_path):
    assert main(["great_belt", "model_c", "--stages", "cable", "--out", str(tmp_path), "--quiet"]) == 0
    folder = tmp_path / "great_belt"
    for f in ("results.h5", "summary.json", "report.md", "cable_main_span.png", "cable_side_span.png"):
        assert (folder / f).is_file(), f
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["cable.horizontal_force_per_cable_N"] == pytest.approx(1.936e8, rel=0.01)
    assert summary["cable.area_m2"] == 0.41
    assert summary["cable.equilibrium_residual"] < 1e-6
    with h5py.File(folder / "results.h5") as h5:
        assert h5.attrs["schema_version"] == "1"
        assert h5["scenario"].attrs["geometry.main_span_m"] == 1624.0
        assert h5["cable/hangers/length"].attrs["unit"] == "m"
        assert len(h5["cable/hangers/z"]) == summary["cable.hanger_count_per_cable"]
        assert h5["cable/main/elevation"][0] == pytest.approx(254.0)  # pylon top
    table = (tmp_path / "comparison.md").read_text()
    assert "model_c" in table and "3.038" in table
    # no temporary folders left; the stage cache is the one hidden folder
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == [".cache"]
