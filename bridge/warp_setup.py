"""Starting Warp once, quietly on a CPU-only run.

``wp.init()`` prints "Warp CUDA warning: Could not find or load the NVIDIA CUDA driver" from its C
library straight to the process's standard error on every machine without a GPU (every run here, once
per sweep worker), and Python's own log settings cannot silence a C ``fprintf``.  :func:`init_warp`
keeps that one line out when no CUDA device is asked for (file descriptor 2 is pointed at a temporary
file during ``wp.init()``, and everything else written there is passed on); asked for ``cuda``, Warp
starts as it is and its warning explains why the device is missing.
"""

from __future__ import annotations

import os
import sys
import tempfile

__all__ = ["init_warp"]

_CUDA_WARNING = "Warp CUDA warning:"
_started = False


def init_warp(device: str = "cpu"):
    """Import, configure (:mod:`kernels` sets the log level) and initialise Warp; return the module."""
    global _started
    import warp as wp

    import kernels  # noqa: F401  (sets Warp's log level before its start-up banner)

    if _started:
        return wp
    if str(device).startswith("cuda"):
        wp.init()
    else:
        sys.stderr.flush()
        saved = os.dup(2)
        with tempfile.TemporaryFile(mode="w+b") as capture:
            os.dup2(capture.fileno(), 2)
            try:
                wp.init()
            finally:
                os.dup2(saved, 2)
                os.close(saved)
            capture.seek(0)
            text = capture.read().decode("utf-8", "replace")
        rest = "".join(line for line in text.splitlines(keepends=True) if not line.startswith(_CUDA_WARNING))
        if rest:
            sys.stderr.write(rest)
    _started = True
    return wp
