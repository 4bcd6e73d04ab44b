"""What a bridge engineer ran into with their own deck and the CFD chain (issue: a bridge engineer's own
deck), each checked through the real command line where the user met it.  Every test here failed on the
code before its fix (ab79c08)."""

from __future__ import annotations

import csv
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bridge.config import load_scenario
from bridge.errors import InputError

REPO = Path(__file__).resolve().parents[2]
SCANLAN_LINE = "# convention: vertical=down lift=down lateral=downwind drag=downwind pitch=nose_up reference_length=B\n"


def cli(*args: str, module: str = "bridge.scenario", cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True,
                          cwd=cwd or REPO, timeout=600)


def one_error_line(proc: subprocess.CompletedProcess) -> str:
    assert proc.returncode == 2, (proc.returncode, proc.stderr[-2000:])
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    return lines[0]


def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def theodorsen_csv(path: Path, reduced_velocities, bad_cell: tuple[int, int, str] | None = None) -> Path:
    """Theodorsen's derivatives (Scanlan's convention) at the given U/(fB); ``bad_cell`` (row, column, text)
    puts a text into one data cell."""
    from bridge.flutter.aerodynamics import Theodorsen
    from bridge.flutter.derivatives import derivatives_from_frf

    uv = np.asarray(reduced_velocities, dtype=float)
    K = 2 * np.pi / uv
    d = derivatives_from_frf(K, Theodorsen().frf(K, 1.0))
    names = ("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4")
    rows = [[repr(float(uv[i]))] + [repr(float(getattr(d, n)[i])) for n in names] for i in range(uv.size)]
    if bad_cell is not None:
        r, c, text = bad_cell
        rows[r][c] = text
    with path.open("w", newline="") as fh:
        fh.write(SCANLAN_LINE)
        w = csv.writer(fh)
        w.writerow(["reduced_velocity"] + [f"{n}*" for n in names])
        w.writerows(rows)
    return path


# ---------------------------------------------------------------- 2: "no flutter" where the data say nothing
def modal_with_table(tmp_path: Path, reduced_velocities) -> Path:
    theodorsen_csv(tmp_path / "deck.csv", reduced_velocities)
    text = (REPO / "scenarios" / "great_belt_thesis_modes.toml").read_text()
    text = text.replace('aerodynamics = "theodorsen"', 'aerodynamics = "derivatives"\nderivatives_path = "deck.csv"')
    return write(tmp_path / "narrow.toml", text)


def test_the_headline_never_says_no_flutter_where_the_data_do_not_reach(tmp_path):
    """Derivatives at U/(fB) 8-12 only: the pair's frequencies (0.128 and 0.294 Hz, a ratio of 2.3) are never
    spanned at once, and out of reach entirely below 32 m/s and above 109 m/s; the headline said "no flutter of
    any mode pair below 150 m/s"."""
    f = modal_with_table(tmp_path, np.linspace(8.0, 12.0, 9))
    proc = cli(str(f), "--out", str(tmp_path / "out"))
    assert proc.returncode == 0, proc.stderr[-2000:]
    head = proc.stdout.splitlines()[1]
    assert "no flutter of any mode pair" not in proc.stdout
    assert head.strip().startswith("NO FLUTTER SPEED FOUND, AND NONE RULED OUT below 150 m/s"), head
    assert "U/(fB) 8-12" in head and "below 32 m/s" in head and "above 109 m/s for S-V1+S-T1" in head, head
    # control: data spanning both frequencies at every speed searched: "no flutter" means none below 150 m/s
    g = modal_with_table(tmp_path, np.geomspace(0.1, 250.0, 60))
    proc = cli(str(g), "--out", str(tmp_path / "out2"))
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.splitlines()[1].strip().startswith("no flutter of any mode pair below 150 m/s"), proc.stdout


def test_speeds_below_the_flutter_speed_that_the_data_do_not_reach_are_named_in_the_headline():
    from bridge.results import headline

    s = {"flutter.critical_speed_m_s": 75.5, "flutter.frequency_hz": 0.2, "flutter.reduced_frequency": 0.52,
         "flutter.mode_pair": "S-V1+S-T1", "flutter.aerodynamics": "cfd",
         "flutter.data_reduced_velocity_min": 8.0, "flutter.data_reduced_velocity_max": 20.0,
         "flutter.data_span_every_pair": False, "flutter.blind_below_critical": "below 25 m/s"}
    lines = headline(s)
    assert lines[1].startswith("not searched below 25 m/s") and "U/(fB) 8-20" in lines[1], lines
    assert "not ruled out" in lines[1]


# ---------------------------------------------------------------- 3: a CFD V_c with its statement of trust
def test_a_cfd_flutter_speed_comes_with_its_grid_error_or_says_it_has_none():
    from bridge.aero.accuracy import GRID_STUDY, covered_by_study, grid_accuracy
    from bridge.aero.options import AeroOptions
    from bridge.cfd.sections import Rectangle, great_belt_section
    from bridge.results import headline

    deck, sst = great_belt_section(), AeroOptions()
    text, err, _ = grid_accuracy(deck, sst, "quick", 1.05e8)
    assert err == GRID_STUDY["quick"].vc_low_percent and "6-8 % below" in text
    base = {"flutter.critical_speed_m_s": 75.5, "flutter.frequency_hz": 0.2007, "flutter.reduced_frequency": 0.52,
            "flutter.mode_pair": "S-V1+S-T1", "flutter.aerodynamics": "cfd", "flutter.aerodynamics_option": "cfd",
            "aero.quality": "quick", "aero.turbulence": "sst", "aero.grid_study": text,
            "aero.vc_grid_error_low_percent": err[0], "aero.vc_grid_error_high_percent": err[1]}
    trust = headline(base)[1]
    assert "preset 'quick'" in trust and "6-8 % below" in trust and "about 80-82 m/s" in trust
    # a preset or a deck the study did not cover says so, and gives no corrected range
    for section, options, quality in ((deck, sst, "tiny"), (Rectangle(31.0, 6.2), sst, "quick"),
                                      (deck, AeroOptions(turbulence="laminar"), "quick")):
        text, err, _ = grid_accuracy(section, options, quality, 1.05e8)
        assert err is None and text.startswith("no grid study covers"), text
        line = headline({**base, "aero.quality": quality, "aero.grid_study": text,
                         "aero.vc_grid_error_low_percent": None, "aero.vc_grid_error_high_percent": None})[1]
        assert "no grid study covers" in line and "m/s" not in line.split("no grid study")[1].split(";")[0]
    assert not covered_by_study(deck, sst, 1e6)       # a Reynolds number the study did not run
    # the body-fitted pair has its own record, for 'quick' only (docs/aero.md: 16, 24, 32 and 40 cells per chord),
    # whose band reaches either side of the grid-converged V_c
    body = AeroOptions(grid="body_fitted")
    text, err, _ = grid_accuracy(deck, body, "quick", 1.05e8)
    assert err == (-1.5, 1.5) != GRID_STUDY["quick"].vc_low_percent and "within 1.5 % either side of" in text, text
    line = headline({**base, "flutter.critical_speed_m_s": 80.3, "aero.grid_study": text,
                     "aero.vc_grid_error_low_percent": err[0], "aero.vc_grid_error_high_percent": err[1]})[1]
    assert "about 79-82 m/s" in line, line
    # measured with the Great Belt's modes: another span keeps the record's words but gets no corrected V_c
    # (the up-scaled bridges' V_c moved differently from the Great Belt's between the grids: docs/flutter.md)
    for span, corrected in ((1624.0, True), (3000.0, False)):
        line = headline({**base, "flutter.critical_speed_m_s": 43.3, "scenario.main_span_m": span,
                         "aero.grid_study": text, "aero.vc_grid_error_low_percent": err[0],
                         "aero.vc_grid_error_high_percent": err[1]})[1]
        assert ("grid-converged V_c about 43-44 m/s" in line) is corrected, line
        assert ("1624 m bridge's modes, not this 3000 m one's" in line) is not corrected, line
    narrow = headline({**base, "flutter.critical_speed_m_s": 80.1, "aero.vc_grid_error_low_percent": 0.0,
                       "aero.vc_grid_error_high_percent": 0.3})[1]
    assert narrow.endswith("grid-converged V_c about 80 m/s"), narrow   # a band within one m/s: one number
    for quality in ("standard", "fine"):
        text, err, _ = grid_accuracy(deck, body, quality, 1.05e8)
        assert err is None and text.startswith(f"no grid study covers the '{quality}' preset on the body-fitted grid")
    assert covered_by_study(deck, body, 1.05e8) and not covered_by_study(deck, body, 5.2e7)   # run at 1.05e8 only
    text, err, _ = grid_accuracy(Rectangle(31.0, 6.2), body, "quick", 1.05e8)
    assert err is None and "on the body-fitted pair the same preset's V_c lies within 1.5 % either side" in text, text
    # the other aerodynamics name themselves
    theo = headline({**base, "flutter.aerodynamics_option": "theodorsen"})[1]
    assert theo.startswith("aerodynamics: Theodorsen's thin plate") and "not the deck's own" in theo


# ------------------------------------------------------------------------------ 4: overrides on a reference bridge
def test_a_reference_bridge_takes_overrides_of_any_key_and_scales_afterwards(tmp_path):
    gb = load_scenario("great_belt")
    f = write(tmp_path / "wide.toml", 'reference = "great_belt"\nmain_span_m = 1624.0\n'
              "[girder]\nwidth_m = 40.0\nmass_per_length_kg_m = 16000.0\n"
              '[deck_section]\nshape = "streamlined_box"\nchord_m = 40.0\n'
              "[flutter]\nmax_speed_m_s = 200.0\n")
    s = load_scenario(f)
    assert s.girder.width_m == 40.0 and s.girder.mass_per_length_kg_m == 16000.0
    assert s.girder.i_vertical_m4 == gb.girder.i_vertical_m4 and s.cable == gb.cable   # the rest is the reference's
    assert s.flutter.max_speed_m_s == 200.0 and s.flutter.aerodynamics == gb.flutter.aerodynamics  # merged
    assert s.flutter.quasi_steady == gb.flutter.quasi_steady and s.aero == gb.aero
    # up-scaled afterwards: the heavier girder needs more cable (Eq 1.2)
    big = load_scenario(write(tmp_path / "wide_3000.toml", f.read_text().replace("1624.0", "3000.0")))
    ref = load_scenario("model_b")
    assert big.geometry.main_span_m == 3000.0 and big.girder.width_m == 40.0
    assert big.cable.area_m2 > ref.cable.area_m2 * 1.05
    # a deck of another shape replaces the reference's section whole
    plate = load_scenario(write(tmp_path / "plate.toml", 'reference = "great_belt"\nmain_span_m = 1624.0\n'
                                '[deck_section]\nshape = "flat_plate"\nchord_m = 31.0\nthickness_m = 0.6\n'))
    assert plate.deck_section.name == "flat_plate"
    # a typo in a key or a table is one line naming it
    for text, key in (("[girder]\nwidht_m = 40.0\n", "girder.widht_m"), ("[girdr]\nwidth_m = 40.0\n", "girdr"),
                      ('kind = "section"\n', "kind")):
        with pytest.raises(InputError) as err:
            load_scenario(write(tmp_path / "typo.toml", 'reference = "great_belt"\nmain_span_m = 1624.0\n' + text))
        assert err.value.key == key, err.value


def test_a_chain_of_references_scales_once_from_the_full_bridge(tmp_path):
    """A file naming Model B and a span of 4000 m is Model C: the rules apply once (the extra cross beams of
    Model B were counted again on top of Model C's)."""
    f = write(tmp_path / "from_b.toml", 'reference = "model_b"\nmain_span_m = 4000.0\n')
    s, c = load_scenario(f), load_scenario("model_c")
    assert s.pylon == c.pylon and s.cable == c.cable and s.geometry == c.geometry


# ------------------------------------------------------------------------------ 5: a CFD deck wider than the structure
@pytest.mark.slow   # ~4 s (runs of the command): runs in CI with -m slow
def test_a_cfd_deck_of_another_width_than_the_girder_is_refused_before_any_work(tmp_path):
    wide = write(tmp_path / "wide_deck.toml", 'reference = "great_belt"\nmain_span_m = 1624.0\n'
                 '[deck_section]\nshape = "streamlined_box"\nchord_m = 40.0\n')
    line = one_error_line(cli(str(wide), "--stages", "aero", "--quality", "tiny", "--out", str(tmp_path / "out")))
    assert line.startswith("error: deck_section.chord_m = 40.0") and "girder.width_m = 31 m" in line
    # the girder widened and no [deck_section]: the CFD's deck would be the 31 m Great Belt box
    girder = write(tmp_path / "wide_girder.toml", 'reference = "great_belt"\nmain_span_m = 1624.0\n'
                   "[girder]\nwidth_m = 40.0\n")
    line = one_error_line(cli(str(girder), "--stages", "aero", "--quality", "tiny", "--out", str(tmp_path / "out")))
    assert "deck_section" in line and "B = 31 m" in line and "girder.width_m = 40 m" in line
    assert not (tmp_path / "out").exists()
    # with Theodorsen the CFD's deck is not used: no objection
    assert cli(str(girder), "--aerodynamics", "theodorsen", "--stages", "cable", "--quick", "--quiet",
               "--out", str(tmp_path / "out")).returncode == 0


# ------------------------------------------------------------------------------ 6: a bad derivative table, found first
def test_a_bad_derivative_table_stops_before_any_stage_with_its_line_and_column(tmp_path):
    theodorsen_csv(tmp_path / "deck.csv", np.linspace(2.0, 40.0, 12), bad_cell=(4, 3, "n/a"))
    f = write(tmp_path / "measured.toml", 'reference = "great_belt"\nmain_span_m = 1624.0\n'
              '[flutter]\naerodynamics = "derivatives"\nderivatives_path = "deck.csv"\n')
    out = tmp_path / "out"
    line = one_error_line(cli(str(f), "--quick", "--out", str(out)))
    # the fifth data row is line 7 of the file (convention line, header), its fourth cell is H3*
    assert "line 7, column H3" in line and "'n/a'" in line and "must be a number" in line, line
    assert not out.exists()   # nothing written: no result folder, no cache entries


# ------------------------------------------------------------------------------ 7: --quality with --quick
def test_quick_and_a_cfd_preset_are_not_mixed(tmp_path):
    line = one_error_line(cli("great_belt", "--quick", "--quality", "fine", "--out", str(tmp_path)))
    assert "--quality = 'fine'" in line and "--quick" in line
    assert not list(tmp_path.iterdir())


# ------------------------------------------------------------------------------ 9: smaller things
@pytest.mark.parametrize("key, values, named", [
    ("reduced_velocities", [-3.0], "aero.reduced_velocities[0]"),
    ("static_angles_deg", [45.0], "aero.static_angles_deg[0]"),
])
def test_a_one_value_list_is_answered_about_the_value(key, values, named):
    from bridge.aero.options import AeroOptions

    with pytest.raises(InputError) as err:
        AeroOptions(**{key: tuple(values)})
    assert err.value.key == named and "allowed range" in err.value.allowed


def test_progress_gives_the_whole_runs_time_left():
    from bridge.aero.forced_motion import ForcedCase, RunProgress
    from bridge.aero.presets import preset

    q = preset("tiny")
    cases = [ForcedCase.thesis("heave", 0.5), ForcedCase.thesis("pitch", 0.5), ForcedCase.thesis("heave", 1.0)]
    jobs = [(c, None, f"case {i}") for i, c in enumerate(cases)]
    lines: list[str] = []
    run = RunProgress(jobs, q, workers=2, sink=lines.append)
    t_end = cases[0].end_time(q)
    run(f"case 0: t = {0.1 * t_end:.4g} of {t_end:.4g} (10 %), 10 steps, about 9 s left")
    assert lines[-1].endswith("about 9 s left")              # no rate yet: nothing to say of the run
    run(f"case 0: t = {0.2 * t_end:.4g} of {t_end:.4g} (20 %), 20 steps, about 8 s left")
    m = re.search(r"\(all 3 cases: about (\d+) s left\)$", lines[-1])
    assert m, lines[-1]
    run.finished("case 0")
    run(f"case 1: resuming at t = {0.5 * t_end:.2f} (step 50) from x.h5")
    assert "all 3 cases" in lines[-1]


def test_a_sweep_says_what_each_case_found(tmp_path):
    proc = cli("thin_plate_section", "--vary", "flutter.max_speed_m_s=180", "--workers", "1",
               "--out", str(tmp_path), module="bridge.sweep")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert re.search(r"\[1/1\] thin_plate_section__flutter.max_speed_m_s=180: done: flutter speed V_c = \d+\.\d m/s",
                     proc.stderr), proc.stderr


def test_the_readme_rerun_of_one_stage_is_a_command_that_works(tmp_path):
    """README: "so `--stages flutter ...` after a full run takes a second" - the command it shows must run
    into the folder of that full run (it needed --overwrite, which the sentence left out)."""
    readme = (REPO / "README.md").read_text()
    m = re.search(r"so `(--stages flutter[^`]*)` after a full run", readme)
    assert m, "README no longer shows the one-stage rerun"
    base = ["great_belt_thesis_modes", "--quiet", "--out", str(tmp_path)]   # a full run of its one stage
    assert cli(*base).returncode == 0
    proc = cli(*base, *m.group(1).split())
    assert proc.returncode == 0, proc.stderr[-1000:]


# ------------------------------------------------------------------------------ the main job is the thesis's chain
def test_the_main_job_takes_the_decks_aerodynamics_from_the_cfd():
    from bridge.pipeline import plan_stages

    for name in ("great_belt", "model_a", "model_b", "model_c"):
        s = load_scenario(name)
        assert s.flutter.aerodynamics == "cfd" and s.aero.turbulence == "sst" and s.aero.quality == "quick"
        assert plan_stages(s, None) == ("cable", "fem", "aero", "flutter")
    from bridge.config import with_aerodynamics

    quick = with_aerodynamics(load_scenario("great_belt"), "theodorsen")
    assert plan_stages(quick, None) == ("cable", "fem", "flutter")
    with pytest.raises(InputError) as err:   # a model whose inputs the scenario lacks: named
        with_aerodynamics(load_scenario("great_belt_thesis_modes"), "quasi_steady")
    assert err.value.key == "--aerodynamics"
