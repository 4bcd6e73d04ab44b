"""Flutter of the bridge deck: modal input, aerodynamic models, two-mode determinant and multimode p-k
solvers, and the pipeline stage (thesis chapter 4 and section 5.4).  See docs/flutter.md."""

from bridge.flutter.modal import ModalModel
from bridge.flutter.options import FlutterOptions
from bridge.flutter.section import SectionModel

__all__ = ["ModalModel", "FlutterOptions", "SectionModel"]
