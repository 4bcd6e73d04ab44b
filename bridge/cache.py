"""Stage cache: a stage whose inputs have not changed is not computed again.

Each stage's output is stored under a key, the SHA-256 of everything the result depends on:

* the stage's name and the source text of its code (``Stage.code`` in :mod:`bridge.stages`: the
  modules and packages that compute it, plus ``COMMON_CODE``, which writes every stage's output)
  and the program version;
* the scenario inputs (every field of the validated scenario, less ``IDENTITY_FIELDS``, the fields
  the stage declares it ``ignores`` and, for a ``shared`` stage, the scenario's name), and the bytes
  of every input file the scenario names (``*_path`` keys, e.g. a measured aerodynamic table);
* the keys of the upstream stages it reads (a key fixes its output: same inputs, same code);
* the run options that change results (``quick``, ``quality``).

A stored entry is a folder ``<cache>/<stage>/<key>/`` with ``output.pkl`` (summary, report, the stage's
HDF5 group as a file image, its figures as PNG bytes, and the Python result object that later stages
read).  Entries are written to a temporary folder and renamed into place: a reader sees a whole entry
or none.  Delete the cache folder at any time; it only costs the recomputation.  Pickle is used for
the result objects: the cache is the user's own folder, never a file from elsewhere.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import pickle
import shutil
import tempfile
from collections.abc import Mapping
from dataclasses import replace
from functools import cache
from importlib.util import find_spec
from pathlib import Path
from typing import Any

from . import __version__
from .stages import IDENTITY_FIELDS, STAGES, StageOutput

__all__ = ["stage_key", "store", "load", "save", "StoredGroup", "CACHE_FORMAT"]

CACHE_FORMAT = "1"  # bump when the entry layout changes
COMMON_CODE = ("bridge.cache", "bridge.errors", "bridge.results", "bridge.stages")


@cache
def _code_digest(modules: tuple[str, ...]) -> str:
    """SHA-256 over the source files of the given modules and packages (packages: every .py inside)."""
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


def _file_digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def stage_key(name: str, scenario: Any, upstream_keys: Mapping[str, str], quick: bool,
              quality: str | None = None) -> str:
    """The cache key of stage ``name`` for this scenario (see the module docstring)."""
    from .config import scenario_fields

    stage = STAGES[name]
    skip = set(IDENTITY_FIELDS) | set(stage.ignores) | ({"name"} if stage.shared else set())
    inputs = {k: (v.tolist() if hasattr(v, "tolist") else v)
              for k, v in scenario_fields(scenario, include_none=True).items()
              if (top := k.split(".")[0].split("[")[0]) not in skip and (stage.uses is None or top in stage.uses)}
    files = {}
    base = Path(scenario.source_path).parent if getattr(scenario, "source_path", None) else Path.cwd()
    for k, v in inputs.items():
        if k.endswith("_path") and isinstance(v, str):
            p = Path(v) if Path(v).is_absolute() else base / v
            files[k] = _file_digest(p) if p.is_file() else "missing"
    blob = json.dumps({"format": CACHE_FORMAT, "stage": name, "version": __version__,
                       "code": _code_digest(COMMON_CODE + stage.code), "inputs": inputs, "files": files,
                       "upstream": {k: upstream_keys[k] for k in sorted(upstream_keys)}, "quick": bool(quick),
                       **({"quality": quality} if quality is not None else {})},
                      sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()


def _h5_image(write_h5) -> bytes:
    """Run a stage's ``write_h5`` into an in-memory HDF5 file and return the file's bytes."""
    import h5py

    buf = io.BytesIO()
    with h5py.File(buf, "w") as h5:
        write_h5(h5.create_group("stage"))
    return buf.getvalue()


class StoredGroup:
    """A ``write_h5`` that copies a stored HDF5 group (attributes and members) into the target group."""

    def __init__(self, image: bytes):
        self.image = image

    def __call__(self, group) -> None:
        import h5py

        with h5py.File(io.BytesIO(self.image), "r") as h5:
            src = h5["stage"]
            for k, v in src.attrs.items():
                group.attrs[k] = v
            for member in src:
                h5.copy(src[member], group, name=member)


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120, bbox_inches="tight")
    return buf.getvalue()


def store(output: StageOutput) -> StageOutput:
    """The same output with its figures rendered to PNG bytes and its HDF5 group held as a file image:
    a self-contained value that can be pickled, cached and written any number of times."""
    if isinstance(output.write_h5, StoredGroup) and all(isinstance(f, bytes) for f in output.figures.values()):
        return output
    import matplotlib

    matplotlib.use("Agg")
    write_h5 = output.write_h5 if isinstance(output.write_h5, StoredGroup) else StoredGroup(_h5_image(output.write_h5))
    figures = {name: f if isinstance(f, bytes) else _png(f) for name, f in output.figures.items()}
    return replace(output, write_h5=write_h5, figures=figures)


def _entry(root: Path, name: str, key: str) -> Path:
    return Path(root) / name / key


def load(root: Path, name: str, key: str) -> StageOutput | None:
    """The stored output of stage ``name`` under ``key``, or None (also for an unreadable entry)."""
    f = _entry(root, name, key) / "output.pkl"
    if not f.is_file():
        return None
    try:
        with open(f, "rb") as fh:
            d = pickle.load(fh)
    except Exception:  # a damaged or foreign entry is a miss, recomputed and replaced
        return None
    return StageOutput(summary=d["summary"], write_h5=StoredGroup(d["h5_image"]), report=d["report"],
                       figures=d["figures"], data=d["data"], from_cache=True)


def save(root: Path, name: str, key: str, output: StageOutput) -> None:
    """Keep ``output`` (made self-contained by :func:`store`) under ``key``; an existing entry stays."""
    from .files import folder_mode

    final = _entry(root, name, key)
    if final.exists():
        return
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=final.parent, prefix=f".{key[:12]}.", suffix=".tmp"))
    try:
        output = store(output)
        with open(tmp / "output.pkl", "wb") as fh:
            pickle.dump({"summary": output.summary, "report": output.report, "figures": output.figures,
                         "h5_image": output.write_h5.image, "data": output.data}, fh, protocol=pickle.HIGHEST_PROTOCOL)
        os.chmod(tmp, folder_mode())
        try:
            os.replace(tmp, final)
        except OSError:  # another process stored the same entry first: keep theirs
            shutil.rmtree(tmp, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
