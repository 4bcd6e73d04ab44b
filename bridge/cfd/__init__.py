"""2D incompressible laminar Navier-Stokes on Cartesian MAC grids with immersed rigid bodies.

Public API: build a ``CartesianGrid``, a ``FlowConfig`` (with ``BoundaryConditions``), a ``Simulation``,
bodies (``Simulation.add_body`` with a ``Polygon`` and a motion), then ``run`` with monitors.
Plug-in points for later issues: ``Simulation.set_viscosity`` (cell field nu + nu_t from a turbulence
model before each step), the grid object (metrics), the Poisson solver object, body motions
(anything with ``pose(t)``/``velocity(t)``), stage hooks (``StageHook``). ``OversetPair``: a fine body grid
moving with the body over a fixed background (overset.py). ``Simulation.state`` (a ``FlowState``): the
fields a resumed run needs, with save and load to HDF5. See docs/cfd.md.
"""

from .bodies import Polygon, box_deck, circle, flat_plate
from .boundaries import BoundaryConditions
from .grids import GHOST, CartesianGrid, stretched_faces
from .immersed import ImmersedBody
from .monitors import CFLMonitor, DivergenceMonitor, ForceHistory, NaNMonitor, ProgressNote, max_divergence, run
from .motion import HarmonicMotion, PrescribedMotion, Stationary, UniformTranslation
from .overset import OversetPair
from .precision import DTYPE
from .pressure import PoissonSolver
from .state import FlowState
from .time_stepping import TIME_SCHEMES, FlowConfig, FlowDiverged, Simulation, StageHook

__all__ = [
    "BoundaryConditions", "CartesianGrid", "CFLMonitor", "DivergenceMonitor", "DTYPE", "FlowConfig",
    "FlowDiverged", "FlowState", "ForceHistory", "GHOST", "HarmonicMotion", "ImmersedBody", "NaNMonitor",
    "OversetPair", "PoissonSolver", "Polygon", "PrescribedMotion", "ProgressNote", "Simulation", "StageHook",
    "Stationary", "TIME_SCHEMES",
    "UniformTranslation", "box_deck", "circle", "flat_plate", "max_divergence", "run", "stretched_faces",
]
