"""Parameter sweeps: ``python -m bridge.sweep SCENARIO --main-span 1624,2000,3000,4000 [--vary KEY=V1,V2]``.

Every combination of the listed main spans and ``--vary`` values is one case, run through the pipeline
like ``python -m bridge.scenario`` and written to ``OUT/<sweep>/cases/<case>/``.  The sweep is resumable:
a case whose folder holds a finished run of the same inputs and stages is skipped (results are renamed
into place only when finished).  Stages shared by cases (same inputs: the aero stage's CFD of one deck) are
computed once, before the cases start, into the stage cache ``OUT/.cache/``, and the cases read them from there
(``--no-cache`` recomputes in every case).  Cases
run in parallel on local processes (``--workers``, default 2) or on an existing Dask cluster
(``--scheduler tcp://host:8786``; needs the optional extra ``pip install -e ".[dask]"``).

At the end ``OUT/<sweep>/sweep.h5`` holds one table (a dataset per numeric summary key, one row per case,
plus the varied inputs), ``OUT/<sweep>/sweep.csv`` the same table for a spreadsheet, and
``OUT/<sweep>/sweep.png`` plots a chosen result (default the flutter speed,
``flutter.critical_speed_m_s``, when the flutter stage ran) against the main span.
"""

from __future__ import annotations

import sys

if __name__ == "__main__":
    from bridge.interrupts import stop_quietly_while_loading

    stop_quietly_while_loading()

import argparse
import itertools
import json
import math
import os
import re
import signal
import tempfile
import time
from collections.abc import Sequence
from concurrent.futures import as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .config import AERODYNAMIC_CHOICES, check_name, load_scenario, with_aerodynamics
from .errors import ConvergenceError, InputError
from .interrupts import Interrupts, exit_command
from .workers import worker_pool

__all__ = ["Case", "plan_cases", "run_case", "run_sweep", "collect", "main"]


@dataclass(frozen=True)
class Case:
    """One run of a sweep: the scenario, its main span (None: the file's) and dotted-key overrides."""

    scenario: str
    main_span_m: float | None
    overrides: tuple[tuple[str, Any], ...]
    aerodynamics: str | None = None   # --aerodynamics: the flutter stage's, for every case (not in the name)

    def load(self):
        """The case's validated scenario (:func:`bridge.config.load_scenario`)."""
        sc = load_scenario(self.scenario, main_span_m=self.main_span_m, overrides=dict(self.overrides))
        return with_aerodynamics(sc, self.aerodynamics)

    @property
    def name(self) -> str:
        parts = [Path(self.scenario).stem]
        if self.main_span_m is not None:
            parts.append(f"L{self.main_span_m:g}")
        parts += [f"{k}={v}" for k, v in self.overrides]
        return re.sub(r"[^A-Za-z0-9._=-]", "_", "__".join(parts))


def _parse_value(text: str) -> Any:
    for conv in (int, float):
        try:
            return conv(text)
        except ValueError:
            pass
    return text


def plan_cases(scenario: str, spans: Sequence[float] | None, vary: dict[str, list[Any]],
               aerodynamics: str | None = None) -> list[Case]:
    """The cartesian product of spans and varied values, in a stable order."""
    span_list: list[float | None] = list(spans) if spans else [None]
    keys = list(vary)
    cases = []
    for span in span_list:
        for values in itertools.product(*(vary[k] for k in keys)) if keys else [()]:
            cases.append(Case(scenario, span, tuple(zip(keys, values, strict=True)), aerodynamics))
    return cases


def case_key(case: Case, stages: list[str] | None, quick: bool) -> str:
    """What a finished case must have been run with to be skipped on resume: the cache keys of its planned
    stages (their inputs, the input files they read, their code, ``quick``) and the program version."""
    import hashlib

    from . import __version__
    from .pipeline import stage_keys
    from .stages import RunOptions

    sc = case.load()
    keys = stage_keys(sc, stages, RunOptions(quick=quick))
    blob = json.dumps({"stages": keys, "version": __version__}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()


def _finished_with(folder: Path) -> str | None:
    try:
        return json.loads((folder / "summary.json").read_text()).get("run.key")
    except (OSError, ValueError, AttributeError):
        return None


_STOPPING = None  # in a worker process: the sweep's "stop" event (set by the parent on Ctrl-C)


def _worker_start(stopping=None) -> None:
    """Sweep worker processes leave Ctrl-C to the parent, which asks each running case to stop and
    sets ``stopping`` so that cases already handed to the pool's queue are not started."""
    global _STOPPING
    _STOPPING = stopping
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def run_case(case: Case, out_dir: str, stages: list[str] | None, quick: bool,
             cache_dir: str | None = None) -> tuple[str, str]:
    """Run one case (in a worker process) and return (case name, "done" | "skipped" | "interrupted" |
    error line).  A case is skipped only if its folder holds a finished run of the same inputs and
    stages (:func:`case_key`); a folder from other inputs is replaced (files the program did not
    write stay)."""
    from dataclasses import replace

    from .pipeline import run_scenario
    from .stages import RunOptions

    previous = signal.getsignal(signal.SIGINT)
    in_worker = previous is signal.SIG_IGN
    if in_worker:  # a running case stops on Ctrl-C (the parent forwards it), cleaning up after itself
        signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        if in_worker and _STOPPING is not None and _STOPPING.is_set():
            raise KeyboardInterrupt   # queued before the Ctrl-C, which cancel() cannot take back
        key = case_key(case, stages, quick)
        folder = Path(out_dir) / case.name
        if _finished_with(folder) == key:
            return case.name, "skipped"
        sc = case.load()
        sc = replace(sc, name=case.name)
        _, outputs = run_scenario(sc, Path(out_dir), stages,
                                  RunOptions(quick=quick, cache=Path(cache_dir) if cache_dir else None),
                                  overwrite=True, run_key=key)
    except (InputError, ConvergenceError) as err:
        return case.name, f"error: {err}"
    except Exception as err:   # any other failure of one case is that case's error: the others go on
        return case.name, f"error: {type(err).__name__}: {err}"
    except KeyboardInterrupt:
        if not in_worker:
            raise
        return case.name, "interrupted"
    finally:
        if in_worker:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
    reused = [name for name, out in outputs.items() if out.from_cache]
    return case.name, "done" + _result_words(outputs) + (f" (from the cache: {', '.join(reused)})" if reused else "")


def _result_words(outputs) -> str:
    """What a finished case found, for its line on the terminal: the flutter speed and its modes (or that
    none was found), else the first frequency or the cable force - the headline's first line."""
    from .results import headline

    summary = {k: v for out in outputs.values() for k, v in out.summary.items()}
    first = headline(summary)[:1]
    return f": {first[0]}" if first else ""


def _as_float(value: Any) -> float:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else np.nan


def _label(key: str) -> str:
    """Axis label of a summary key: the comparison table's label where it has one, else the key."""
    from .scenario import COMPARISON_ROWS

    return next((label for k, label, _ in COMPARISON_ROWS if k == key), key)


def collect(cases: list[Case], cases_dir: Path, sweep_dir: Path, plot_key: str | None,
            keys: dict[str, str] | None = None) -> Path:
    """Gather every finished case's summary into ``sweep.h5`` and ``sweep.csv`` and plot ``plot_key``
    against the main span (``sweep.png``).  A ``plot_key`` that is no numeric result of any finished
    case is an InputError, raised before anything is written.  With ``keys`` (case name -> run key) a
    case folder holding a run of other inputs counts as not finished."""
    import csv
    import io

    import h5py

    from .files import atomic_write_bytes, atomic_write_text, file_mode

    rows = []
    for c in cases:
        f = cases_dir / c.name / "summary.json"
        row = json.loads(f.read_text()) if f.is_file() else None
        if row is not None and keys is not None and row.get("run.key") != keys.get(c.name):
            row = None   # a result of other inputs (this run's case failed): not this sweep's
        rows.append(row)
    numeric = sorted({k for r in rows if r for k, v in r.items()
                      if isinstance(v, (int, float)) and not isinstance(v, bool)})
    if plot_key is not None and plot_key not in numeric:
        shown = ", ".join(numeric[:12]) + (", ..." if len(numeric) > 12 else "")
        raise InputError("--plot", plot_key, f"not a numeric result of this sweep; available: {shown or 'none'}")
    varied = sorted({k for c in cases for k, _ in c.overrides})
    fd, tmp = tempfile.mkstemp(dir=sweep_dir, prefix=".sweep.", suffix=".h5")
    os.close(fd)
    try:
        with h5py.File(tmp, "w") as h5:
            h5.attrs["description"] = "one row per case; NaN where a case failed or lacks the quantity"
            h5.create_dataset("case", data=np.array([c.name for c in cases], dtype=h5py.string_dtype()))
            h5.create_dataset("finished", data=np.array([r is not None for r in rows]))
            inputs = h5.create_group("inputs")
            inputs.create_dataset("main_span_m", data=np.array(
                [np.nan if c.main_span_m is None else c.main_span_m for c in cases]))
            for key in varied:
                vals = [dict(c.overrides).get(key) for c in cases]
                if all(isinstance(v, (int, float)) for v in vals):
                    inputs.create_dataset(key, data=np.array(vals, dtype=float))
                else:
                    inputs.create_dataset(key, data=np.array([str(v) for v in vals], dtype=h5py.string_dtype()))
            results = h5.create_group("results")
            for key in numeric:  # null (e.g. no flutter for a pair) and missing values become NaN
                results.create_dataset(key, data=np.array([_as_float(r.get(key)) if r else np.nan for r in rows]))
        os.chmod(tmp, file_mode())
        os.replace(tmp, sweep_dir / "sweep.h5")
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise

    text = io.StringIO()
    w = csv.writer(text, lineterminator="\n")
    w.writerow(["case", "finished", "main_span_m", *varied, *numeric])
    for c, r in zip(cases, rows, strict=True):
        over = dict(c.overrides)
        w.writerow([c.name, r is not None, "" if c.main_span_m is None else c.main_span_m,
                    *(over.get(k, "") for k in varied),
                    *("" if not r or math.isnan(_as_float(r.get(k))) else r.get(k) for k in numeric)])
    atomic_write_text(sweep_dir / "sweep.csv", text.getvalue())

    if plot_key is None:
        plot_key = next((k for k in ("flutter.critical_speed_m_s", "fem.frequency_S_V1_hz",
                                     "cable.horizontal_force_total_N") if k in numeric), None)
    if plot_key is not None:
        import matplotlib

        matplotlib.use("Agg")
        from matplotlib.figure import Figure

        fig = Figure(figsize=(6.4, 4.2), layout="constrained")
        ax = fig.subplots()
        spans = [r.get("scenario.main_span_m", np.nan) if r else np.nan for r in rows]
        ys = [_as_float(r.get(plot_key)) if r else np.nan for r in rows]
        labels = sorted({tuple(c.overrides) for c in cases}, key=repr)
        for lab in labels:
            idx = [i for i, c in enumerate(cases) if tuple(c.overrides) == lab]
            order = sorted(idx, key=lambda i: spans[i])
            text_label = ", ".join(f"{k} = {v}" for k, v in lab) or Path(cases[0].scenario).stem
            ax.plot([spans[i] for i in order], [ys[i] for i in order], "o-", label=text_label)
        ax.set_xlabel("main span L [m]")
        ax.set_ylabel(_label(plot_key))
        ax.set_title(f"{sweep_dir.name}: {_label(plot_key).split(' [')[0]} against main span", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=120)
        atomic_write_bytes(sweep_dir / "sweep.png", buf.getvalue())
    return sweep_dir / "sweep.h5"


def run_sweep(cases: list[Case], sweep_dir: Path, stages: list[str] | None = None, quick: bool = False,
              workers: int = 2, scheduler: str | None = None, say=print,
              cache_dir: Path | None = None) -> dict[str, str]:
    """Run all cases (skipping finished ones) locally or on a Dask cluster; return case -> status.

    ``cache_dir``: the stage cache shared by the cases (:mod:`bridge.cache`; None: no cache).  On Ctrl-C
    the running cases are asked to stop (each cleans up after itself), the ones not started are
    cancelled, and KeyboardInterrupt is raised with the finished cases in place.
    """
    import multiprocessing

    cases_dir = sweep_dir / "cases"
    cases_dir.mkdir(parents=True, exist_ok=True)
    status: dict[str, str] = {}
    if cache_dir is not None:   # for the cases still to run (a resumed sweep's finished ones need nothing)
        todo = [c for c in cases if _finished_with(cases_dir / c.name) != case_key(c, stages, quick)]
        run_shared_stages(todo, stages, quick, Path(cache_dir), say, scheduler)
    t0 = time.perf_counter()
    cache = None if cache_dir is None else str(cache_dir)

    def report(name: str, state: str) -> None:
        status[name] = state
        say(f"[{len(status)}/{len(cases)}] {name}: {state} ({time.perf_counter() - t0:.0f} s)")

    if scheduler:
        from .cluster import connect

        client = connect(scheduler)   # first: an InputError if Dask is not installed
        from distributed import as_completed as dask_completed

        futures = client.map(run_case, cases, out_dir=str(cases_dir), stages=stages, quick=quick,
                             cache_dir=cache, pure=False)
        try:
            for fut in dask_completed(futures):
                report(*fut.result())
        except BaseException:
            client.cancel(futures)   # the cases not started never start
            raise
        finally:
            client.close()
    elif workers <= 1:
        for c in cases:
            report(*run_case(c, str(cases_dir), stages, quick, cache))
    else:
        context = multiprocessing.get_context()
        stopping = context.Event()   # handed to the workers as they start (inheritance, as Event needs)
        with worker_pool(workers, context, _worker_start, (stopping,), stopping) as pool:
            futs = [pool.submit(run_case, c, str(cases_dir), stages, quick, cache) for c in cases]
            for fut in as_completed(futs):
                report(*fut.result())
    return status


def run_shared_stages(cases: list[Case], stages: list[str] | None, quick: bool, cache_dir: Path, say=print,
                      scheduler: str | None = None) -> int:
    """Compute each shared stage (``Stage.shared``: the aero stage's CFD, which bridges with one deck share) once,
    here, before the cases start, and leave it in the stage cache for them; return how many were run or read.

    Else the cases that start together would all miss the cache and each compute the same CFD, on one core each
    (two workers: twice the work in twice the time).  Here a stage runs as ``python -m bridge.scenario`` runs it,
    with its own parallel cases (or on ``scheduler``) and its progress shown.  A failure is said and left to the
    cases, which report it as their error."""
    from .pipeline import plan_stages, run_stages, stage_keys
    from .stages import STAGES, RunOptions

    options = RunOptions(progress=say, cache=cache_dir, quick=quick, scheduler=scheduler)
    seen: set[str] = set()
    for case in cases:
        scenario = case.load()
        keys = stage_keys(scenario, stages, options)
        for name in plan_stages(scenario, stages):
            if not STAGES[name].shared or keys[name] in seen:
                continue
            seen.add(keys[name])
            say(f"{name}: shared by the cases, computed (or read from the cache) once before they start")
            try:
                run_stages(scenario, [name], options)
            except Exception as err:   # InputError, ConvergenceError or other: each case meets it again
                say(f"{name}: {type(err).__name__}: {err} (the cases that need it will report it)")
    return len(seen)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m bridge.sweep", description=__doc__.split("\n\n")[0],
                                epilog="exit status: 0 done; 1 some cases failed (listed); 2 bad input, nothing "
                                       "run; 130 interrupted (finished cases kept)")
    p.add_argument("scenario", help="scenario name or path (the base of every case)")
    p.add_argument("--main-span", default=None, help="comma-separated main spans in metres")
    p.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2",
                   help="a dotted scenario key and its values (repeatable), "
                        "e.g. girder.mass_per_length_kg_m=14000,16000")
    p.add_argument("--stages", default=None, help="comma-separated stages (default: all for the kind)")
    p.add_argument("--out", default="out", type=Path, help="output folder (default out/)")
    p.add_argument("--name", default=None, help="sweep name (default: derived from the scenario)")
    p.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1), help="local processes")
    p.add_argument("--scheduler", default=None, help="address of an existing Dask scheduler")
    p.add_argument("--plot", default=None, help="summary key to plot against the main span")
    p.add_argument("--no-cache", action="store_true", help="compute every stage afresh (no OUT/.cache/)")
    p.add_argument("--quick", action="store_true", help="coarse meshes/grids")
    p.add_argument("--aerodynamics", choices=AERODYNAMIC_CHOICES, default=None,
                   help="the flutter stage's aerodynamics for every case instead of the scenario's (as for "
                        "python -m bridge.scenario)")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    from .files import check_output_root
    from .pipeline import plan_stages
    from .scenario import parse_stages

    args = build_parser().parse_args(argv)
    say = lambda m: print(m, file=sys.stderr, flush=True)  # noqa: E731
    sweep_dir = None
    with Interrupts() as interrupts:
        try:
            spans = None
            if args.main_span:
                spans = []
                for x in args.main_span.split(","):
                    try:
                        v = float(x)
                    except ValueError:
                        raise InputError("--main-span", x, "must be numbers separated by commas") from None
                    if not (math.isfinite(v) and v > 0):
                        raise InputError("--main-span", x, "must be positive")
                    spans.append(v)
            vary: dict[str, list[Any]] = {}
            for item in args.vary:
                if "=" not in item:
                    raise InputError("--vary", item, "must be KEY=V1,V2,...")
                key, values = item.split("=", 1)
                vary[key.strip()] = [_parse_value(v.strip()) for v in values.split(",") if v.strip()]
                if not vary[key.strip()]:
                    raise InputError("--vary", item, "needs at least one value after '='")
            stages = parse_stages(args.stages)
            cases = plan_cases(args.scenario, spans, vary, args.aerodynamics)
            seen: dict[str, Case] = {}
            for c in cases:
                if c.name in seen:
                    raise InputError("--main-span/--vary", c.name, "two cases of the sweep get this one name "
                                     "(a value given twice, or values that print alike): make them distinct")
                seen[c.name] = c
            if args.name is not None:
                check_name(args.name, "--name")
            planned: set[str] = set()
            for c in cases:  # check every case's input and stages before running any
                sc = c.load()
                planned |= set(plan_stages(sc, stages))
            if args.plot is not None and args.plot.split(".")[0] not in planned | {"scenario"}:
                raise InputError("--plot", args.plot, f"names no result of the stages this sweep runs "
                                 f"({', '.join(sorted(planned))}); keys look like flutter.critical_speed_m_s")
            if args.scheduler is not None:
                from .cluster import connect

                connect(args.scheduler).close()   # a scheduler that does not answer costs nothing
            check_output_root(args.out)
            sweep_dir = args.out / (args.name or f"sweep_{Path(args.scenario).stem}")
            status = run_sweep(cases, sweep_dir, stages, args.quick, args.workers, args.scheduler, say,
                               cache_dir=None if args.no_cache else args.out / ".cache")
            keys = {c.name: case_key(c, stages, args.quick) for c in cases}
            table = collect(cases, sweep_dir / "cases", sweep_dir, args.plot, keys)
            failed = {k: v for k, v in status.items() if v.startswith("error")}
            print(f"sweep table: {table} (also {table.with_suffix('.csv').name}, "
                  f"{'sweep.png' if (sweep_dir / 'sweep.png').is_file() else 'no plot'})")
            for k, v in failed.items():
                print(f"{k}: {v}", file=sys.stderr)
            return 1 if failed else 0
        except InputError as err:
            print(f"error: {err}", file=sys.stderr)
            return 2
        except BaseException:
            where = f" in {sweep_dir / 'cases'}" if sweep_dir is not None else ""
            return interrupts.reported(
                lambda: f"interrupted; finished cases are kept{where} (the same command resumes)")


if __name__ == "__main__":
    exit_command(main())
