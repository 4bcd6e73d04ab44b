"""Running a scenario through its stages and writing the results.

``run_scenario`` is what ``python -m bridge.scenario`` and the sweeps call: it resolves the requested
stages with their prerequisites, runs them in order (taking each from the stage cache,
:mod:`bridge.cache`, when ``options.cache`` is set and its inputs are unchanged), and hands every output
to :func:`bridge.results.write_results` (atomic: nothing is left behind if a stage fails).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from . import cache
from .config import Scenario, check_deck_chord
from .datastore import DataError
from .errors import InputError
from .results import write_results
from .stages import STAGES, RunOptions, StageOutput, resolve_stage

__all__ = ["plan_stages", "run_stages", "run_scenario", "default_stages", "stage_keys", "wants_cfd"]

# Stages that only make sense for one kind of scenario.
_KIND_STAGES = {"suspension_bridge": ("cable", "fem", "aero", "flutter", "buffeting"), "section": ("aero", "flutter"),
                "modal": ("aero", "flutter")}


def wants_cfd(scenario: Scenario) -> bool:
    """True when the flutter stage is to use the deck's own aerodynamics (``[flutter] aerodynamics = "cfd"``)."""
    fl, section = scenario.flutter, scenario.section
    return "cfd" in (getattr(fl, "aerodynamics", None), getattr(section, "aerodynamics", None))


def default_stages(scenario: Scenario) -> tuple[str, ...]:
    """The registered stages a scenario of this kind runs when none are named (the aero stage only when
    the flutter stage is to use it; the buffeting stage only when the scenario has a [buffeting] table, so that
    the main job stays as it was)."""
    return tuple(s for s in _KIND_STAGES.get(scenario.kind, ()) if s in STAGES and (s != "aero" or wants_cfd(scenario))
                 and (s != "buffeting" or scenario.buffeting is not None))


def plan_stages(scenario: Scenario, requested: Iterable[str] | None) -> tuple[str, ...]:
    """Requested stages plus their prerequisites, in registry order; unknown names are an InputError."""
    wanted = list(requested) if requested is not None else list(default_stages(scenario))
    if not wanted:
        raise InputError("--stages", ",".join(wanted), f"no stage named; known: {', '.join(STAGES)}")
    for name in wanted:
        if name not in STAGES:
            raise InputError("--stages", name, f"unknown stage; known: {', '.join(STAGES)}")
    needed: set[str] = set()

    def need(name: str) -> None:
        if name in needed:
            return
        needed.add(name)
        for dep in STAGES[name].needs:
            if scenario.kind in ("section", "modal") and dep in ("cable", "fem"):
                continue  # a sectional model or given modes carry their own modal data
            if dep == "aero" and not wants_cfd(scenario):
                continue  # the flutter stage reads the CFD only when asked to
            need(dep)

    for name in wanted:
        need(name)
    allowed = _KIND_STAGES.get(scenario.kind, ())
    for name in needed:
        if name not in allowed:
            raise InputError("--stages", name, f"not available for a scenario of kind {scenario.kind!r} "
                             f"(available: {', '.join(s for s in allowed if s in STAGES)})")
    if "aero" in needed and scenario.deck_section is None:   # the CFD's deck: the Great Belt box by default
        from .cfd.sections import great_belt_section

        check_deck_chord(scenario, great_belt_section())
    if "flutter" in needed:   # a measured table is read now, so that a bad one is found before any stage runs
        check_aerodynamic_files(scenario)
    return tuple(s for s in STAGES if s in needed)


def check_aerodynamic_files(scenario: Scenario) -> None:
    """Read the aerodynamic table or derivative file the flutter stage will use (``table`` and
    ``derivatives`` aerodynamics), so that a file that cannot be used is an InputError before any work."""
    fopts = scenario.flutter
    aerodynamics = fopts.aerodynamics if fopts is not None else None
    section = scenario.section if scenario.kind == "section" else None
    if section is not None and section.aerodynamics is not None:
        aerodynamics = section.aerodynamics
    if fopts is None or aerodynamics not in ("table", "derivatives"):
        return
    from dataclasses import replace

    base = Path(scenario.source_path).parent if scenario.source_path else None
    replace(fopts, aerodynamics=aerodynamics).aerodynamic_model(base)


def stage_keys(scenario: Scenario, stages: Iterable[str] | None = None,
               options: RunOptions | None = None) -> dict[str, str]:
    """The cache key of every planned stage (:func:`bridge.cache.stage_key`), computed without running:
    what a result of these stages depends on (inputs, input files, code, options)."""
    options = options or RunOptions()
    keys: dict[str, str] = {}
    for name in plan_stages(scenario, stages):
        keys[name] = cache.stage_key(name, scenario, {d: keys[d] for d in STAGES[name].needs if d in keys},
                                     options.quick, options.quality if name == "aero" else None)
    return keys


def run_stages(scenario: Scenario, stages: Iterable[str] | None = None,
               options: RunOptions | None = None) -> dict[str, StageOutput]:
    """Run the planned stages and return their outputs (no result files written).

    With ``options.cache`` set, a stage whose key (:func:`bridge.cache.stage_key`) is stored is taken
    from the cache (and says so); a computed stage is stored there.  Outputs from this path are
    self-contained (:func:`bridge.cache.store`); without a cache they are returned as the stage made them.
    """
    options = options or RunOptions()
    outputs: dict[str, StageOutput] = {}
    keys = stage_keys(scenario, stages, options) if options.cache is not None else {}
    for name in plan_stages(scenario, stages):
        if options.cache is None:
            outputs[name] = resolve_stage(name)(scenario, outputs, options)
            continue
        try:
            hit, unreadable = cache.load(options.cache, name, keys[name]), False
        except cache.UnreadableEntry as bad:   # never trusted: computed again and replaced
            options.say(f"[{scenario.name}] {name}: the stored result in {bad.path} is not readable as this "
                        f"stage's data ({bad.reason}); computing it again")
            hit, unreadable = None, True
        if hit is not None:
            options.say(f"[{scenario.name}] {name}: inputs unchanged, reusing the stored result "
                        f"({options.cache / name / keys[name][:12]}...)")
            outputs[name] = hit
            continue
        out = cache.store(resolve_stage(name)(scenario, outputs, options))
        try:
            cache.save(options.cache, name, keys[name], out, replace_unreadable=unreadable)
        except DataError as err:   # a result the cache cannot hold as data: the run goes on without storing it
            options.say(f"[{scenario.name}] {name}: not kept in the stage cache ({err})")
        outputs[name] = out
    return outputs


def run_scenario(scenario: Scenario, out_dir: Path, stages: Iterable[str] | None = None,
                 options: RunOptions | None = None, overwrite: bool = False,
                 run_key: str | None = None) -> tuple[Path, dict[str, StageOutput]]:
    """Run the stages and write ``out_dir/<scenario.name>/``; return that folder and the outputs.

    An existing result folder is an :class:`InputError` unless ``overwrite`` (then the files of the
    earlier run are replaced and any other file there is kept); see :func:`bridge.results.write_results`.
    """
    from .results import check_target

    check_target(Path(out_dir), scenario.name, overwrite)
    outputs = run_stages(scenario, stages, options)
    folder = write_results(Path(out_dir), scenario, outputs, overwrite=overwrite, run_key=run_key)
    return folder, outputs
