"""tools/plate_loading.py: our plate's pressure along the chord.  Bad input stops it before any run; a short
coarse run reads the pressure on the plate's two sides (its lift carries most of the force record's, and the
plate at -alpha loads the chord as at +alpha with the sign changed: the plate and its grid are mirror-symmetric)."""

import json

import numpy as np
import pytest
from cfd_helpers import load_tool


@pytest.mark.parametrize("argv, option", [(["--angle", "0"], "--angle"), (["--duration", "0.5"], "--duration"),
                                          (["--cells-per-chord", "4"], "--cells-per-chord"),
                                          (["--dy-over-dx", "5"], "dy_over_dx"),
                                          (["--openfoam", "no_such_case"], "--openfoam"),
                                          (["--quality", "superb"], "superb"),
                                          (["--turbulence", "laminar", "--sst-walls", "resolved"], "--sst-walls")])
def test_bad_input_exits_2_naming_the_option_and_writes_nothing(tmp_path, capsys, argv, option):
    tool = load_tool("plate_loading")
    out = tmp_path / "loading"
    with pytest.raises(SystemExit) as e:
        tool.main(argv + ["--out", str(out)])
    assert e.value.code == 2
    assert option in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
def test_a_coarse_run_reads_the_pressure_on_both_sides_of_the_plate(tmp_path):
    tool = load_tool("plate_loading")
    got = {}
    for angle in (2.0, -2.0):
        out = tmp_path / f"a{angle:g}"
        assert tool.main(["--quality", "quick", "--duration", "4", "--angle", str(angle), "--out", str(out)]) == 0
        got[angle] = json.loads((out / "loading.json").read_text())
        assert (out / "loading.png").stat().st_size > 1000
    up, down = got[2.0], got[-2.0]
    ratio = up["ours"]["lift_from_pressure"] / up["ours_force_record"]["C_L"]
    assert 0.6 < ratio < 1.1, ratio          # 16 cells per chord: the samples lie 1.5-2.5 cells off the wall
    assert up["ours"]["lift_from_pressure"] > 0
    total = up["ours"]["lift_from_pressure"]
    assert np.array(down["ours"]["strips"]) == pytest.approx(-np.array(up["ours"]["strips"]), abs=0.05 * total)
    side = up["ours_upper_side"]
    assert len(side["x"]) == len(side["nut_over_nu_max"]) == len(up["ours_delta_cp"]["x"])
    assert min(side["nut_over_nu_max"]) > -1e-9 and 0 < min(side["first_cell_height"])


def test_the_samples_are_the_first_cells_off_the_plate_that_no_forcing_touches():
    tool = load_tool("plate_loading")
    y = (np.arange(10) - 4.5) * 0.1           # cell centres, the plate about y = 0
    forced = np.zeros((10, 3), dtype=bool)
    forced[3:7, :] = True                     # the plate and its forced neighbours
    forced[7, 1] = True                       # a column where the forcing reaches one cell further up
    up, down = tool.surface_rows(forced, y, np.array([0, 1, 2]))
    assert up.tolist() == [7, 8, 7] and down.tolist() == [2, 2, 2]


def test_the_upper_side_takes_the_largest_eddy_viscosity_below_the_height_and_the_first_free_cells_speed():
    tool = load_tool("plate_loading")
    y = (np.arange(10) - 4.5) * 0.02          # cell centres; the upper surface at 0.01
    nut = np.arange(30.0).reshape(10, 3)       # grows upward and along x
    u = np.tile(np.linspace(0.0, 0.9, 10)[:, None], (1, 3))
    got = tool.upper_side_flow(nut, u, y, np.array([0, 2]), np.array([6, 7]), 0.01, height=0.05)
    # centres above 0.01 and below 0.06: 0.03, 0.05 (rows 6, 7)
    assert got["nut_over_nu_max"].tolist() == [nut[7, 0], nut[7, 2]]
    assert got["first_cell_height"] == pytest.approx([0.02, 0.04])
    assert got["first_cell_u"] == pytest.approx([u[6, 0], u[7, 2]])
