"""Flutter of the bridge deck: modal input, aerodynamic models, two-mode determinant and multimode p-k
solvers, and the pipeline stage (thesis chapter 4 and section 5.4)."""

from bridge.flutter.modal import ModalModel

__all__ = ["ModalModel"]
