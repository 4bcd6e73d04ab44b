"""The flow contract (bridge/cfd/flow.py): every flow keeps it, owns its turbulence model and advances it in
its own step; the presets' flows come from a public builder (bridge/aero/presets.py); the runnable example of
the CFD on its own (tools/example_pitch.py) works."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bridge.aero.forced_motion import ForcedCase, StaticCase, run_case, whole_periods
from bridge.aero.presets import QUALITY, build_flow, preset, section_polygons
from bridge.cfd import (
    LAMINAR,
    BoundaryConditions,
    CartesianGrid,
    Flow,
    FlowConfig,
    KOmegaSST,
    Polygon,
    Simulation,
    Stationary,
    freestream_turbulence,
    run,
)
from bridge.cfd.sections import FlatPlate, great_belt_section
from bridge.errors import InputError

REPO = Path(__file__).resolve().parents[2]


def _user_flow():
    grid = CartesianGrid.uniform(48, 24, (0.0, 2.0), (-0.5, 0.5))
    sim = Simulation(grid, FlowConfig(nu=1e-5, threads=1, bc=BoundaryConditions(
        left="inflow", right="outflow", bottom="slip", top="slip")))
    sim.add_body(Polygon(np.array([[0.4, -0.05], [0.8, -0.05], [0.8, 0.05], [0.4, 0.05]])), Stationary())
    sim.set_state(u=1.0)
    return sim


def test_a_user_built_flow_with_sst_advances_k_in_its_own_step():
    """Before, ``bridge.cfd.run`` never advanced a model: a user's k stayed at the freestream's, silently."""
    sim = _user_flow()
    assert sim.turbulence is LAMINAR
    model = KOmegaSST(sim, *freestream_turbulence(1.0, 1e-5))
    assert isinstance(sim, Flow) and sim.turbulence is model and "SST" in sim.describe()
    k0 = model.k.interior().copy()
    run(sim, 0.05)
    k1 = model.k.interior()
    assert np.isfinite(k1).all() and np.abs(k1 - k0).max() > 1e-3 * k0.max()
    with pytest.raises(ValueError, match="already has a turbulence model"):
        KOmegaSST(sim, *freestream_turbulence(1.0, 1e-5))


def test_the_step_limit_is_the_smaller_of_the_flows_and_its_models():
    sim = _user_flow()
    model = KOmegaSST(sim, *freestream_turbulence(1.0, 1e-5))
    free = sim.stable_dt()
    assert 0 < free <= model.stable_dt()
    model.stable_dt = lambda: 1e-3 * free   # a model that needs a smaller step gets it
    assert sim.stable_dt() == 1e-3 * free
    assert sim.step() == 1e-3 * free


@pytest.mark.parametrize("grid", ["single", "overset"])
def test_the_presets_flows_keep_the_contract_and_own_their_sst_model(grid):
    q = preset("tiny", grid).with_(turbulence="sst", reynolds=1e7)
    flow = build_flow(q, section_polygons(great_belt_section()), ForcedCase.thesis("pitch", 1.0))
    assert isinstance(flow, Flow) and flow.turbulence.name == "sst" and "SST" in flow.describe()
    k = [s.state.arrays()["k"].copy() for s in flow.simulations]
    run(flow, 1.0, max_steps=5)
    assert flow.n_steps == 5 and np.isfinite(flow.total_force).all()
    assert all(np.abs(s.state.arrays()["k"] - k0).max() > 0 for s, k0 in zip(flow.simulations, k, strict=True))


def test_a_section_longer_than_the_single_grid_is_refused_naming_the_preset():
    long_plate = [Polygon(np.array([[-0.5, -0.01], [2.5, -0.01], [2.5, 0.01], [-0.5, 0.01]]))]
    with pytest.raises(InputError, match="aero.quality.*cannot hold this section"):
        build_flow(QUALITY["tiny"], long_plate, StaticCase(0.0))


def test_an_internal_error_while_building_a_flow_is_not_relabelled_as_the_users(monkeypatch):
    """run_case used to turn any ValueError raised while building the flow into InputError("aero.quality")."""
    import bridge.cfd

    def broken(*args, **kwargs):
        raise ValueError("an invariant of the solver broke")

    monkeypatch.setattr(bridge.cfd, "Simulation", broken)
    with pytest.raises(ValueError, match="invariant"):
        run_case(section_polygons(FlatPlate(1.0, 0.04)), StaticCase(0.0), QUALITY["tiny"])


@pytest.mark.slow   # 4 s: a subprocess importing the program
def test_the_example_script_prints_the_pitch_derivatives_of_a_section():
    out = subprocess.run([sys.executable, str(REPO / "tools" / "example_pitch.py"), "--quality", "tiny",
                          "--reduced-velocities", "4"], capture_output=True, text=True, timeout=300, cwd=REPO)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = out.stdout.strip().splitlines()
    assert lines[1].split() == ["U/(fB)", "A2*", "A3*", "H2*", "H3*"]
    values = [float(v) for v in lines[2].split()]
    assert values[0] == 4 and len(values) == 5 and np.isfinite(values).all()


@pytest.mark.slow
def test_the_example_gives_the_numbers_of_the_aero_stages_route():
    """The example's own loop (build_flow, run, a monitor) and run_case (the aero stage's) give the same
    derivatives to round-off."""
    from bridge.aero.frequency_response import forced_motion_response
    from bridge.flutter.derivatives import FRF, derivatives_from_frf

    out = subprocess.run([sys.executable, str(REPO / "tools" / "example_pitch.py"), "--quality", "tiny",
                          "--reduced-velocities", "6"], capture_output=True, text=True, timeout=300, cwd=REPO)
    assert out.returncode == 0, out.stderr[-2000:]
    example = [float(v) for v in out.stdout.strip().splitlines()[2].split()[1:]]
    section = great_belt_section()
    q = QUALITY["tiny"].with_(overset=True, turbulence="sst", reynolds=50 * section.chord_m / 1.48e-5)
    K = 2 * np.pi / 6
    case = ForcedCase.thesis("pitch", K)
    rec = run_case(section_polygons(section), case, q)
    w = whole_periods(rec, case, q)
    (r,) = forced_motion_response(rec.t[w], rec.motion[w], [K], dof="pitch", speed_m_s=1, deck_width_m=1,
                                  air_density_kg_m3=1, lift=rec.lift[w], moment=rec.moment[w], fundamental=K)
    d = derivatives_from_frf(np.array([K]), FRF(np.nan, r.frf.h_ptheta, np.nan, r.frf.h_mtheta))
    stage = [float(np.squeeze(getattr(d, n))) for n in ("A2", "A3", "H2", "H3")]
    assert example == pytest.approx(stage, rel=2e-4, abs=1e-4)   # the example prints 4 decimals
