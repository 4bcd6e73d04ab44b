"""Row-kernel launcher: splits the rows of a launch over CPU threads (the CPU backend runs one
launch on one thread; two Python threads launching over half the rows each use both cores, with
identical results, WARP_CPU.md). On CUDA a launch covers all rows at once (no splitting).
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import warp as wp

__all__ = ["RowLauncher", "ROW0"]


class _Row0:
    def __repr__(self):
        return "ROW0"


ROW0 = _Row0()  # placeholder in an input list for the first row of a chunk


class RowLauncher:
    """Launch row kernels over ``threads`` CPU threads (1 on CUDA)."""

    def __init__(self, device: str | None = None, threads: int = 2):
        self.device = wp.get_device(device)
        if threads < 1:
            raise ValueError(f"threads: must be >= 1, got {threads}")
        self.threads = threads if self.device.is_cpu else 1
        self._pool = ThreadPoolExecutor(self.threads) if self.threads > 1 else None

    def rows(self, kernel, n_rows: int, row_start: int, inputs: list, min_split: int = 64):
        """Launch ``kernel`` for rows row_start .. row_start + n_rows - 1 (ROW0 marks the row input)."""
        k = inputs.index(ROW0)
        if self._pool is None or n_rows < min_split:
            args = list(inputs)
            args[k] = row_start
            wp.launch(kernel, dim=n_rows, inputs=args, device=self.device)
            return
        bounds = [row_start + (n_rows * t) // self.threads for t in range(self.threads + 1)]
        futures = []
        for t in range(self.threads):
            args = list(inputs)
            args[k] = bounds[t]
            futures.append(self._pool.submit(wp.launch, kernel, dim=bounds[t + 1] - bounds[t],
                                             inputs=args, device=self.device))
        for f in futures:
            f.result()

    def once(self, kernel, dim: int, inputs: list):
        """Plain single launch (small boundary or box kernels)."""
        wp.launch(kernel, dim=dim, inputs=inputs, device=self.device)
