"""The aero stage: forced-motion cases that resume after a kill, and the chain to the flutter stage.

Tiny grids only (seconds): these check the machinery, not the aerodynamics (docs/aero.md has the
validation against Theodorsen and its status)."""

import numpy as np
import pytest

from bridge.aero.forced_motion import ForcedCase, run_case
from bridge.aero.presets import QUALITY, preset, section_polygons
from bridge.cfd.sections import Rectangle


class Killed(Exception):
    pass


@pytest.mark.parametrize("grid", ["single", pytest.param("overset", marks=pytest.mark.slow),
                                  pytest.param("single-sst", marks=pytest.mark.slow),
                                  pytest.param("overset-sst", marks=pytest.mark.slow)])
def test_a_killed_case_resumes_from_its_checkpoint_and_ends_with_the_same_numbers(tmp_path, grid):
    """Bit for bit: the checkpoint holds all the state (overset: both grids and the body grid's stream
    function of the last two steps, which the hole extrapolates; SST: k, omega and the eddy viscosity
    of the next step, on each grid). Overset and SST ~20 s each (slow), the laminar single grid a few
    seconds."""

    poly = section_polygons(Rectangle(10.0, 2.0))[0]
    case = ForcedCase("heave", (2.5,), (0.005,))
    q = preset("tiny", grid.removesuffix("-sst"))
    if grid.endswith("-sst"):
        q = q.with_(turbulence="sst", reynolds=1e7)
    whole = run_case(poly, case, q)
    ckpt = tmp_path / "case.h5"
    calls = []

    def kill_at_half(message):
        calls.append(message)
        if len(calls) == 5:
            raise Killed(message)

    with pytest.raises(Killed):
        run_case(poly, case, q, checkpoint=ckpt, checkpoint_every=50, progress=kill_at_half)
    assert ckpt.is_file()
    notes = []
    again = run_case(poly, case, q, checkpoint=ckpt, checkpoint_every=50, progress=notes.append)
    assert again.resumed_from_step > 0 and "resuming" in notes[0]
    assert again.resumed_from_step < whole.steps        # it did not start from the end either
    for name in ("t", "lift", "drag", "moment", "motion"):
        assert np.array_equal(getattr(again, name), getattr(whole, name)), name
    # a checkpoint of another case is not resumed
    other = run_case(poly, ForcedCase("heave", (2.5,), (0.01,)), q, checkpoint=ckpt, checkpoint_every=10_000)
    assert other.resumed_from_step == 0


def _section_scenario(path, name_mass):
    path.write_text(f'''kind = "section"
[section]
mass_per_length_kg_m = {name_mass}
inertia_per_length_kg_m2_m = 4.0e6
heave_frequency_hz = 0.12
pitch_frequency_hz = 0.30
deck_width_m = 30.0
[deck_section]
shape = "rectangle"
chord_m = 30.0
depth_m = 6.0
[aero]
quality = "tiny"
reduced_velocities = [2.5, 4.0]
[flutter]
aerodynamics = "cfd"
max_speed_m_s = 300.0
multimode = false
''')
    return path


@pytest.mark.slow  # ~10 s (four CFD cases): runs in CI with -m slow
def test_the_aero_stage_feeds_flutter_and_bridges_with_one_deck_share_it(tmp_path):
    from bridge.config import load_scenario
    from bridge.pipeline import plan_stages, run_stages
    from bridge.stages import RunOptions

    a = load_scenario(_section_scenario(tmp_path / "deck_a.toml", 43000.0))
    b = load_scenario(_section_scenario(tmp_path / "deck_b.toml", 50000.0))
    assert plan_stages(a, None) == ("aero", "flutter")
    options = RunOptions(cache=tmp_path / "cache")
    out_a = run_stages(a, None, options)
    aero = out_a["aero"].data
    assert aero.quality == "tiny" and aero.reduced_frequency.tolist() == pytest.approx([np.pi / 2, 2 * np.pi / 2.5])
    # the flutter stage used exactly the CFD's FRFs (the table reproduces them at the runs' K)
    h = aero.model.frf(aero.reduced_frequency, 50.0)
    for name in ("h_pu", "h_ptheta", "h_mu", "h_mtheta"):
        np.testing.assert_allclose(getattr(h, name), getattr(aero.frf, name), rtol=1e-10, atol=1e-12)
    assert out_a["flutter"].summary["flutter.aerodynamics"].startswith("cfd (rectangle, tiny")
    # the static runs (default -2, 0, 2 degrees) give the flutter model its lateral terms, quasi-steady
    assert aero.static.angles_deg.tolist() == [-2.0, 0.0, 2.0]
    qs = aero.static.quasi_steady()
    hr = aero.model.frf(aero.reduced_frequency, 50.0)
    np.testing.assert_allclose(hr.h_qr, -2j * aero.reduced_frequency * qs.drag_coefficient, rtol=1e-12)
    assert qs.drag_coefficient > 0.1 and out_a["aero"].summary["aero.static.drag_coefficient"] == qs.drag_coefficient
    # another bridge (other masses, other name) with the same deck: the aero result is the stored one
    out_b = run_stages(b, None, options)
    assert out_b["aero"].from_cache and not out_b["flutter"].from_cache
    np.testing.assert_array_equal(out_b["aero"].data.frf.h_pu, aero.frf.h_pu)
    # the cases left their checkpoints, so a re-run after a kill would resume
    assert len(list((tmp_path / "cache" / "aero-runs").glob("*.h5"))) == 4 + 3   # and the three static runs


def test_a_checkpoint_of_other_solver_code_is_not_resumed(monkeypatch):
    """The checkpoint's key holds the source of the solver: a changed CFD never continues an old run."""
    from bridge.aero import forced_motion
    from bridge.aero.forced_motion import case_key

    poly = section_polygons(Rectangle(10.0, 2.0))[0]
    case = ForcedCase("heave", (2.5,), (0.005,))
    before = case_key(poly, case, QUALITY["tiny"])
    monkeypatch.setattr(forced_motion, "code_digest", lambda modules: "edited")
    assert case_key(poly, case, QUALITY["tiny"]) != before
    # and it covers every kernel module the CFD runs, as does the aero stage's cache key: every module of
    # kernels/ but the FEM's (the SST's kernels.transport once was not covered, the O-grid's
    # kernels.curvilinear later; a list of the modules imported so far depended on the tests run before)
    import pkgutil

    import kernels
    from bridge.stages import STAGES

    seen = []
    monkeypatch.setattr(forced_motion, "code_digest", lambda modules: seen.extend(modules) or "x")
    case_key(poly, case, QUALITY["tiny"])
    used = [f"kernels.{m.name}" for m in pkgutil.iter_modules(kernels.__path__) if m.name != "fem"]
    assert "kernels.transport" in used and "kernels.curvilinear" in used
    for covers in (seen, STAGES["aero"].code):
        assert all(any(m == c or m.startswith(c + ".") for c in covers) for m in used), covers



def test_the_grid_option_is_checked_and_picks_the_overset_pair():
    from bridge.aero.options import AeroOptions
    from bridge.errors import InputError

    with pytest.raises(InputError, match="aero.grid.*single, overset"):
        AeroOptions(grid="chimera")
    assert preset("quick", "overset").grid.overset and not preset("quick").grid.overset
    with pytest.raises(InputError, match="aero.grid"):
        preset("quick", "chimera")


def test_cells_per_chord_puts_the_preset_on_another_grid_and_the_headline_loses_its_grid_record():
    """[aero] cells_per_chord: the same preset on a grid of the user's (a grid study), in the stage's key; the
    grid study's record of the preset does not apply to it, so the headline gives no corrected range."""
    from dataclasses import replace as dc_replace

    from bridge.aero.accuracy import grid_accuracy
    from bridge.aero.options import AeroOptions
    from bridge.aero.stage import scenario_preset
    from bridge.cache import stage_key
    from bridge.config import load_scenario
    from bridge.errors import InputError

    for bad in (4, 2001, 16.5, True, "24"):
        with pytest.raises(InputError, match="aero.cells_per_chord"):
            AeroOptions(cells_per_chord=bad)
    sc = load_scenario("great_belt")
    for grid in ("overset", "body_fitted"):
        finer = dc_replace(sc, aero=AeroOptions(grid=grid, cells_per_chord=24))
        section, q = scenario_preset(finer)
        assert q.name == "quick" and q.grid.cells_per_chord == 24
        assert scenario_preset(dc_replace(sc, aero=AeroOptions(grid=grid)))[1].grid.cells_per_chord == 16
        assert scenario_preset(finer, "tiny")[1].grid.cells_per_chord == 12   # --quick: a smoke run stays coarse
    keys = {stage_key("aero", dc_replace(sc, aero=AeroOptions(cells_per_chord=c)), {}, False) for c in (0, 16, 24)}
    assert len(keys) == 3
    for own in (0, 16):   # the preset's own grid
        assert grid_accuracy(section, AeroOptions(cells_per_chord=own), "quick", 1.05e8)[1] is not None
    text, err, _ = grid_accuracy(section, AeroOptions(cells_per_chord=24), "quick", 1.05e8)
    assert err is None and text.startswith("no grid study covers 'quick' on 24 cells per chord"), text


def test_the_sst_walls_option_is_checked_reaches_the_preset_and_the_stage_key():
    from dataclasses import replace as dc_replace

    from bridge.aero.options import AeroOptions
    from bridge.cache import stage_key
    from bridge.config import load_scenario
    from bridge.errors import InputError

    with pytest.raises(InputError, match="aero.sst_walls.*equilibrium, function, blended"):
        AeroOptions(sst_walls="log")
    with pytest.raises(InputError, match="aero.sst_walls"):
        preset("quick", "overset").with_(sst_walls="log")
    sc = load_scenario("great_belt")
    keys = {stage_key("aero", dc_replace(sc, aero=AeroOptions(sst_walls=walls)), {}, False)
            for walls in ("function", "blended", "equilibrium")}
    assert len(keys) == 3
    from bridge.aero.stage import preset_warnings
    from bridge.cfd.sections import great_belt_section

    sst = preset("quick", "overset").with_(turbulence="sst", reynolds=1e8)
    assert preset_warnings(sst, "quick", great_belt_section()) == ""
    blended = preset_warnings(sst.with_(sst_walls="blended"), "quick", great_belt_section())
    assert "under study" in blended and "lift slope negative" in blended


def test_cases_side_by_side_give_the_numbers_of_cases_one_after_the_other(tmp_path):
    """run_cases with two worker processes (each case on one core) returns, in the jobs' order, the same
    records bit for bit as the cases run one after the other here, and passes their progress lines on;
    the errors a worker raises cross the process boundary intact (they are picklable)."""
    import pickle

    from bridge.aero.forced_motion import StaticCase, run_cases
    from bridge.errors import ConvergenceError, DivergedError, InputError

    poly = section_polygons(Rectangle(10.0, 2.0))[0]
    q = QUALITY["tiny"].with_(static_duration=1.0)
    jobs = [(StaticCase(a), None, f"angle {a:g}") for a in (2.0, -1.0, 0.0)]
    lines = []
    apart = run_cases(poly, jobs, q, workers=2, progress=lines.append)
    here = run_cases(poly, jobs, q, workers=1)
    for a, b in zip(apart, here, strict=True):
        np.testing.assert_array_equal(a.lift, b.lift)
        np.testing.assert_array_equal(a.moment, b.moment)
    assert apart[0].lift.mean() != apart[1].lift.mean()   # the order is the jobs' (different angles)
    assert any(line.startswith("angle -1:") for line in lines) and any(line.startswith("angle 2:") for line in lines)
    for err in (InputError("aero.quality", "tiny", "too coarse"), ConvergenceError("x", 3, 1.0, 0.1),
                DivergedError("the CFD of heave", "NaN at t = 1")):
        back = pickle.loads(pickle.dumps(err))
        assert type(back) is type(err) and str(back) == str(err)


def test_a_multi_frequency_run_that_answers_nonlinearly_is_flagged():
    """The stage's check of a multi-frequency run (bridge.aero.stage.check_distortion): a moment linear in the
    pitch passes; one with a quadratic part that would give the lowest sine alone a second harmonic of 10 % (the
    Great Belt deck's single-frequency pitch runs carried 8-11 % at the thesis's amplitudes, docs/aero.md) is
    flagged with its share, on the terminal and in the stage's warning."""
    from types import SimpleNamespace

    from bridge.aero.forced_motion import ForcedCase
    from bridge.aero.stage import DISTORTION_LIMIT, check_distortion
    from bridge.stages import RunOptions

    case = ForcedCase.multi_frequency("pitch", (0.25, 0.5, 0.75), 0.0174)
    t = np.linspace(0.0, 4 * 2 * np.pi / 0.25, 4001)
    x = np.array([case.displacement(s) for s in t])
    said = []
    options = RunOptions(progress=said.append)
    sel = t >= 2 * 2 * np.pi / 0.25
    for eps, flagged in ((0.0, False), (0.2 / case.amplitudes[0], True)):   # eps a_1^2 / 2 = 0.1 a_1
        rec = SimpleNamespace(t=t, lift=5.0 * x + eps * 5.0 * x**2, moment=1.2 * x + eps * 1.2 * x**2)
        warning = check_distortion(rec, sel, case, "", options)
        assert bool(warning) == flagged, (eps, warning)
    assert "multi-frequency pitch run" in warning and "excitation = \"single\"" in warning
    assert len(said) == 1 and said[0].startswith("aero: WARNING")
    share = float(warning.split(" % ")[0].split()[-1]) / 100
    assert share > DISTORTION_LIMIT
