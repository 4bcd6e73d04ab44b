"""The Great Belt frame model in quick mode (2 elements per hanger panel): dead-load equilibrium,
constraints, mode labels, normalisation (Eq 4.31-4.32), modal integrals (Eq 4.34), stage outputs."""

from __future__ import annotations

import numpy as np
import pytest

from bridge.cable import solve_cables
from bridge.config import load_scenario
from bridge.stages import RunOptions, StageOutput
from bridge.structure import analyse
from bridge.structure.assembly import constraint_transform
from bridge.structure.stage import run


@pytest.fixture(scope="module")
def great_belt():
    s = load_scenario("great_belt")
    c = solve_cables(s, steps_per_panel=4)
    return s, c, analyse(s, c, elements_per_panel=2, n_modes=30)


def test_dead_load_state_is_self_equilibrated(great_belt):
    s, c, r = great_belt
    m = r.model
    # hanger tensions carry the girder weight; cable nodes without hanger balance their own weight
    assert m.hanger_weight_residual < 1e-5
    assert m.cable_node_residual_N < 1e-6 * m.hanger_tension_N.mean()
    assert np.all(m.hanger_tension_N > 0.0)
    # each hanger carries about one panel of half the girder
    panel_load = 0.5 * s.girder.mass_per_length_kg_m * 9.81 * c.main_panel_m
    assert np.median(m.hanger_tension_N) == pytest.approx(panel_load, rel=0.02)


def test_rigid_links_follow_the_girder(great_belt):
    _, _, r = great_belt
    m = r.model
    T = constraint_transform(m)
    slave, master = m.links[len(m.links) // 3]
    # a unit twist of the reduced DOF theta_z at the master moves the slave by theta x r
    col = T[6 * master + 5].indices
    assert len(col) == 1
    q = np.zeros(T.shape[1])
    q[col[0]] = 1.0
    u = T @ q
    r_vec = m.nodes[slave] - m.nodes[master]
    assert np.allclose(u[6 * slave:6 * slave + 3], np.cross([0.0, 0.0, 1.0], r_vec), atol=1e-14)
    assert u[6 * slave + 5] == 1.0


def test_frequencies_and_labels(great_belt):
    _, _, r = great_belt
    m = r.modes
    for lab in ("S-V1", "SS-V1", "S-T1", "SS-T1", "S-L1"):
        assert lab in m.labels
    assert 0.07 < r.frequency("S-V1") < 0.15
    assert 0.2 < r.frequency("S-T1") < 0.4
    assert r.frequency("S-L1") < r.frequency("SS-V1") < r.frequency("S-T1")
    assert np.all(np.diff(m.frequencies_hz) >= 0.0)


def test_normalisation_and_symmetry(great_belt):
    _, _, r = great_belt
    m = r.modes
    mirror = 2 * m.mid_span_z_m - m.z_m
    for i, (kind, sym) in enumerate(zip(m.kinds, m.symmetries, strict=False)):
        field = {"vertical": m.U, "torsional": m.Theta, "lateral": m.V}.get(kind)
        if field is None:
            continue
        f = field[i]
        assert f.max() == pytest.approx(1.0, abs=1e-12)          # Eq 4.31-4.32: max is +1
        assert np.abs(f).max() == pytest.approx(1.0, abs=1e-12)
        fm = np.interp(mirror, m.z_m, f)
        sign = 1.0 if sym == "S" else -1.0
        assert np.abs(f - sign * fm).max() < 1e-6                 # the model is symmetric about mid-span


def test_modal_integrals(great_belt):
    _, _, r = great_belt
    m = r.modes
    uu, ut, tt = m.uu, m.ut, m.tt
    assert np.allclose(uu, uu.T) and np.allclose(tt, tt.T)
    i = m.index("S-V1")
    # a_jj = (1/L) int U^2 (Eq 4.34) against numpy's trapezoid on the same nodes
    assert uu[i, i] == pytest.approx(np.trapezoid(m.U[i] ** 2, m.z_m) / m.deck_length_m, rel=1e-12)
    pairs = m.pair_integrals()
    assert pairs[0]["j"] == "S-V1" and pairs[0]["k"] == "S-T1"
    for p in pairs:
        assert 0.0 < p["a_jj"] < 1.0 and 0.0 < p["a_kk"] < 1.0 and abs(p["a_jk"]) < 1.0
    # a symmetric bending mode and a skew-symmetric torsion mode are orthogonal over the deck
    assert abs(ut[i, m.index("SS-T1")]) < 1e-6
    assert np.all(m.modal_masses > 0.0)


def test_damping_from_the_nearest_measured_mode_of_the_same_symmetry(great_belt):
    """Table 3.4 rows are matched by symmetry and nearest frequency (bridge.structure.modes.assign_damping)."""
    s, _, r = great_belt
    m = r.modes
    for i, (f, sym) in enumerate(zip(m.frequencies_hz, m.symmetries, strict=True)):
        rows = [d for d in s.damping if d.symmetry == sym]
        best = min(rows, key=lambda d: abs(d.frequency_hz - f))
        assert m.damping_ratios[i] == best.ratio
    # the first symmetric torsional mode (~0.28 Hz) takes the 0.287 Hz measured mode's 0.20 %
    assert m.damping_ratios[m.labels.index("S-T1")] == pytest.approx(0.0020)


def test_modal_model_for_flutter(great_belt):
    _, _, r = great_belt
    mm = r.modal_model
    assert set(mm.kinds) <= {"vertical", "torsional", "lateral"}
    assert mm.deck_length_m == pytest.approx(1624.0 + 2 * 535.0)
    j, k = mm.index("S-V1"), mm.index("S-T1")
    jj, kk = r.modes.index("S-V1"), r.modes.index("S-T1")
    assert mm.uu[j, j] == pytest.approx(r.modes.uu[jj, jj])
    assert mm.ut[j, k] == pytest.approx(r.modes.ut[jj, kk])
    assert mm.tt[k, k] == pytest.approx(r.modes.tt[kk, kk])


def test_stage_outputs(tmp_path):
    import h5py

    from bridge.cable_stage import run as run_cable

    s = load_scenario("great_belt")
    opts = RunOptions(quick=True)
    out = run(s, {"cable": run_cable(s, {}, opts)}, opts)
    assert isinstance(out, StageOutput)
    for key in ("fem.frequency_S_V1_hz", "fem.frequency_S_T1_hz", "fem.a_jj", "fem.a_kk", "fem.a_jk",
                "fem.n_modes", "fem.n_dof"):
        assert key in out.summary
    assert out.report.startswith("## ")
    assert "S-T1" in out.report
    with h5py.File(tmp_path / "r.h5", "w") as f:
        out.write_h5(f.create_group("fem"))
    with h5py.File(tmp_path / "r.h5") as f:
        g = f["fem"]
        n = g["frequencies_hz"].shape[0]
        assert g["U"].shape == (n, g["z_m"].shape[0])
        assert g["pairs/a_jk"].shape[0] >= 2
    assert len(out.figures) >= 5


def test_models_frequencies_fall_with_span():
    """Table 3.5: the first symmetric vertical and torsional frequencies fall from Great Belt to Model C."""
    f = {}
    for name in ("great_belt", "model_c"):
        s = load_scenario(name)
        r = analyse(s, solve_cables(s, steps_per_panel=4), elements_per_panel=1, n_modes=40)
        f[name] = (r.frequency("S-V1"), r.frequency("S-T1"))
    assert f["model_c"][0] < 0.8 * f["great_belt"][0]
    assert f["model_c"][1] < 0.8 * f["great_belt"][1]


def test_assembled_mass_is_the_bridge_mass(great_belt):
    """A rigid translation of the unconstrained model: u^T M u = total mass of girder, cables, hangers, pylons."""
    s, _, r = great_belt
    m, M = r.model, r.assembled.mass
    length = np.linalg.norm(m.elements.xb - m.elements.xa, axis=1)
    expected = float(np.sum(m.elements.props[:, 4] * length))
    from bridge.structure.model import GROUPS

    in_girder = m.group == GROUPS.index("girder")
    assert np.sum(m.elements.props[in_girder, 4] * length[in_girder]) == pytest.approx(
        s.girder.mass_per_length_kg_m * m.deck_length_m, rel=1e-12)
    legs = np.isin(m.group, [GROUPS.index("pylon_lower_leg"), GROUPS.index("pylon_upper_leg")])
    leg_height = length[legs].sum() / 4   # four legs, foundation to saddle
    assert leg_height == pytest.approx(s.geometry.pylon_height_m, rel=1e-12)
    for d in range(3):
        u = np.zeros(M.shape[0])
        u[d::6] = 1.0
        assert u @ (M @ u) == pytest.approx(expected, rel=1e-12)


def test_shift_invert_matches_dense_solver():
    """lowest_modes against scipy.linalg.eigh on a small random SPD pencil."""
    import scipy.linalg as sla
    import scipy.sparse as sp

    from bridge.structure.eigen import lowest_modes

    rng = np.random.default_rng(3)
    a = rng.normal(size=(60, 60))
    K = a @ a.T + 60 * np.eye(60)
    b = rng.normal(size=(60, 60))
    M = b @ b.T / 60 + np.eye(60)
    f, vec = lowest_modes(sp.csr_matrix(K), sp.csr_matrix(M), 8)
    w2 = sla.eigh(K, M, eigvals_only=True)[:8]
    assert np.allclose((2 * np.pi * f) ** 2, w2, rtol=1e-10)
    assert np.allclose(vec.T @ M @ vec, np.eye(8), atol=1e-8)


def test_the_same_model_gives_the_same_modes_bit_for_bit():
    """Solved twice in one process the modes agree to the last bit, signs included: a result must not
    depend on what the process solved before (ARPACK's own start vector comes from a seed it carries
    from call to call)."""
    import scipy.sparse as sp

    from bridge.structure.eigen import lowest_modes

    rng = np.random.default_rng(5)
    a = rng.normal(size=(80, 80))
    K = sp.csr_matrix(a @ a.T + 80 * np.eye(80))
    M = sp.identity(80, format="csr")
    f1, v1 = lowest_modes(K, M, 6)
    f2, v2 = lowest_modes(K, M, 6)
    np.testing.assert_array_equal(f1, f2)
    np.testing.assert_array_equal(v1, v2)
