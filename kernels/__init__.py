"""Warp kernels only: ``@wp.func`` for pointwise maths, thin ``@wp.kernel`` wrappers.

No orchestration and no I/O here; the ``bridge`` package launches these kernels.

Importing this package sets Warp's log level to warnings: its start-up banner and per-module load lines
would otherwise fill every run's output.  Set ``BRIDGE_WARP_LOG=info`` to see them again.
"""

import os as _os

import warp as _wp

if _os.environ.get("BRIDGE_WARP_LOG", "warning").lower() != "info":
    _wp.config.log_level = _wp.LOG_WARNING
