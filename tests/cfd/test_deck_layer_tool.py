"""tools/deck_layer.py: the Great Belt deck's boundary layer over its top.  Bad input stops it before any run;
the geometry and the law-of-the-wall eddy viscosity it compares with have closed forms; a short run reads the
first free cells above the top; and (slow) at the deck's Reynolds number the equilibrium wall's layer is
turbulent from the nose where the wall function's is laminar (docs/cfd.md, "Turbulence model and walls")."""

import json
import math

import numpy as np
import pytest
from cfd_helpers import load_tool


@pytest.mark.parametrize("argv, option", [(["--angle", "12"], "--angle"), (["--duration", "1"], "--duration"),
                                          (["--speed", "0"], "--speed"), (["--threads", "0"], "--threads"),
                                          (["--quality", "superb"], "--quality"),
                                          (["--sst-walls", "resolved"], "--sst-walls"),
                                          (["--section", "box"], "--section"),
                                          (["--nose-height", "1.5"], "--nose-height"),
                                          (["--section", "plate", "--nose-height", "1"], "--nose-height"),
                                          (["--bottom-flat", "1"], "--bottom-flat"),
                                          (["--bottom-flat", "-0.1"], "--bottom-flat"),
                                          (["--section", "plate", "--bottom-flat", "0.3"], "--bottom-flat"),
                                          (["--cells-per-chord", "4"], "--cells-per-chord"),
                                          (["--background-coarsening", "0"], "--background-coarsening"),
                                          (["--body-margin", "0"], "--body-margin")])
def test_bad_input_exits_2_naming_the_option_and_writes_nothing(tmp_path, capsys, argv, option):
    tool = load_tool("deck_layer")
    out = tmp_path / "layer"
    with pytest.raises(SystemExit) as e:
        tool.main(argv + ["--out", str(out)])
    assert e.value.code == 2
    assert option in capsys.readouterr().err
    assert not out.exists()


def test_distance_and_top_of_a_polygon():
    tool = load_tool("deck_layer")
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    pts = np.array([[0.5, 1.25], [2.0, 2.0], [0.5, 0.5], [-0.3, 0.5]])
    assert tool.distance_to_polygon(pts, square) == pytest.approx([0.25, math.sqrt(2.0), 0.5, 0.3])
    roof = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.5]])        # top: y = x up to 0.5, then 1 - x
    top = tool.top_of(roof, np.array([0.1, 0.5, 0.8, 1.5]))
    assert top[:3] == pytest.approx([0.1, 0.5, 0.2]) and np.isnan(top[3])


def test_the_plate_control_and_the_deck_outlines():
    tool = load_tool("deck_layer")
    (plate,) = tool.section_polygons("plate")
    v = plate.vertices
    assert np.ptp(v[:, 0]) == pytest.approx(1.0) and np.ptp(v[:, 1]) == pytest.approx(tool.PLATE_THICKNESS)
    assert tool.top_of(v, np.array([-0.3, 0.0, 0.4])) == pytest.approx([tool.PLATE_THICKNESS / 2] * 3)
    (deck,) = tool.section_polygons("great_belt")
    assert np.ptp(deck.vertices[:, 0]) == pytest.approx(1.0) and np.ptp(deck.vertices[:, 1]) == pytest.approx(4.4 / 31)
    (roofline,) = tool.section_polygons("great_belt", nose_height=1.0)   # the nose on the roof: a straight top
    crown, edge = 2.2 / 31, 2.2 / 31 - 0.02 * 0.5
    assert tool.top_of(roofline.vertices, np.array([-0.5, -0.25, 0.0])) == pytest.approx([edge, 0.5 * (edge + crown),
                                                                                            crown])
    # a shallower bottom: the flat part 0.3 of the chord wide, the rear panel rising from x = 0.15 to the nose
    (shallow,) = tool.section_polygons("great_belt", bottom_flat=0.3)
    beneath = shallow.vertices * np.array([1.0, -1.0])                 # the bottom seen as a top
    nose = -2.2 / 31 + 0.8 * (4.4 / 31 - 0.01)
    assert tool.top_of(beneath, np.array([0.0, 0.15, 0.325, 0.5])) == pytest.approx(
        [2.2 / 31, 2.2 / 31, 0.5 * (2.2 / 31 - nose), -nose])
    assert math.degrees(math.atan((nose + 2.2 / 31) / 0.35)) == pytest.approx(16.8, abs=0.1)


def test_the_pressure_load_sums_to_the_normal_force_and_its_moment_about_mid_chord():
    """Midpoint sums over the columns, exact for loads linear in x: a uniform load of 1 gives C_N = 1 and no
    moment; the same on the front half only, C_N = 1/2 at the quarter chord: C_M = 1/2 x 1/4, nose-up."""
    tool = load_tool("deck_layer")
    n = 40
    x = ((np.arange(n) + 0.5) / n).tolist()
    top = {"x_from_nose": x, "first_cell_cp": [-0.3] * n}           # suction over the top
    uniform = tool.pressure_loads(top, {"first_cell_cp": [0.7] * n}, 1.0 / n)
    assert uniform["C_N_pressure"] == pytest.approx(1.0) and uniform["C_M_pressure"] == pytest.approx(0.0, abs=1e-12)
    front = tool.pressure_loads(top, {"first_cell_cp": [0.7 if xi < 0.5 else -0.3 for xi in x]}, 1.0 / n)
    assert front["C_N_pressure"] == pytest.approx(0.5) and front["C_M_pressure"] == pytest.approx(0.125)
    assert front["normal_load"][:2] == pytest.approx([1.0, 1.0]) and front["normal_load"][-1] == pytest.approx(0.0)


def test_the_displacement_thickness_of_a_linear_layer_is_half_its_thickness():
    """u = (y - top) / a up to a, then 1: delta* = a / 2, exact on the trapezoid when a cell centre lies at a;
    a uniform stream over the wall gives half the gap to the first centre (u = 0 on the wall)."""
    tool = load_tool("deck_layer")
    y = np.arange(-0.5, 1.0, 0.01) + 0.005                         # centres at 0.005, 0.015, ...
    top, a = 0.002, 0.043                                          # a cell centre at top + a = 0.045
    u = np.clip((y - top) / a, 0.0, 1.0)
    assert tool.displacement_thickness(y, u, top, 0.1) == pytest.approx(a / 2, rel=1e-12)
    assert tool.displacement_thickness(y, np.ones_like(y), top, 0.1) == pytest.approx(0.5 * (0.005 - top))
    assert tool.displacement_thickness(y, 2 * u, top, 0.1) == pytest.approx(a / 2, rel=1e-12)   # u / u_e


def test_the_first_free_cell_lies_above_the_surface_and_outside_the_forcing():
    tool = load_tool("deck_layer")
    y = (np.arange(10) - 4.5) * 0.1
    forced = np.zeros((10, 3), dtype=bool)
    forced[3:7, :] = True
    forced[7, 2] = True
    # column 0: surface at 0.12 (row 6's centre 0.15 lies above it but is forced); column 1: a free cell below
    # the surface (row 2) must not count; column 2: the forcing one row further up
    rows = tool.first_free_rows(forced, y, np.array([0, 1, 2]), np.array([0.12, 0.12, 0.12]))
    assert rows.tolist() == [7, 7, 8]


def test_the_laws_eddy_viscosity_is_kappa_u_tau_d_in_the_log_layer_and_vanishes_in_the_sublayer():
    tool = load_tool("deck_layer")
    nu, u_tau = 1e-6, 0.05
    d = np.array([1e-1, 1.0])                                     # y+ = 5e3 and 5e4
    speed = u_tau * (np.log(d * u_tau / nu) / 0.41 + 5.0)        # the log law, which Spalding's joins
    assert tool.law_eddy_viscosity(speed, d, nu) == pytest.approx(0.41 * u_tau * d, rel=0.01)
    d_sub = np.array([1e-5])                                      # y+ = 0.5: u+ = y+
    law = tool.law_eddy_viscosity(u_tau * d_sub * u_tau / nu, d_sub, nu)
    assert law[0] < 1e-3 * nu


def test_a_short_run_reads_the_layer_over_the_top(tmp_path):
    tool = load_tool("deck_layer")
    out = tmp_path / "layer"
    assert tool.main(["--duration", "2", "--threads", "1", "--cells-per-chord", "12", "--background-coarsening", "3",
                      "--body-margin", "2", "--out", str(out)]) == 0
    got = json.loads((out / "layer.json").read_text())
    # the grid as asked, not the preset's 16 cells per chord over a background of 8: the background's cells are
    # 1/4 chord, and the body grid, reaching 2 B beyond the deck (1 + 2 x 2 chords at 12 cells, 2.5 chords upstream
    # of the deck's centre), moves the inflow from 3 to 4.5 chords upstream (8 background cells clear of it):
    # 4.5 + 20 chords at 4 cells
    assert got["cells_per_chord"] == 12 and got["background_coarsening"] == 3 and got["body_margin"] == 2.0
    assert got["grids"].startswith("98 x ") and " body 60 x " in got["grids"]
    record = np.array(got["C_L_record"])             # one value per 0.1 B/V, t = 0 to 2
    assert record.shape == (21,) and np.isfinite(record).all()
    assert abs(record[11:].mean() - got["C_L"]) < 0.01   # the second half's mean, from every step: the same lift
    assert (out / "layer.png").stat().st_size > 1000
    x = np.array(got["x_from_nose"])
    assert x.min() > 0 and x.max() < 1 and len(x) == got["cells_per_chord"]
    assert min(got["first_cell_distance"]) > 0 and max(got["first_cell_distance"]) < 0.1
    assert min(got["first_cell_nut_over_nu"]) > -1e-6
    assert np.all(np.array(got["largest_nut_over_nu"]) >= np.array(got["first_cell_nut_over_nu"]) - 1e-9)
    profile = np.array(got["u_at_heights"])
    assert profile.shape == (len(x), len(got["heights"])) and np.isfinite(profile).all()
    assert profile[:, -1].min() > 0.5          # 0.1 B above the top: outside the layer after 2 B/V
    ratio = np.array(got["first_cell_omega_over_log"])
    assert ratio.shape == x.shape and np.isfinite(ratio).all() and ratio.min() > 0
    assert 0 < got["C_D"] < 1 and abs(got["C_L"]) < 1 and abs(got["C_M"]) < 1
    bottom = got["bottom"]                    # the side below, read as the top of the mirrored section
    assert bottom["x_from_nose"] == got["x_from_nose"]
    assert 0 < min(bottom["first_cell_distance"]) and max(bottom["first_cell_distance"]) < 0.1
    assert np.array(bottom["u_at_heights"])[:, -1].min() > 0.5
    thickness = np.array(got["displacement_thickness"])
    assert thickness.shape == x.shape and thickness.min() > 0 and thickness.max() < 0.1
    assert len(got["normal_load"]) == len(x) and np.isfinite(got["normal_load"]).all()
    assert got["C_N_pressure"] * got["C_L"] > 0        # the lift's sign from the pressure samples


@pytest.mark.slow   # 5 s; the default run keeps the tool's short run
def test_the_plate_held_at_plus_and_minus_an_angle_reads_the_same_layer_on_opposite_sides(tmp_path):
    """The bottom is read as the top of the mirrored section: a symmetric plate at +2 degrees shows under its
    bottom what it shows over its top at -2 (to round-off), with the lift and moment reversed."""
    tool = load_tool("deck_layer")
    got = {}
    for angle in ("2", "-2"):
        out = tmp_path / angle
        assert tool.main(["--section", "plate", "--angle", angle, "--duration", "2", "--threads", "1",
                          "--out", str(out)]) == 0
        got[angle] = json.loads((out / "layer.json").read_text())
    up, down = got["2"], got["-2"]
    assert up["C_L"] > 0.05 and down["C_L"] == pytest.approx(-up["C_L"], rel=1e-6)
    assert down["C_M"] == pytest.approx(-up["C_M"], rel=1e-6, abs=1e-9)
    for key in ("C_N_pressure", "C_M_pressure"):           # the pressure read on both sides, mirrored
        assert down[key] == pytest.approx(-up[key], rel=1e-6, abs=1e-9), key
    assert np.array(down["bottom"]["first_cell_cp"]) == pytest.approx(np.array(up["first_cell_cp"]), rel=1e-6,
                                                                        abs=1e-9)
    for key in ("first_cell_u", "first_cell_distance", "u_at_heights", "first_cell_nut_over_nu",
                "displacement_thickness"):
        assert np.array(down["bottom"][key]) == pytest.approx(np.array(up[key]), rel=1e-6, abs=1e-9), key
    assert not np.allclose(up["first_cell_u"], up["bottom"]["first_cell_u"], rtol=1e-3)   # the sides differ


@pytest.mark.slow
def test_at_the_decks_reynolds_number_the_equilibrium_layer_is_turbulent_from_the_nose_and_the_wall_functions_not(
        tmp_path):
    """The finding the stage's default rests on (docs/aero.md): held at 2 degrees for 20 B/V on `quick`, over 0.1-0.8
    B the equilibrium wall's first free cells carry hundreds to thousands of nu, the wall function's below nu."""
    tool = load_tool("deck_layer")
    share = {}
    for walls in ("equilibrium", "function"):
        out = tmp_path / walls
        assert tool.main(["--sst-walls", walls, "--threads", "1", "--out", str(out)]) == 0
        got = json.loads((out / "layer.json").read_text())
        x = np.array(got["x_from_nose"])
        front = (x > 0.08) & (x < 0.8)
        nut = np.array(got["first_cell_nut_over_nu"])[front]
        share[walls] = np.array(got["share_of_law"], dtype=float)[front]
        if walls == "equilibrium":
            assert nut.min() > 100, nut
        else:
            assert nut.max() < 1, nut
    assert share["equilibrium"].min() > 100 * share["function"].max()
