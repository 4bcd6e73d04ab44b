"""Worker processes that never outlive the program that started them.

The aero stage runs its CFD cases side by side (:func:`bridge.aero.forced_motion.run_cases`) and a sweep
runs its cases side by side (:func:`bridge.sweep.run_sweep`), each in a pool of worker processes.  A
worker left behind computes at full CPU for nobody, so two guards hold:

* **the worker watches its parent** (:func:`watch_parent`, run first in every worker): a thread waits on
  the parent's sentinel (a pipe the parent alone holds open) and ends the worker at once when the parent
  is gone - killed outright (SIGKILL, an out-of-memory kill), or exited without stopping it.  This is the
  guarantee; it needs nothing from the parent.
* **a worker ignores Ctrl-C** (the terminal sends it to the whole process group) from its first instruction
  to the end of its start-up, and then while no task asks for it; the parent forwards it to the running
  tasks (:class:`_Pool`, :func:`_start_worker`);
* **the parent stops its workers** when the run is interrupted (Ctrl-C, SIGTERM through
  :class:`bridge.interrupts.Interrupts`) or a case fails (:func:`worker_pool`): the cases not started are
  cancelled, the running ones receive SIGINT (so that they stop between two steps), and whatever is still
  alive after ``grace_s`` is terminated, then killed.  A second interrupt during that clean-up skips the
  wait and kills them at once.

Only the standard library is used.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import multiprocessing.connection
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor

from .interrupts import sigint_held

__all__ = ["watch_parent", "worker_pool", "stop_processes", "ORPHANED"]

ORPHANED = 70   # a worker's exit status when it ends because its parent is gone (EX_SOFTWARE)


def watch_parent() -> None:
    """In a worker process: end it (``os._exit(ORPHANED)``) as soon as its parent process is gone.

    Waits on the parent's sentinel in a daemon thread; the worker's main thread may be inside a Warp kernel
    or blocked on the pool's pipes, which no signal from a dead parent would reach.  Does nothing outside a
    multiprocessing child."""
    parent = multiprocessing.parent_process()
    if parent is None or getattr(parent, "sentinel", None) is None:
        return

    def wait_for_parent() -> None:
        multiprocessing.connection.wait([parent.sentinel])
        os._exit(ORPHANED)

    threading.Thread(target=wait_for_parent, name="watch-parent", daemon=True).start()


def _start_worker(initializer: Callable | None, initargs: tuple) -> None:
    """First thing in every worker: watch the parent, leave Ctrl-C to the parent (SIGINT ignored until a task
    of the caller's asks for it), run the caller's initializer, then let SIGINT in (it arrives blocked:
    :class:`_Pool`), so that one sent while the worker was still importing is dropped."""
    watch_parent()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if initializer is not None:
        initializer(*initargs)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


class _Pool(ProcessPoolExecutor):
    """A ProcessPoolExecutor that starts its workers with SIGINT blocked.

    Workers start inside ``submit``.  A worker inherits the blocked signal (across fork and exec), so a
    Ctrl-C that reaches the whole process group while a new worker still imports the program - before its
    initializer ignores SIGINT - does not print that import's traceback; the parent's own Ctrl-C waits the
    few milliseconds ``submit`` takes."""

    def submit(self, fn, /, *args, **kwargs):
        with sigint_held():
            return super().submit(fn, *args, **kwargs)


def stop_processes(processes, grace_s: float = 10.0, interrupt: bool = True) -> None:
    """Stop ``processes`` (multiprocessing.Process objects): SIGINT to each (``interrupt``), up to ``grace_s``
    for them to end, then SIGTERM, then SIGKILL.  Returns when every one has ended.  An interrupt that lands
    while waiting skips the wait (the processes are killed) and is raised afterwards."""
    alive = [p for p in processes if p.pid is not None and p.is_alive()]
    try:
        if interrupt:
            for p in alive:
                with contextlib.suppress(OSError):
                    os.kill(p.pid, signal.SIGINT)
            deadline = time.monotonic() + grace_s
            for p in alive:
                p.join(max(0.0, deadline - time.monotonic()))
    finally:
        for p in alive:
            if p.is_alive():
                with contextlib.suppress(OSError):
                    p.terminate()
        deadline = time.monotonic() + 2.0
        for p in alive:
            p.join(max(0.0, deadline - time.monotonic()))
            if p.is_alive():
                with contextlib.suppress(OSError):
                    p.kill()
                p.join(1.0)


@contextlib.contextmanager
def worker_pool(workers: int, context=None, initializer: Callable | None = None, initargs: tuple = (),
                stopping=None, grace_s: float = 10.0) -> Iterator[ProcessPoolExecutor]:
    """A ProcessPoolExecutor whose workers watch their parent (:func:`watch_parent`) and are stopped, never
    left behind, when the block ends with an exception (an interrupt or a failed task).

    ``stopping``: an Event handed to the workers (through ``initargs``) that is set before they are stopped,
    so that a task a worker takes from the queue after the interrupt does not start.  On a normal exit the
    pool is shut down and waited for, as ``with ProcessPoolExecutor(...)`` does."""
    pool = _Pool(max_workers=workers, mp_context=context or multiprocessing.get_context(),
                 initializer=_start_worker, initargs=(initializer, initargs))
    try:
        yield pool
    except BaseException:
        if stopping is not None:
            stopping.set()
        children = multiprocessing.active_children()   # the pool's workers (its manager is a thread)
        # shutdown(wait=False) forgets the pool's manager thread, so the shutdown(wait=True) below would not
        # wait for it: held here, it is joined, else its end (which frees the pool's queues and unlinks their
        # semaphores) could be cut off by the program's exit half-way, and the resource tracker would warn
        # of "leaked" semaphores after the program's last line
        manager = getattr(pool, "_executor_manager_thread", None)
        try:
            pool.shutdown(wait=False, cancel_futures=True)
            stop_processes(children, grace_s)
        finally:
            for p in children:   # a second interrupt above: nothing may stay
                if p.is_alive():
                    with contextlib.suppress(OSError):
                        p.kill()
            with contextlib.suppress(BaseException):
                pool.shutdown(wait=True)
                if manager is not None:
                    manager.join(max(grace_s, 5.0))
        raise
    pool.shutdown(wait=True)
