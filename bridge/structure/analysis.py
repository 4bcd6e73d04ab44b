"""Build, assemble and solve the FEM of one bridge: the result object of the ``fem`` stage.

:func:`analyse` runs model (:mod:`.model`) -> Warp element matrices and sparse assembly
(:mod:`.assembly`) -> shift-invert eigen solve (:mod:`.eigen`) -> classification, normalisation,
damping and modal integrals (:mod:`.modes`).  :class:`FemResult` carries all of it;
``FemResult.modal_model`` is the flutter input (:class:`bridge.flutter.modal.ModalModel`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..cable import CableSolution
from ..config import Scenario
from .assembly import AssembledModel, assemble
from .eigen import lowest_modes
from .model import FrameModel, build_model
from .modes import ModeSet, classify_modes

__all__ = ["FemResult", "analyse", "DEFAULT_ELEMENTS_PER_PANEL", "DEFAULT_N_MODES", "FLUTTER_KINDS"]

DEFAULT_ELEMENTS_PER_PANEL = 4   # from tools/fem_convergence.py (docs/structure.md)
DEFAULT_N_MODES = 40
FLUTTER_KINDS = ("vertical", "torsional", "lateral")


@dataclass(frozen=True)
class FemResult:
    """Model, matrices and modes of one bridge, plus wall-clock timings (s) of the steps."""

    scenario: Scenario
    model: FrameModel
    assembled: AssembledModel
    modes: ModeSet
    timings_s: dict = field(default_factory=dict)

    @property
    def n_dof(self) -> int:
        return self.assembled.n_dof

    @property
    def frequencies_hz(self) -> np.ndarray:
        return self.modes.frequencies_hz

    @property
    def labels(self) -> tuple[str, ...]:
        return self.modes.labels

    def frequency(self, label: str) -> float:
        return float(self.modes.frequencies_hz[self.modes.index(label)])

    @property
    def modal_model(self):
        """The vertical, torsional and lateral modes as a :class:`bridge.flutter.modal.ModalModel`
        (integrals of Eq 4.34 over the whole deck length; mu and J of Eq 4.7).

        Wind direction: the flutter convention takes theta nose-up (Eq 4.20), and the FEM's Theta is
        the rotation theta_z about the bridge axis (right-handed x across, y up, z along), which lifts
        the edge at +x; so the wind blows from +x towards -x, and the lateral displacement positive
        DOWNWIND is R = -V (V = u_x).  Hence rr = vv, ur = -uv, rt = -vt.  (The deck and the FEM are
        symmetric about x = 0, so the other wind direction gives the mirror image and the same speeds.)"""
        from ..flutter.modal import ModalModel  # lazy: the flutter package is optional for this stage

        m = self.modes
        keep = [i for i, k in enumerate(m.kinds) if k in FLUTTER_KINDS]
        ix = np.ix_(keep, keep)
        s = self.scenario
        return ModalModel(
            labels=tuple(m.labels[i] for i in keep), kinds=tuple(m.kinds[i] for i in keep),
            symmetries=tuple(m.symmetries[i] for i in keep), frequencies_hz=m.frequencies_hz[keep],
            damping_ratios=m.damping_ratios[keep], uu=m.uu[ix], ut=m.ut[ix], tt=m.tt[ix],
            rr=m.vv[ix], ur=-m.uv[ix], rt=-m.vt[ix],
            mass_per_length_kg_m=s.deck_mass_per_length_kg_m,
            inertia_per_length_kg_m2_m=s.deck_inertia_per_length_kg_m2_m,
            deck_width_m=s.girder.width_m, deck_length_m=self.model.deck_length_m)


def analyse(scenario: Scenario, cables: CableSolution, elements_per_panel: int = DEFAULT_ELEMENTS_PER_PANEL,
            n_modes: int = DEFAULT_N_MODES, device: str = "cpu") -> FemResult:
    """Frame model, assembly (Warp kernel on ``device``), the ``n_modes`` lowest modes, classified."""
    t0 = time.perf_counter()
    model = build_model(scenario, cables, n_sub=elements_per_panel)
    t1 = time.perf_counter()
    assembled = assemble(model, device=device)
    t2 = time.perf_counter()
    freq, vec = lowest_modes(assembled.stiffness_reduced, assembled.mass_reduced, n_modes)
    t3 = time.perf_counter()
    modes = classify_modes(scenario, freq, assembled.T @ vec, assembled.mass, model.girder_nodes,
                           model.girder_z, model.deck_length_m, model.mid_span_z_m)
    t4 = time.perf_counter()
    return FemResult(scenario, model, assembled, modes,
                     {"model": t1 - t0, "assembly": t2 - t1, "eigen": t3 - t2, "classify": t4 - t3})
