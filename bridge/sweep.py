"""Parameter sweeps: ``python -m bridge.sweep SCENARIO --main-span 1624,2000,3000,4000 [--vary KEY=V1,V2]``.

Every combination of the listed main spans and ``--vary`` values is one case, run through the pipeline
like ``python -m bridge.scenario`` and written to ``OUT/<sweep>/cases/<case>/``.  The sweep is resumable:
a case whose folder is complete (results are renamed into place only when finished) is skipped.  Cases
run in parallel on local processes (``--workers``, default 2) or on an existing Dask cluster
(``--scheduler tcp://host:8786``; needs the optional extra ``pip install -e ".[dask]"``).

At the end ``OUT/<sweep>/sweep.h5`` holds one table (a dataset per numeric summary key, one row per case,
plus the varied inputs) and ``OUT/<sweep>/sweep.png`` plots a chosen result (default the flutter speed,
``flutter.critical_speed_m_s``, when the flutter stage ran) against the main span.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import re
import sys
import tempfile
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .config import load_scenario
from .errors import ConvergenceError, InputError

__all__ = ["Case", "plan_cases", "run_case", "run_sweep", "collect", "main"]


@dataclass(frozen=True)
class Case:
    """One run of a sweep: the scenario, its main span (None: the file's) and dotted-key overrides."""

    scenario: str
    main_span_m: float | None
    overrides: tuple[tuple[str, Any], ...]

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


def plan_cases(scenario: str, spans: Sequence[float] | None, vary: dict[str, list[Any]]) -> list[Case]:
    """The cartesian product of spans and varied values, in a stable order."""
    span_list: list[float | None] = list(spans) if spans else [None]
    keys = list(vary)
    cases = []
    for span in span_list:
        for values in itertools.product(*(vary[k] for k in keys)) if keys else [()]:
            cases.append(Case(scenario, span, tuple(zip(keys, values, strict=True))))
    return cases


def run_case(case: Case, out_dir: str, stages: list[str] | None, quick: bool) -> tuple[str, str]:
    """Run one case (in a worker process) and return (case name, "done" | "skipped" | error line)."""
    from dataclasses import replace

    from .pipeline import run_scenario
    from .stages import RunOptions

    folder = Path(out_dir) / case.name
    if (folder / "summary.json").is_file():
        return case.name, "skipped"
    try:
        sc = load_scenario(case.scenario, main_span_m=case.main_span_m, overrides=dict(case.overrides))
        sc = replace(sc, name=case.name)
        run_scenario(sc, Path(out_dir), stages, RunOptions(quick=quick))
    except (InputError, ConvergenceError) as err:
        return case.name, f"error: {err}"
    return case.name, "done"


def _as_float(value: Any) -> float:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else np.nan


def collect(cases: list[Case], cases_dir: Path, sweep_dir: Path, plot_key: str | None) -> Path:
    """Gather every finished case's summary into ``sweep.h5`` and plot ``plot_key`` against the main span."""
    import h5py

    rows = []
    for c in cases:
        f = cases_dir / c.name / "summary.json"
        rows.append(json.loads(f.read_text()) if f.is_file() else None)
    numeric = sorted({k for r in rows if r for k, v in r.items()
                      if isinstance(v, (int, float)) and not isinstance(v, bool)})
    fd, tmp = tempfile.mkstemp(dir=sweep_dir, prefix=".sweep.", suffix=".h5")
    os.close(fd)
    with h5py.File(tmp, "w") as h5:
        h5.attrs["description"] = "one row per case; NaN where a case failed or lacks the quantity"
        h5.create_dataset("case", data=np.array([c.name for c in cases], dtype=h5py.string_dtype()))
        h5.create_dataset("finished", data=np.array([r is not None for r in rows]))
        inputs = h5.create_group("inputs")
        inputs.create_dataset("main_span_m", data=np.array(
            [np.nan if c.main_span_m is None else c.main_span_m for c in cases]))
        for key in {k for c in cases for k, _ in c.overrides}:
            vals = [dict(c.overrides).get(key) for c in cases]
            if all(isinstance(v, (int, float)) for v in vals):
                inputs.create_dataset(key, data=np.array(vals, dtype=float))
            else:
                inputs.create_dataset(key, data=np.array([str(v) for v in vals], dtype=h5py.string_dtype()))
        results = h5.create_group("results")
        for key in numeric:  # "none" (e.g. no flutter for a pair) and missing values become NaN
            results.create_dataset(key, data=np.array([_as_float(r.get(key)) if r else np.nan for r in rows]))
    os.replace(tmp, sweep_dir / "sweep.h5")

    if plot_key is None:
        plot_key = next((k for k in ("flutter.critical_speed_m_s", "fem.frequency_S_V1_hz",
                                     "cable.horizontal_force_total_N") if k in numeric), None)
    if plot_key is not None and plot_key in numeric:
        import matplotlib

        matplotlib.use("Agg")
        from matplotlib.figure import Figure

        fig = Figure(figsize=(6, 4))
        ax = fig.subplots()
        spans = [r.get("scenario.main_span_m", np.nan) if r else np.nan for r in rows]
        ys = [_as_float(r.get(plot_key)) if r else np.nan for r in rows]
        labels = sorted({tuple(c.overrides) for c in cases})
        for lab in labels:
            idx = [i for i, c in enumerate(cases) if tuple(c.overrides) == lab]
            order = sorted(idx, key=lambda i: spans[i])
            text = ", ".join(f"{k}={v}" for k, v in lab) or Path(cases[0].scenario).stem
            ax.plot([spans[i] for i in order], [ys[i] for i in order], "o-", label=text)
        ax.set_xlabel("main span L [m]")
        ax.set_ylabel(plot_key)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fd, tmp_png = tempfile.mkstemp(dir=sweep_dir, prefix=".sweep.", suffix=".png")
        os.close(fd)
        fig.savefig(tmp_png, dpi=120, bbox_inches="tight")
        os.replace(tmp_png, sweep_dir / "sweep.png")
    return sweep_dir / "sweep.h5"


def run_sweep(cases: list[Case], sweep_dir: Path, stages: list[str] | None = None, quick: bool = False,
              workers: int = 2, scheduler: str | None = None, say=print) -> dict[str, str]:
    """Run all cases (skipping finished ones) locally or on a Dask cluster; return case -> status."""
    cases_dir = sweep_dir / "cases"
    cases_dir.mkdir(parents=True, exist_ok=True)
    status: dict[str, str] = {}
    t0 = time.perf_counter()

    def report(name: str, state: str) -> None:
        status[name] = state
        say(f"[{len(status)}/{len(cases)}] {name}: {state} ({time.perf_counter() - t0:.0f} s)")

    if scheduler:
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--scheduler", scheduler, 'needs Dask: pip install -e ".[dask]"') from None
        client = Client(scheduler)
        futures = client.map(run_case, cases, out_dir=str(cases_dir), stages=stages, quick=quick, pure=False)
        from distributed import as_completed as dask_completed

        for fut in dask_completed(futures):
            report(*fut.result())
        client.close()
    elif workers <= 1:
        for c in cases:
            report(*run_case(c, str(cases_dir), stages, quick))
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            futs = [pool.submit(run_case, c, str(cases_dir), stages, quick) for c in cases]
            for fut in as_completed(futs):
                report(*fut.result())
    return status


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m bridge.sweep", description=__doc__.split("\n\n")[0])
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
    p.add_argument("--quick", action="store_true", help="coarse meshes/grids")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    say = lambda m: print(m, file=sys.stderr, flush=True)  # noqa: E731
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
        cases = plan_cases(args.scenario, spans, vary)
        for c in cases:  # check every case's input before running any
            load_scenario(c.scenario, main_span_m=c.main_span_m, overrides=dict(c.overrides))
        stages = None if args.stages is None else [s.strip() for s in args.stages.split(",") if s.strip()]
        sweep_dir = args.out / (args.name or f"sweep_{Path(args.scenario).stem}")
        status = run_sweep(cases, sweep_dir, stages, args.quick, args.workers, args.scheduler, say)
        table = collect(cases, sweep_dir / "cases", sweep_dir, args.plot)
        failed = {k: v for k, v in status.items() if v.startswith("error")}
        print(f"sweep table: {table}")
        for k, v in failed.items():
            print(f"{k}: {v}", file=sys.stderr)
        return 1 if failed else 0
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
