"""Three-grid convergence (bridge.aero.accuracy.three_grids) and the tool that applies it to runs on three grids
(tools/grid_convergence.py)."""

import importlib.util
import json
import math
from pathlib import Path
from types import SimpleNamespace

import h5py
import numpy as np
import pytest

from bridge.aero.accuracy import three_grids

TOOL = Path(__file__).resolve().parents[2] / "tools" / "grid_convergence.py"


@pytest.mark.parametrize("cells", [(32, 24, 16), (40, 32, 16), (30, 10, 9), (40, 36, 12)])
@pytest.mark.parametrize("order", [0.5, 1.7, 2.0])
def test_three_grids_recovers_the_order_and_the_limit_of_a_power_law_on_unequal_ratios(order, cells):
    """phi(h) = phi* + C h^p on three grids refined by unequal ratios (32, 24, 16 as the deck's study; the others
    with the larger ratio on either side): the order and phi* come back to round-off, and the index is the
    formula's."""
    phi = [2.0 + 3.0 * (1.0 / n) ** order for n in cells]
    g = three_grids(phi, cells)
    assert g.order == pytest.approx(order, rel=1e-9)
    assert g.extrapolated == pytest.approx(2.0, rel=1e-9)
    r21 = cells[0] / cells[1]
    assert g.gci_fine == pytest.approx(1.25 * abs((phi[0] - phi[1]) / phi[0]) / (r21 ** order - 1), rel=1e-9)
    assert g.monotone and g.converging
    assert g.off_extrapolated(2) == pytest.approx((phi[2] - 2.0) / 2.0, rel=1e-6)


def test_three_grids_against_celik_et_al_2008_table_1():
    """Celik et al. 2008 (J. Fluids Eng. 130, 078001), Table 1, first column: grids of 18 000, 8 000 and 4 500
    cells in 2D (r21 = 1.5, r32 = 1.333), phi = 6.063, 5.972, 5.863: p = 1.53, phi_ext = 6.1685,
    GCI_fine = 2.2 %, e_ext = 1.7 %."""
    g = three_grids((6.063, 5.972, 5.863), tuple(math.sqrt(n) for n in (18000, 8000, 4500)))
    assert round(g.order, 2) == 1.53
    assert round(g.extrapolated, 4) == 6.1685
    assert round(100 * g.gci_fine, 1) == 2.2
    assert round(100 * abs(g.off_extrapolated(0)), 1) == 1.7


def test_three_grids_says_when_the_grids_do_not_converge():
    diverging = three_grids((1.0, 1.2, 1.25), (32, 24, 16))   # the finer change is the larger
    assert not diverging.converging and math.isnan(diverging.order) and math.isnan(diverging.extrapolated)
    # a negative order (phi grows without bound as h shrinks), whose changes still shrink on these ratios: no
    # positive order fits (Celik et al.'s |...| alone would report one)
    away = three_grids([10.0 + 3.0 * (1.0 / n) ** -0.3 for n in (32, 24, 16)], (32, 24, 16))
    assert not away.converging and math.isnan(away.order)
    oscillating = three_grids((1.0, 1.05, 0.9), (32, 24, 16))   # no order: only how far apart the three lie
    assert not oscillating.monotone and not oscillating.converging and math.isnan(oscillating.order)
    assert oscillating.spread == pytest.approx(0.15)
    flat = three_grids((1.0, 1.0, 1.1), (32, 24, 16))
    assert math.isnan(flat.order)
    for values, cells in (((1, 2), (3, 2, 1)), ((1, 2, 3), (16, 24, 32)), ((1, math.nan, 2), (3, 2, 1))):
        with pytest.raises(ValueError, match="three_grids"):
            three_grids(values, cells)


def _run_folder(root: Path, name: str, cells: int, scale: float, vc: float, quality: str = "quick") -> Path:
    """A run's output folder as python -m bridge.scenario writes it, with only what the tool reads."""
    folder = root / name
    folder.mkdir()
    U = np.array([20.0, 16.0, 12.57, 8.0])
    with h5py.File(folder / "results.h5", "w") as f:
        f["aero/reduced_velocity"] = U
        for k, n in enumerate(("H1", "H2", "H3", "H4", "A1", "A2", "A3", "A4")):
            f[f"aero/derivatives/{n}"] = (k + 1) * scale * U
    summary = {"scenario.name": name, "aero.cells_per_chord": cells, "aero.section": "box", "aero.quality": quality,
               "aero.reynolds": 1e8, "aero.turbulence": "sst", "aero.sst_walls": "resolved", "aero.grid": "body_fitted",
               "aero.reduced_velocity_min": 8.0, "aero.reduced_velocity_max": 20.0,
               "flutter.aerodynamics_option": "cfd", "flutter.critical_speed_m_s": vc, "flutter.frequency_hz": 0.2,
               "flutter.mode_pair": "S-V1+S-T1", "flutter.pair_S-V1+S-T1.critical_speed_m_s": vc,
               "flutter.pair_SS-V1+SS-T1.critical_speed_m_s": None}
    (folder / "summary.json").write_text(json.dumps(summary))
    return folder


@pytest.fixture
def _tool(capsys):
    """tools/grid_convergence.py's main in this process (a subprocess per call costs a second of imports):
    returncode, stdout, stderr as a run's."""
    spec = importlib.util.spec_from_file_location("grid_convergence", TOOL)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)

    def run(*args):
        try:
            code = mod.main([str(a) for a in args])
        except SystemExit as stop:   # argparse's own errors
            code = stop.code
        out = capsys.readouterr()
        return SimpleNamespace(returncode=code, stdout=out.out, stderr=out.err)
    return run


def test_the_tool_reports_the_derivatives_and_v_c_of_three_runs(tmp_path, _tool):
    """Derivatives and V_c on a power law in the grid (order 2, limit 80 m/s): the tool's order, extrapolation
    and the coarsest grid's distance from it are the closed form's."""
    vc = {n: 80.0 - 200.0 / n ** 2 for n in (16, 24, 32)}
    runs = [_run_folder(tmp_path, f"gb{n}", n, 1.0 + 1.0 / n ** 2, vc[n]) for n in (16, 24, 32)]
    out = tmp_path / "gc.json"
    r = _tool(*runs, "--out", out)
    assert r.returncode == 0, r.stderr
    data = json.loads(out.read_text())
    assert data["cells_per_chord"] == [32, 24, 16]
    t = data["critical_speed_m_s"]["governing"]["three_grids"]
    assert t["order"] == pytest.approx(2.0, rel=1e-9) and t["extrapolated"] == pytest.approx(80.0, rel=1e-12)
    assert t["coarsest_off_extrapolated"] == pytest.approx(vc[16] / 80.0 - 1.0, rel=1e-9)
    assert list(data["critical_speed_m_s"]["pairs"]) == ["S-V1+S-T1"]   # a pair without flutter on a grid: left out
    row = next(x for x in data["derivatives"] if x["derivative"] == "A2" and x["reduced_velocity"] == 20.0)
    assert row["change_finest"] == pytest.approx((1 + 1 / 32 ** 2) / (1 + 1 / 24 ** 2) - 1, rel=1e-9)
    assert row["order"] == pytest.approx(2.0, rel=1e-6) and row["signs_kept"]
    assert "observed order 2.00, extrapolated 80.00" in r.stdout
    slow = [_run_folder(tmp_path, f"slow{n}", n, 1.0, 80.0 - 20.0 / n ** 0.3) for n in (16, 24, 32)]
    r = _tool(*slow, "--out", tmp_path / "slow.json")
    assert "observed order 0.30 (an order below 0.5: the extrapolation means little)" in r.stdout, r.stdout


def test_the_tool_gives_no_order_where_the_flutter_speed_oscillates(tmp_path, _tool):
    """The deck's own sequence (docs/aero.md): 80.4, 80.9, 80.8 m/s on 16, 24 and 32 cells."""
    runs = [_run_folder(tmp_path, f"gb{n}", n, 1.0, v) for n, v in ((16, 80.40), (24, 80.92), (32, 80.81))]
    out = tmp_path / "gc.json"
    r = _tool(*runs, "--out", out)
    assert r.returncode == 0, r.stderr
    line = "governing V_c: 80.81, 80.92, 80.40; no observed order (not monotone); the three lie within 0.6 %"
    assert line in r.stdout
    t = json.loads(out.read_text())["critical_speed_m_s"]["governing"]["three_grids"]
    assert t["order"] is None and t["extrapolated"] is None and not t["monotone"]


def test_the_tool_refuses_runs_that_differ_in_more_than_the_grid(tmp_path, _tool):
    a = _run_folder(tmp_path, "a", 16, 1.0, 80.0)
    b = _run_folder(tmp_path, "b", 24, 1.0, 81.0, quality="standard")
    out = tmp_path / "gc.json"
    r = _tool(a, b, "--out", out)
    assert r.returncode == 2 and "aero.quality" in r.stderr and not out.exists()
    c = _run_folder(tmp_path, "c", 16, 1.0, 80.0)
    r = _tool(a, c, "--out", out)
    assert r.returncode == 2 and "grids must differ" in r.stderr and not out.exists()
    r = _tool(a, tmp_path / "missing", "--out", out)
    assert r.returncode == 2 and "no results.h5" in r.stderr and not out.exists()
    d = _run_folder(tmp_path, "d", 24, 1.0, 81.0)
    with h5py.File(d / "results.h5", "a") as f:   # other reduced velocities
        f["aero/reduced_velocity"][0] = 19.0
    r = _tool(a, d, "--out", out)
    assert r.returncode == 2 and "reduced velocities" in r.stderr and not out.exists()
    e = _run_folder(tmp_path, "e", 32, 1.0, 81.0)
    summary = json.loads((e / "summary.json").read_text())
    (e / "summary.json").write_text(json.dumps({**summary, "scenario.main_span_m": 3000.0}))   # another bridge
    r = _tool(a, e, "--out", out)
    assert r.returncode == 2 and "scenario.main_span_m" in r.stderr and not out.exists()
    (e / "summary.json").write_text("{not json")
    r = _tool(a, e, "--out", out)
    assert r.returncode == 2 and "summary.json" in r.stderr and not out.exists()
    r = _tool(a, b, c, d, "--out", out)   # four runs
    assert r.returncode == 2 and not out.exists()
