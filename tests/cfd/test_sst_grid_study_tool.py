"""tools/sst_grid_study.py on the body-fitted pair: its layer options reach the preset only there, and a value
out of range stops the tool before any run."""

from types import SimpleNamespace

import pytest
from cfd_helpers import load_tool


def test_the_layer_options_belong_to_the_body_fitted_grid_and_are_checked(tmp_path, capsys):
    study = load_tool("sst_grid_study")
    given = SimpleNamespace(grid="body_fitted", growth=1.2, first_height=None)
    assert study._grid_changes(given) == {"growth": 1.2}
    assert study._grid_changes(SimpleNamespace(grid="overset", growth=None, first_height=None)) == {}
    out = tmp_path / "s.json"
    for args, message in ((["--growth", "1.1"], "only with --grid body_fitted"),
                          (["--grid", "body_fitted", "--growth", "1.3"], "--growth: 1.3 not allowed"),
                          (["--grid", "body_fitted", "--first-height", "0"], "--first-height: 0.0 not allowed")):
        with pytest.raises(SystemExit) as e:
            study.main([*args, "--out", str(out)])
        assert e.value.code == 2 and message in capsys.readouterr().err
    assert not out.exists()
