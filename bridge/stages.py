"""What a pipeline stage hands back, and the registry of stages.

A stage is a function ``run(scenario, upstream, options) -> StageOutput``:
  scenario  - the validated :class:`bridge.config.Scenario`
  upstream  - ``dict[str, StageOutput]`` of the stages already run (e.g. ``upstream["cable"].data``)
  options   - :class:`RunOptions` (output verbosity, coarse mode for tests)
Stages never write files themselves; :mod:`bridge.results` writes everything atomically.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import import_module
from typing import Any

__all__ = ["StageOutput", "RunOptions", "STAGES", "resolve_stage"]


@dataclass
class StageOutput:
    """Everything one stage produced.

    summary  - flat headline numbers for ``summary.json``; keys are ``"<stage>.<name>_<unit>"``,
               e.g. ``"cable.horizontal_force_per_cable_N"``; values are float, int or str.
    write_h5 - callable that fills the stage's HDF5 group (``results.h5:/<stage>``); document every
               dataset in ``docs/results.md``.
    report   - a Markdown section for ``report.md`` (starts with a ``## `` heading).
    figures  - ``{"file_name.png": matplotlib.figure.Figure}``.
    data     - the stage's Python result object, for later stages.
    """

    summary: dict[str, float | int | str]
    write_h5: Callable[[Any], None]
    report: str
    figures: dict[str, Any] = field(default_factory=dict)
    data: Any = None


@dataclass(frozen=True)
class RunOptions:
    """Options of one run that are not physics: ``quick`` shrinks meshes/grids for tests and smoke runs;
    ``progress`` is a callable taking a one-line message (default: print to stderr)."""

    quick: bool = False
    progress: Callable[[str], None] | None = None

    def say(self, message: str) -> None:
        if self.progress is not None:
            self.progress(message)


# Stage name -> ("module:function", stages it needs).  Order here is the run order.
STAGES: dict[str, tuple[str, tuple[str, ...]]] = {
    "cable": ("bridge.cable_stage:run", ()),
    "fem": ("bridge.structure.stage:run", ("cable",)),
    "flutter": ("bridge.flutter.stage:run", ("fem",)),
}


def resolve_stage(name: str) -> Callable[..., StageOutput]:
    """Import the stage function registered under ``name``."""
    if name not in STAGES:
        raise KeyError(f"unknown stage {name!r}; known stages: {', '.join(STAGES)}")
    target, _ = STAGES[name]
    module_name, func_name = target.split(":")
    return getattr(import_module(module_name), func_name)
