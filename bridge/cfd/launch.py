"""Row-kernel launcher: splits the rows of a launch over CPU threads (the CPU backend runs one
launch on one thread; two Python threads launching over half the rows each use both cores, with
identical results, WARP_CPU.md). On CUDA a launch covers all rows at once (no splitting).

Launches are recorded once and replayed: a plain ``wp.launch`` packs every argument again (~30-50 us
for the solver's 20-argument kernels, ~1.3 ms per time step), a recorded ``Launch`` replays in
~8 us and only the scalar arguments that changed since the last call are re-packed. The record is
keyed by the kernel, the launch size, the identity of the array arguments and the integer
arguments (so the row chunks that run at the same time have separate records), and it holds
references to those arrays, so an identity cannot be reused while its record exists.
"""

from __future__ import annotations

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

    __slots__ = ("cmd", "scalars")

    def __init__(self, cmd, scalars):
        self.cmd, self.scalars = cmd, scalars


class RowLauncher:
    """Launch row kernels over ``threads`` CPU threads (1 on CUDA)."""

    MAX_RECORDS = 256  # least recently used records beyond this are dropped

    def __init__(self, device: str | None = None, threads: int = 2, record: bool = True):
        self.device = wp.get_device(device)
        if threads < 1:
            raise ValueError(f"threads: must be >= 1, got {threads}")
        self.threads = threads if self.device.is_cpu else 1
        self._pool = ThreadPoolExecutor(self.threads - 1) if self.threads > 1 else None
        self.record = record
        self._records: OrderedDict = OrderedDict()

    def _launch(self, kernel, dim: int, args: list):
        if not self.record:
            wp.launch(kernel, dim=dim, inputs=args, device=self.device)
            return
        # integer arguments (row offsets, ranges, flags) are part of the key: the two row chunks of one
        # launch must never share a record, they run at the same time
        key = (kernel, dim, tuple(id(a) if isinstance(a, wp.array) else a if type(a) is int else None
                                  for a in args))
        rec = self._records.get(key)
        scalars = [(i, a) for i, a in enumerate(args) if not isinstance(a, wp.array)]
        if rec is None:
            rec = _Recorded(wp.launch(kernel, dim=dim, inputs=args, device=self.device, record_cmd=True),
                            scalars)
            self._records[key] = rec
            if len(self._records) > self.MAX_RECORDS:
                self._records.popitem(last=False)
        else:
            self._records.move_to_end(key)
            for (i, a), (_, old) in zip(scalars, rec.scalars, strict=True):
                if type(a) is not type(old) or not (isinstance(a, int | float) and a == old):
                    rec.cmd.set_param_at_index(i, a)
            rec.scalars = scalars
        rec.cmd.launch()

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
