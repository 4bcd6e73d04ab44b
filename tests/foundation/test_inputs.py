"""Bad scenario input: one line naming the key, the value and the allowed range; exit status 2; nothing
left in the output folder."""

import pytest

from bridge.config import load_scenario
from bridge.errors import InputError
from bridge.scenario import main

GOOD = (open(__file__.replace("tests/foundation/test_inputs.py", "scenarios/great_belt.toml")).read())


def write(tmp_path, text, name="bad.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize("edit, key", [
    (("main_span_m = 1624.0", "main_span_m = -1624.0"), "geometry.main_span_m"),
    (("mass_per_length_kg_m = 14.78e3", "mass_per_length_kg_m = 0.0"), "girder.mass_per_length_kg_m"),
    (("sag_m = 180.5", "sag_m = 30.0"), "sag_ratio"),
    (("sag_m = 180.5", 'sag_m = "deep"'), "geometry.sag_m"),
    (("area_m2 = 0.41 ", "area_m2 = 0.41\ncolour = 1 "), "cable.colour"),
    (("side_span_m = 535.0", "side_spam_m = 535.0"), "geometry.side_span_m"),
    (('material = "concrete"', 'material = "granite"'), "pylon.material"),
    (("t_m = 1.7 }", "t_m = 9.0 }"), "pylon.lower_leg.t_m"),
])
def test_bad_values_name_the_key(tmp_path, edit, key):
    old, new = edit
    assert old in GOOD
    path = write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(InputError) as info:
        load_scenario(path)
    assert key in str(info.value)


def test_command_line_bad_input_exit_2_and_no_output(tmp_path, capsys):
    bad = write(tmp_path, GOOD.replace("sag_m = 180.5", "sag_m = -1.0"))
    out = tmp_path / "out"
    assert main([str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "geometry.sag_m" in err[0]
    assert not out.exists() or not any(out.iterdir())


def test_span_past_the_cable_limit_is_an_input_error(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["model_c", "--main-span", "5300", "--out", str(out)]) == 2
    assert "geometry.main_span_m = 5300" in capsys.readouterr().err
    assert not out.exists() or not any(out.iterdir())


def test_unknown_scenario_and_stage(tmp_path, capsys):
    assert main(["no_such_bridge", "--out", str(tmp_path)]) == 2
    assert main(["great_belt", "--stages", "wind_tunnel", "--out", str(tmp_path)]) == 2
    assert "wind_tunnel" in capsys.readouterr().err
    assert not any(p.name == "great_belt" for p in tmp_path.iterdir())


def test_failed_stage_leaves_no_partial_results(tmp_path, monkeypatch):
    import bridge.cable_stage as stage

    def boom(*a, **k):
        raise RuntimeError("simulated failure")

    monkeypatch.setattr(stage, "cable_figures", boom)
    with pytest.raises(RuntimeError):
        main(["great_belt", "--stages", "cable", "--out", str(tmp_path), "--quiet"])
    assert list(tmp_path.iterdir()) == []


def test_user_scenario_with_reference_file(tmp_path):
    p = write(tmp_path, 'name = "my_bridge"\nreference = "great_belt"\nmain_span_m = 2500.0\n')
    s = load_scenario(p)
    assert s.name == "my_bridge" and s.geometry.main_span_m == 2500.0
