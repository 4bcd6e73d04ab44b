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

A stored entry is one HDF5 file ``<cache>/<stage>/<key>/entry.h5`` holding data only, since result
folders, cache included, travel between people: attributes ``format``, ``stage`` and ``key`` (the entry's
own), ``summary`` (JSON text), ``report`` (text), ``figures/<file name>`` (the PNG or other file's bytes,
uint8), ``h5_image`` (the stage's HDF5 group as an HDF5 file image, uint8) and ``data``, the result object
that later stages read, encoded by :mod:`bridge.datastore` (arrays and JSON; reading instantiates only
data containers and the result classes of ``bridge``, never code a file names).  Nothing is unpickled.
An entry that does not read back as this stage's data (damaged, of another format, made for another
key, or naming a type that is not data) is :class:`UnreadableEntry`: the pipeline says so in one line,
computes the stage again and replaces the entry.  Entries are written to a temporary folder and renamed
into place: a reader sees a whole entry or none.  Delete the cache folder at any time; it only costs
the recomputation.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import shutil
import tempfile
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from . import __version__, datastore
from .stages import IDENTITY_FIELDS, STAGES, StageOutput, code_digest

__all__ = ["stage_key", "store", "load", "save", "StoredGroup", "UnreadableEntry", "CACHE_FORMAT", "ENTRY"]

CACHE_FORMAT = "2"  # bump when the entry layout changes
ENTRY = "entry.h5"  # the file of an entry, in its folder <cache>/<stage>/<key>/
COMMON_CODE = ("bridge.cache", "bridge.datastore", "bridge.errors", "bridge.results", "bridge.stages")


class UnreadableEntry(Exception):
    """A stored entry that does not read back as its stage's data; ``path`` is the entry (its file, or
    its folder when the file is missing), ``reason`` one line on what is wrong."""

    def __init__(self, path: Path, reason: str):
        super().__init__(f"{path}: {reason}")
        self.path, self.reason = path, reason


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
    base = Path(scenario.source_path).parent if scenario.source_path else Path.cwd()
    for k, v in inputs.items():
        if k.endswith("_path") and isinstance(v, str):
            p = Path(v) if Path(v).is_absolute() else base / v
            files[k] = _file_digest(p) if p.is_file() else "missing"
    blob = json.dumps({"format": CACHE_FORMAT, "stage": name, "version": __version__,
                       "code": code_digest(COMMON_CODE + stage.code), "inputs": inputs, "files": files,
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
    a self-contained value that can be cached and written any number of times."""
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
    """The stored output of stage ``name`` under ``key``; None when nothing is stored there.

    An entry folder whose ``entry.h5`` is missing or does not read back as this stage's data (any
    failure to decode it) raises :class:`UnreadableEntry`; :func:`save` with ``replace_unreadable=True``
    then replaces it.  Any other file in the folder (e.g. an ``output.pkl`` of an older format) is never read.
    """
    folder = _entry(root, name, key)
    if not folder.exists():
        return None
    f = folder / ENTRY
    if not f.is_file():
        raise UnreadableEntry(folder, f"no {ENTRY} in it")
    try:
        return _read_entry(f, name, key)
    except Exception as exc:  # a damaged or foreign entry: recomputed and replaced
        reason = str(exc) if isinstance(exc, datastore.DataError) else f"{type(exc).__name__}: {exc}"
        raise UnreadableEntry(f, " ".join(reason.split())) from None


def _read_entry(f: Path, name: str, key: str) -> StageOutput:
    import h5py

    member = datastore.member
    def text(group, member_name: str) -> str:
        ds = member(group, member_name, h5py.Dataset)
        if ds.shape != () or ds.dtype.kind not in "OS":
            raise datastore.DataError(f"{member_name}: not text")
        raw = ds[()]
        return raw.decode() if isinstance(raw, bytes) else str(raw)

    def octets(ds) -> bytes:
        if ds.dtype != "uint8" or ds.ndim != 1:
            raise datastore.DataError(f"{ds.name}: not bytes (uint8)")
        return ds[()].tobytes()

    with h5py.File(f, "r") as h5:
        fmt, stage, made_for = (h5.attrs.get(k) for k in ("format", "stage", "key"))
        if (fmt, stage, made_for) != (CACHE_FORMAT, name, key):
            raise datastore.DataError(f"an entry of format {fmt!r} for the stage {stage!r} under the key "
                                      f"{str(made_for)[:12]!r}..., not of format {CACHE_FORMAT!r} for this one")
        summary = json.loads(text(h5, "summary"))
        if type(summary) is not dict or not all(type(v) in (float, int, bool, str, type(None))
                                                for v in summary.values()):
            raise datastore.DataError("summary: not a table of numbers, flags and text")
        report = text(h5, "report")
        figures_group = member(h5, "figures", h5py.Group)
        figures = {fig: octets(member(figures_group, fig, h5py.Dataset)) for fig in figures_group}
        image = octets(member(h5, "h5_image", h5py.Dataset))
        data = datastore.read(member(h5, "data", h5py.Group))
    return StageOutput(summary=summary, write_h5=StoredGroup(image), report=report, figures=figures, data=data,
                       from_cache=True)


def _write_entry(f: Path, name: str, key: str, output: StageOutput) -> None:
    import h5py
    import numpy as np

    with h5py.File(f, "w") as h5:
        h5.attrs.update({"format": CACHE_FORMAT, "stage": name, "key": key})
        h5["summary"] = json.dumps(output.summary, default=_plain)
        h5["report"] = output.report
        figures = h5.create_group("figures", track_order=True)
        for fig, content in output.figures.items():
            figures[fig] = np.frombuffer(content, dtype=np.uint8)
        h5["h5_image"] = np.frombuffer(output.write_h5.image, dtype=np.uint8)
        datastore.write(h5.create_group("data"), output.data)


def _plain(value: Any) -> Any:
    """A numpy number of a summary as the Python number it is."""
    if hasattr(value, "item") and getattr(value, "shape", None) == ():
        return value.item()
    raise TypeError(f"summary value {value!r} of type {type(value).__name__} is not a number, flag or text")


def save(root: Path, name: str, key: str, output: StageOutput, replace_unreadable: bool = False) -> None:
    """Keep ``output`` (made self-contained by :func:`store`) under ``key``.  An existing entry stays,
    unless ``replace_unreadable`` (it was :class:`UnreadableEntry`): then the new one takes its place.
    Data that cannot be stored (:mod:`bridge.datastore`) is a :class:`bridge.datastore.DataError`, and
    nothing is kept."""
    from .files import folder_mode

    final = _entry(root, name, key)
    if final.exists() and not replace_unreadable:
        return
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=final.parent, prefix=f".{key[:12]}.", suffix=".tmp"))
    try:
        _write_entry(tmp / ENTRY, name, key, store(output))
        os.chmod(tmp, folder_mode())
        aside = None
        if final.exists():   # replace: move the unreadable entry out of the way, then put the new one there
            aside = Path(tempfile.mkdtemp(dir=final.parent, prefix=f".{key[:12]}.", suffix=".replaced.tmp"))
            try:
                os.replace(final, aside / "entry")
            except OSError:  # another process moved it first
                pass
        try:
            os.replace(tmp, final)
        except OSError:  # another process stored the same entry first: keep theirs
            shutil.rmtree(tmp, ignore_errors=True)
        if aside is not None:
            shutil.rmtree(aside, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
