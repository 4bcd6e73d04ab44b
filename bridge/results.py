"""Writing a run's results: ``results.h5``, ``summary.json``, ``report.md`` and PNG plots.

Everything is written into a temporary folder beside the target and renamed into place at the end, so
a failed run leaves no partial results (an earlier complete result of the same scenario is replaced only
once the new one is complete).  The HDF5 schema is documented in ``docs/results.md``.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Mapping
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from . import __version__
from .config import Scenario, scenario_fields
from .stages import StageOutput

__all__ = ["write_results", "write_dataset"]

SCHEMA_VERSION = "1"


def write_dataset(group: h5py.Group, name: str, data: Any, unit: str = "", description: str = "") -> None:
    """Write one dataset with its ``unit`` and ``description`` attributes (strings become UTF-8)."""
    arr = np.asarray(data)
    if arr.dtype.kind in "UO":
        arr = np.asarray(arr, dtype=h5py.string_dtype())
    ds = group.create_dataset(name, data=arr)
    if unit:
        ds.attrs["unit"] = unit
    if description:
        ds.attrs["description"] = description


def _summary_value(v: Any) -> Any:
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    return v


def write_results(out_root: Path, scenario: Scenario, outputs: Mapping[str, StageOutput]) -> Path:
    """Write all stage outputs of ``scenario`` to ``out_root/<scenario.name>/`` atomically; return that folder."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_root.mkdir(parents=True, exist_ok=True)
    final = out_root / scenario.name
    tmp = Path(tempfile.mkdtemp(prefix=f".{scenario.name}.", suffix=".tmp", dir=out_root))
    try:
        stamp = datetime.now(UTC).isoformat(timespec="seconds")
        summary: dict[str, Any] = {"scenario.name": scenario.name, "scenario.kind": scenario.kind,
                                   "stages": list(outputs)}
        with h5py.File(tmp / "results.h5", "w") as h5:
            h5.attrs["schema_version"] = SCHEMA_VERSION
            h5.attrs["program_version"] = __version__
            h5.attrs["created_utc"] = stamp
            h5.attrs["scenario_name"] = scenario.name
            inputs = h5.create_group("scenario")
            for key, value in scenario_fields(scenario).items():  # every input, dotted keys with units
                inputs.attrs[key] = value
            for name, out in outputs.items():
                out.write_h5(h5.create_group(name))
                summary.update({k: _summary_value(v) for k, v in out.summary.items()})
        with open(tmp / "summary.json", "w") as fh:
            json.dump(summary, fh, indent=2, sort_keys=False)
            fh.write("\n")
        report = [f"# {scenario.name}: results", "",
                  f"{scenario.description}  ", f"Written {stamp} by bridge {__version__}; stages: "
                  f"{', '.join(outputs)}.", ""]
        for out in outputs.values():
            report += [out.report.rstrip(), ""]
            for fname, fig in out.figures.items():
                fig.savefig(tmp / fname, dpi=120, bbox_inches="tight")
                plt.close(fig)
                report += [f"![{fname}]({fname})", ""]
        (tmp / "report.md").write_text("\n".join(report))
        os.chmod(tmp, 0o755)
        if final.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{scenario.name}.", suffix=".old", dir=out_root))
            os.replace(final, old / "previous")
            os.replace(tmp, final)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return final
