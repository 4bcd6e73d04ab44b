"""3D finite-element model of a suspension bridge and its eigen analysis (thesis chapter 3).

Stage entry point: :func:`bridge.structure.stage.run`; library entry point: :func:`analyse`.
"""

from .analysis import FemResult, analyse

__all__ = ["FemResult", "analyse"]
