"""Files the program writes: one permission for all, atomic replacement, output folders checked first.

Every result file is written under a temporary name in its final folder and renamed into place, so a
reader (or a crash) never sees half a file.  All files get the mode a plain ``open(..., "w")`` would give
under the user's umask (``0o666 & ~umask``, usually 0644): ``tempfile.mkstemp`` alone would leave 0600.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .errors import InputError

__all__ = ["file_mode", "folder_mode", "atomic_write_bytes", "atomic_write_text", "check_output_root"]


def _umask() -> int:
    mask = os.umask(0o022)  # the only portable way to read it is to set it: put it straight back
    os.umask(mask)
    return mask


def file_mode() -> int:
    """Mode of a new regular file under the current umask (0644 with the usual umask 022)."""
    return 0o666 & ~_umask()


def folder_mode() -> int:
    """Mode of a new folder under the current umask (0755 with the usual umask 022)."""
    return 0o777 & ~_umask()


def atomic_write_bytes(path: Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder and rename it into place."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, file_mode())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def atomic_write_text(path: Path, text: str) -> Path:
    return atomic_write_bytes(path, text.encode("utf-8"))


def check_output_root(out: Path, option: str = "--out") -> Path:
    """Make sure ``out`` is (or can become) a folder we can write into; raise :class:`InputError` if not.

    Called before any computation, so a bad ``--out`` costs nothing.  Creates the folder (and parents).
    The write test creates and removes one empty temporary file: permission bits alone do not tell
    (root ignores them; read-only mounts ignore them the other way).
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(option, str(out), "is a file, not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(dir=out, prefix=".write-test.")
        os.close(fd)
        os.unlink(probe)
    except OSError as err:
        raise InputError(option, str(out), f"cannot write there ({err.strerror or err})") from None
    return out
