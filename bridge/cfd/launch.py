"""Row-kernel launcher: splits the rows of a launch over CPU threads (the CPU backend runs one
launch on one thread; two Python threads launching over half the rows each use both cores, with
identical results, docs/warp_cpu.md). On CUDA a launch covers all rows at once (no splitting).

Launches are recorded once and replayed: a plain ``wp.launch`` packs every argument again (~30-50 us
for the solver's 20-argument kernels, ~1.3 ms per time step), a recorded ``Launch`` replays in
~8 us and only the scalar arguments that changed since the last call are re-packed. The record is
keyed by the kernel, the launch size, the identity of the array arguments and the integer
arguments (so the row chunks that run at the same time have separate records), and it holds
references to those arrays, so an identity cannot be reused while its record exists (NumPy
integers are keyed by value like Python ints; at most ``MAX_RECORDS`` records are kept).

The first launch of a kernel loads its module; two threads doing that at once crash the process
(segmentation fault, seen in CI), so recording and first launches hold a lock. Replays do not.
"""

from __future__ import annotations

import operator
import threading
from collections import OrderedDict
from concurrent.futures import ThreadPoolExecutor

import warp as wp

__all__ = ["RowLauncher", "ROW0"]


class _Row0:
    def __repr__(self):
        return "ROW0"


ROW0 = _Row0()  # placeholder in an input list for the first row of a chunk


class _Recorded:
    """A recorded launch and the scalar arguments it was last packed with."""

    __slots__ = ("cmd", "scalars", "arrays")

    def __init__(self, cmd, scalars, arrays):
        self.cmd, self.scalars = cmd, scalars
        self.arrays = arrays  # keeps the ids in the key from being reused while the record exists


def _key_part(a):
    """Array arguments by identity, integers (Python or NumPy) by value, floats not at all."""
    if isinstance(a, wp.array):
        return id(a)
    if isinstance(a, float):
        return None
    try:
        return operator.index(a)
    except TypeError:
        return None


class RowLauncher:
    """Launch row kernels over ``threads`` CPU threads (1 on CUDA)."""

    MAX_RECORDS = 256  # least recently used records beyond this are dropped

    def __init__(self, device: str | None = None, threads: int = 2, record: bool = True):
        from ..warp_setup import init_warp

        init_warp("cpu" if device is None else str(device))
        self.device = wp.get_device(device)
        if threads < 1:
            raise ValueError(f"threads: must be >= 1, got {threads}")
        self.threads = threads if self.device.is_cpu else 1
        self._pool = ThreadPoolExecutor(self.threads - 1) if self.threads > 1 else None
        self.record = record
        self._records: OrderedDict = OrderedDict()
        self._lock = threading.Lock()
        self._loaded: set = set()  # kernels launched once without recording

    def _launch(self, kernel, dim: int, args: list):
        if dim == 0:
            return
        if not self.record:
            if kernel not in self._loaded:
                with self._lock:  # the first launch loads the module: one thread at a time
                    wp.launch(kernel, dim=dim, inputs=args, device=self.device)
                    self._loaded.add(kernel)
                return
            wp.launch(kernel, dim=dim, inputs=args, device=self.device)
            return
        # integer arguments (row offsets, ranges, flags) are part of the key: the row chunks of one
        # launch must never share a record, they run at the same time
        key = (kernel, dim, tuple(_key_part(a) for a in args))
        scalars = [(i, a) for i, a in enumerate(args) if not isinstance(a, wp.array)]
        with self._lock:
            # recording loads the kernel's module: two threads must not do that at once (a
            # concurrent first load of a module crashes the process)
            rec = self._records.get(key)
            if rec is None:
                cmd = wp.launch(kernel, dim=dim, inputs=args, device=self.device, record_cmd=True)
                rec = _Recorded(cmd, scalars, [a for a in args if isinstance(a, wp.array)])
                self._records[key] = rec
                if len(self._records) > self.MAX_RECORDS:
                    self._records.popitem(last=False)
                rec.cmd.launch()
                return
            self._records.move_to_end(key)
        for (i, a), (_, old) in zip(scalars, rec.scalars, strict=True):
            if type(a) is not type(old) or not (isinstance(a, int | float) and a == old):
                rec.cmd.set_param_at_index(i, a)
        rec.scalars = scalars
        rec.cmd.launch()

    @property
    def n_records(self) -> int:
        """Launches recorded and kept for replay."""
        return len(self._records)

    def forget(self):
        """Drop every recorded launch (and the array references the records hold)."""
        with self._lock:
            self._records.clear()

    def rows(self, kernel, n_rows: int, row_start: int, inputs: list, min_split: int = 64):
        """Launch ``kernel`` for rows row_start .. row_start + n_rows - 1 (ROW0 marks the row input)."""
        k = inputs.index(ROW0)
        if self._pool is None or n_rows < min_split:
            args = list(inputs)
            args[k] = row_start
            self._launch(kernel, n_rows, args)
            return
        bounds = [row_start + (n_rows * t) // self.threads for t in range(self.threads + 1)]
        calls = []
        for t in range(self.threads):
            args = list(inputs)
            args[k] = bounds[t]
            calls.append((bounds[t + 1] - bounds[t], args))
        # chunks 1.. go to the pool, chunk 0 runs here (one thread hand-off less per launch)
        futures = [self._pool.submit(self._launch, kernel, d, a) for d, a in calls[1:]]
        try:
            self._launch(kernel, *calls[0])
        finally:
            for f in futures:
                f.result()

    def once(self, kernel, dim: int, inputs: list):
        """Plain single launch (small boundary or box kernels)."""
        self._launch(kernel, dim, list(inputs))
