"""What a pipeline stage hands back, and the registry of stages.

A stage is a function ``run(scenario, upstream, options) -> StageOutput``:
  scenario  - the validated :class:`bridge.config.Scenario`
  upstream  - ``dict[str, StageOutput]`` of the stages already run (e.g. ``upstream["cable"].data``)
  options   - :class:`RunOptions` (output verbosity, coarse mode for tests)
Stages never write files themselves; :mod:`bridge.results` writes everything atomically.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache
from importlib import import_module
from importlib.util import find_spec
from pathlib import Path
from typing import Any

__all__ = ["StageOutput", "RunOptions", "Stage", "STAGES", "IDENTITY_FIELDS", "resolve_stage", "code_digest",
           "CFD_KERNELS"]


@dataclass
class StageOutput:
    """Everything one stage produced.

    summary  - flat headline numbers for ``summary.json``; keys are ``"<stage>.<name>_<unit>"``,
               e.g. ``"cable.horizontal_force_per_cable_N"``; values are float, int, bool, str or None
               (None: a number that does not exist, e.g. no flutter below the highest speed searched).
    write_h5 - callable that fills the stage's HDF5 group (``results.h5:/<stage>``); document every
               dataset in ``docs/results.md``.
    report   - a Markdown section for ``report.md`` (starts with a ``## `` heading).
    figures  - ``{"file_name.png": matplotlib.figure.Figure}``, or PNG bytes once stored
               (:func:`bridge.cache.store`); other files of the result folder as bytes
               (``{"aero_pitch_flow.xdmf": b"..."}``: the report links them instead of showing them).
    data     - the stage's Python result object, for later stages.
    from_cache - True when the output was taken from the stage cache instead of computed.
    """

    summary: dict[str, float | int | bool | str | None]
    write_h5: Callable[[Any], None]
    report: str
    figures: dict[str, Any] = field(default_factory=dict)
    data: Any = None
    from_cache: bool = False


@dataclass(frozen=True)
class RunOptions:
    """Options of one run that are not physics: ``quick`` shrinks meshes/grids for tests and smoke runs;
    ``progress`` is a callable taking a one-line message (default: none); ``cache`` is the folder of the
    stage cache (:mod:`bridge.cache`; None: compute every stage afresh and keep nothing);
    ``quality`` the CFD preset of the aero stage (None: the scenario's, "tiny" with ``quick``); ``workers``
    the processes that run the aero stage's CFD cases side by side (None: 2 on a machine with 2 or more
    cores, :func:`bridge.aero.forced_motion.default_workers`; 1: one after the other, each on all cores);
    ``scheduler`` the address of a Dask scheduler whose workers run those cases instead (:mod:`bridge.cluster`)."""

    quick: bool = False
    progress: Callable[[str], None] | None = None
    cache: Path | None = None
    quality: str | None = None
    workers: int | None = None
    scheduler: str | None = None

    def say(self, message: str) -> None:
        if self.progress is not None:
            self.progress(message)


@dataclass(frozen=True)
class Stage:
    """A registered stage.

    target  - ``"module:function"`` of its ``run``
    needs   - stages whose outputs it reads (``upstream``)
    code    - modules and packages whose source decides its result: their text is part of the stage's
              cache key (:mod:`bridge.cache`), so changed code never reuses an old result
    ignores - top-level scenario fields its result does not depend on (also left out of the cache key:
              changing the flutter options does not rerun the FEM)
    shared  - the result does not depend on the scenario's name either, so scenarios and sweep cases
              with the same inputs share one stored result (a deck section's aerodynamics).  The
              cable, fem and flutter stages put the name in their titles and reference tables, so
              they are not shared.
    uses    - if set, the only top-level scenario fields the result depends on (the others are left
              out of the cache key, as with ``ignores``)
    """

    target: str
    needs: tuple[str, ...]
    code: tuple[str, ...]
    ignores: tuple[str, ...] = ()
    shared: bool = False
    uses: tuple[str, ...] | None = None


# The scenario fields that never change a result: how it is called and where it was read from.
IDENTITY_FIELDS = ("description", "source_path")

# The kernel modules the CFD runs (a test checks that the list is complete): part of the aero stage's key
# and of each CFD case's checkpoint key (bridge.aero.forced_motion.case_key).
CFD_KERNELS = ("kernels.cfd", "kernels.curvilinear", "kernels.transport", "kernels.wall_law")

# Registry; the order here is the run order.
STAGES: dict[str, Stage] = {
    "cable": Stage("bridge.cable_stage:run", (), ("bridge.cable", "bridge.cable_stage"),
                   ignores=("damping", "air", "flutter", "section", "modal", "buffeting")),
    "fem": Stage("bridge.structure.stage:run", ("cable",), ("bridge.structure", "kernels.fem"),
                 ignores=("air", "flutter", "section", "modal", "buffeting")),
    # the deck's aerodynamics from forced-motion CFD: the section and the [aero] options only, so
    # bridges with one deck share it (the flutter stage reads it when [flutter] aerodynamics = "cfd")
    "aero": Stage("bridge.aero.stage:run", (), ("bridge.aero", "bridge.cfd", *CFD_KERNELS), shared=True,
                  uses=("deck_section", "aero", "air")),
    "flutter": Stage("bridge.flutter.stage:run", ("fem", "aero"), ("bridge.flutter", "bridge.structure.plots"),
                     ignores=("buffeting",)),
    # the response to turbulent wind below the flutter speed, with the flutter stage's modes, aerodynamics and
    # flutter speed; runs when asked for (--stages) or when the scenario has a [buffeting] table
    "buffeting": Stage("bridge.buffeting.stage:run", ("fem", "aero", "flutter"),
                       ("bridge.buffeting", "bridge.flutter")),
}


def resolve_stage(name: str) -> Callable[..., StageOutput]:
    """Import the stage function registered under ``name``."""
    if name not in STAGES:
        raise KeyError(f"unknown stage {name!r}; known stages: {', '.join(STAGES)}")
    module_name, func_name = STAGES[name].target.split(":")
    return getattr(import_module(module_name), func_name)


@cache
def code_digest(modules: tuple[str, ...]) -> str:
    """SHA-256 over the source files of the given modules and packages (packages: every .py inside): what a
    cached stage result or a CFD checkpoint must match to be reused (a changed code never reuses old results)."""
    h = hashlib.sha256()
    for name in modules:
        spec = find_spec(name)
        if spec is None:
            raise KeyError(f"stage code {name!r} is not an importable module")
        if spec.submodule_search_locations:
            files = sorted(p for loc in spec.submodule_search_locations for p in Path(loc).rglob("*.py"))
        else:
            files = [Path(spec.origin)]
        for f in files:
            h.update(f.name.encode())
            h.update(f.read_bytes())
    return h.hexdigest()
