"""tools/validate_aero.py's grid overrides (a grid study beyond the presets): they replace only the
fields asked for, and a value outside the preset's range stops the tool before any run."""

import pytest
from cfd_helpers import load_tool

from bridge.aero.presets import preset
from bridge.errors import InputError


def test_grid_overrides_replace_only_the_fields_given():
    va = load_tool("validate_aero")
    q = va.plate_quality("standard", "overset", reynolds=1e4,
                         grid_overrides={"cells_per_chord": 200, "dy_over_dx": 0.5, "background_coarsening": 4})
    base = preset("standard", "overset")
    g = q.grid
    assert (g.cells_per_chord, g.dy_over_dx, g.background_coarsening, q.physics.reynolds) == (200, 0.5, 4, 1e4)
    assert (g.upstream, g.downstream, q.run) == (base.grid.upstream, base.grid.downstream, base.run)
    assert va.plate_quality("standard", "overset", grid_overrides={"cells_per_chord": None}) == base
    with pytest.raises(ValueError, match="not among"):
        va.plate_quality("standard", "overset", grid_overrides={"upstream": 8.0})
    with pytest.raises(InputError, match="aero.dy_over_dx"):
        va.plate_quality("standard", "overset", grid_overrides={"dy_over_dx": 2.0})


def test_the_body_fitted_grid_overrides_reach_the_o_grid_and_are_checked():
    va = load_tool("validate_aero")
    q = va.plate_quality("standard", "body_fitted",
                         grid_overrides={"around_per_chord": 240.0, "first_height": 0.00125, "growth": 1.05})
    g = q.grid
    assert g.body_fitted and (g.around_per_chord, g.first_height, g.growth) == (240.0, 0.00125, 1.05)
    assert g.cells_per_chord == preset("standard", "body_fitted").grid.cells_per_chord
    with pytest.raises(InputError, match="aero.growth"):
        va.plate_quality("standard", "body_fitted", grid_overrides={"growth": 1.5})


def test_a_bad_override_exits_2_naming_the_field_and_writes_nothing(tmp_path, capsys):
    va = load_tool("validate_aero")
    out = tmp_path / "v.json"
    with pytest.raises(SystemExit) as e:
        va.main(["--cells-per-chord", "4", "--out", str(out)])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert "aero.cells_per_chord" in err and "4" in err
    assert not out.exists() and not (tmp_path / "validate_aero_runs").exists()


def test_an_out_that_is_a_folder_is_refused_before_any_run(tmp_path, capsys):
    """--out names the JSON file; a folder there once ended a 50-minute run with IsADirectoryError when the
    table was written."""
    va = load_tool("validate_aero")
    with pytest.raises(SystemExit) as e:
        va.main(["--quality", "tiny", "--out", str(tmp_path)])
    assert e.value.code == 2
    assert "--out" in capsys.readouterr().err
    assert not (tmp_path.parent / "validate_aero_runs").exists()


def test_heave_alone_gives_its_four_derivatives_and_none_for_the_pitch_ones(tmp_path):
    import json
    import math

    va = load_tool("validate_aero")
    out = tmp_path / "v.json"
    assert va.main(["--quality", "tiny", "--reduced-velocities", "4", "--thickness", "0.1", "--dofs", "heave",
                    "--out", str(out)]) == 0
    (row,) = json.loads(out.read_text())
    for n in ("H1", "H4", "A1", "A4"):
        assert math.isfinite(row[n]["cfd"]) and row[n]["cfd"] != 0.0
    for n in ("H2", "H3", "A2", "A3"):
        assert row[n]["cfd"] is None and row[n]["relative_difference"] is None
    assert set(row["frf"]) == {"h_pu", "h_mu"}


def test_an_under_resolved_laminar_plate_is_flagged_and_the_validated_grids_are_not():
    """The warnings follow the runs of docs/aero.md: the standard grid at Re 1000 resolves the plate (no
    warning); at Re 1e5 its boundary layer spans 2.5 cells; at Re 1e4 the trailing edge sheds and 40 cells per
    chord do not follow it, 200 do; SST stands in a wall function for the boundary layer (no warning)."""
    va = load_tool("validate_aero")
    assert va.resolution_warnings(va.plate_quality("standard", "overset"), 0.02) == []
    (bl, edge) = va.resolution_warnings(va.plate_quality("standard", "overset", reynolds=1e5), 0.02)
    assert "boundary layer" in bl and "2.5 cells" in bl
    assert "sheds" in edge and "200 cells per chord" in edge
    (edge,) = va.resolution_warnings(va.plate_quality("standard", "overset", reynolds=1e4), 0.02)
    assert "sheds" in edge
    fine = va.plate_quality("standard", "overset", reynolds=1e4,
                            grid_overrides={"cells_per_chord": 200, "dy_over_dx": 0.5})
    assert va.resolution_warnings(fine, 0.02) == []
    assert va.resolution_warnings(va.plate_quality("standard", "overset", "sst", 1e6), 0.02) == []
