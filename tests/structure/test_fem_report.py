"""The FEM stage's mode table: thesis Table 3.4/3.5 rows matched to model modes by type and symmetry,
and the figures of the stage (2D views of the model, one quantity per axis)."""

from types import SimpleNamespace

import pytest

from bridge.config import load_scenario
from bridge.pipeline import run_stages
from bridge.stages import RunOptions
from bridge.structure.stage import fem_report, match_reference


@pytest.fixture(scope="module")
def great_belt_fem():
    return run_stages(load_scenario("great_belt"), ["fem"], RunOptions(quick=True))["fem"]


def _row(report: str, label: str) -> list[str]:
    """Cells of the mode-table row of ``label``: mode, label, f, energy, zeta, Table 3.4, Table 3.5."""
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in report.splitlines()
            if line.startswith("| ") and line.count("|") == 8]
    hits = [r for r in rows if r[1] == label]
    assert len(hits) == 1, f"{label} should have one row in the mode table"
    return hits[0]


def test_reference_rows_go_to_modes_of_their_stated_type_else_the_nearest_vertical_or_torsional():
    modes = SimpleNamespace(labels=("S-L1", "SS-V1", "S-V1", "S-C1", "S-V2", "SS-V2", "S-T1", "S-V3"),
                            kinds=("lateral", "vertical", "vertical", "cable", "vertical", "vertical",
                                   "torsional", "vertical"),
                            symmetries=("S", "SS", "S", "S", "S", "SS", "S", "S"),
                            frequencies_hz=(0.05, 0.09, 0.10, 0.12, 0.13, 0.18, 0.28, 0.30))
    rows = [("S", 0.113), ("SS", 0.174), ("S", 0.208), ("SS", 0.241), ("S", 0.287), ("S", 0.332)]
    got = match_reference(modes, rows, {1: "vertical", 3: "vertical", 5: "torsional"})
    # typed rows: S-V1, S-V2 take rows 1, 3 and S-T1 row 5 (by rank, not by row order: S-V3 lies between);
    # untyped rows go to the nearest unmatched vertical/torsional mode within 15 %: row 6 to S-V3 (-10 %),
    # SS row 2 to SS-V2 (0.18, nearest 0.174); SS row 4 (0.241) has none within 15 % (SS-V1 0.09 is left);
    # lateral (0) and cable (3) modes get none
    assert got == {2: (1, "S", 0.113), 4: (3, "S", 0.208), 6: (5, "S", 0.287), 7: (6, "S", 0.332),
                   5: (2, "SS", 0.174)}
    assert match_reference(modes, rows, {1: "vertical", 3: "vertical", 5: "torsional"}, tolerance=2.0)[1] == \
        (4, "SS", 0.241)
    assert match_reference(modes, rows[:1], {1: "vertical"}) == {2: (1, "S", 0.113)}   # the rest none


def test_great_belt_mode_table_matches_by_type_and_lists_the_flutter_modes(great_belt_fem):
    r = great_belt_fem.data
    report = fem_report(r)
    assert r.modes.labels[0] == "S-L1"          # the first model mode is lateral (0.050 Hz) ...
    lateral = _row(report, "S-L1")
    assert "0.113" not in lateral[5] and "none (lateral)" == lateral[5] == lateral[6]   # ... with no reference
    s_v1 = _row(report, "S-V1")
    assert s_v1[5].startswith("1: S 0.113") and s_v1[6].startswith("1: S 0.128")      # Table 3.4 / 3.5 row 1
    f = float(s_v1[2])
    assert f"({100 * (f - 0.113) / 0.113:+.1f} %)" in s_v1[5]
    # every vertical and torsional mode handed to the flutter stage is in the table (S-T1 is mode 24)
    for label, kind in zip(r.modal_model.labels, r.modal_model.kinds, strict=True):
        if kind in ("vertical", "torsional"):
            _row(report, label)
    assert int(_row(report, "S-T1")[0]) > 12
    t1 = _row(report, "S-T1")                      # the first torsional mode takes Table 3.4/3.5 row 5
    assert t1[5].startswith("5: S 0.287") and t1[6].startswith("5: S 0.294")
    assert "rows 1, 3, 7 vertical and 5 torsional" in report     # the rule is stated


def test_model_figure_is_two_labelled_views_with_the_scale_in_the_title(great_belt_fem):
    from bridge.structure.plots import model_figure

    fig = model_figure(great_belt_fem.data, "S-T1", deck_amplitude_m=50.0)
    axes = fig.get_axes()
    assert len(axes) == 2 and all(ax.name == "rectilinear" for ax in axes)
    assert [ax.get_ylabel() for ax in axes] == ["y (elevation) [m]", "x (across) [m]"]
    assert "displacements drawn x" in axes[0].get_title() and "50 m" in axes[0].get_title()
