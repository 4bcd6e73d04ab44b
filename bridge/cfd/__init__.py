"""2D incompressible Navier-Stokes (laminar or URANS with k-omega SST) on Cartesian MAC grids with immersed
rigid bodies, on one grid or an overset pair.

Public API: build a ``CartesianGrid``, a ``FlowConfig`` (with ``BoundaryConditions``), a ``Simulation``,
bodies (``Simulation.add_body`` with a ``Polygon`` and a motion), optionally its turbulence model
(``KOmegaSST(sim, *freestream_turbulence(U, nu))``, which the simulation then owns and advances), then
``run(flow, t_end, monitors)``.  ``OversetPair``: a fine body grid moving with the body over a fixed background
(overset.py; its model: ``OversetSST``).  Both keep the ``Flow`` contract of flow.py, the one a new grid type
implements.  The presets' flows for a deck section: bridge.aero.presets.  Plug-in points: the grid object
(metrics), the Poisson solver object, body motions (anything with ``pose(t)``/``velocity(t)``), stage hooks
(``SubstepHook``), ``Simulation.state`` (a ``FlowState``: the fields a resumed run needs).  See docs/cfd.md.
"""

from .bodies import Polygon, box_deck, circle, flat_plate
from .boundaries import BoundaryConditions
from .flow import LAMINAR, Flow, FlowBase, FlowDiverged, Laminar, TurbulenceModel, run
from .grids import GHOST, CartesianGrid, stretched_faces
from .immersed import ImmersedBody
from .monitors import CFLMonitor, Checkpoint, DivergenceMonitor, ForceHistory, NaNMonitor, ProgressNote, max_divergence
from .motion import HarmonicMotion, PrescribedMotion, Stationary, UniformTranslation
from .overset import OversetPair
from .precision import DTYPE
from .pressure import PoissonSolver
from .state import FlowState
from .time_stepping import TIME_SCHEMES, FlowConfig, Simulation, SubstepHook
from .turbulence import KOmegaSST, OversetSST, freestream_turbulence

__all__ = [
    "Flow", "FlowBase", "TurbulenceModel", "Laminar", "LAMINAR", "KOmegaSST", "OversetSST", "freestream_turbulence",
    "Checkpoint",
    "BoundaryConditions", "CartesianGrid", "CFLMonitor", "DivergenceMonitor", "DTYPE", "FlowConfig",
    "FlowDiverged", "FlowState", "ForceHistory", "GHOST", "HarmonicMotion", "ImmersedBody", "NaNMonitor",
    "OversetPair", "PoissonSolver", "Polygon", "PrescribedMotion", "ProgressNote", "Simulation", "SubstepHook",
    "Stationary", "TIME_SCHEMES",
    "UniformTranslation", "box_deck", "circle", "flat_plate", "max_divergence", "run", "stretched_faces",
]
