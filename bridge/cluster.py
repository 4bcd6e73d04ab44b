"""The aero stage's CFD cases on an existing Dask cluster (``--scheduler ADDRESS``; a sweep uses :func:`connect`).

Dask's ``distributed`` (the optional extra ``pip install -e ".[dask]"``) runs tasks on workers that may sit
on other machines, so a user with more machines runs the aero stage in the time of its longest case.  What
local worker processes get from :mod:`bridge.workers` is rebuilt here for a cluster:

* **progress**: a task puts its lines on a Dask queue that the caller drains twice a second;
* **stop**: on Ctrl-C, or when a task fails, the caller sets a Dask event and cancels the tasks not started;
  a running CFD case checks the event between two steps (at most once a second, :class:`StopCheck`) and
  ends, so no worker of the cluster computes on for nobody (a sweep's case, a whole scenario run, has no
  such check: on Ctrl-C the cases not started are cancelled, the running ones finish);
* **errors**: a task's exception reaches the caller as the task raised it (:mod:`bridge.errors` pickles).

The workers need this package installed (the same version).  A case writes its checkpoints to the caller's
checkpoint folder at the same path on its worker, so an interrupted run resumes from them where that path
is a shared file system; a worker that cannot write there runs its case without checkpoints and says so.

A local Dask cluster for trying it: ``dask scheduler`` in one terminal,
``dask worker tcp://127.0.0.1:8786 --nthreads 1 --nworkers 2`` in another.
"""

from __future__ import annotations

import contextlib
import time
import uuid
from collections.abc import Callable, Sequence
from typing import Any

from .errors import InputError

__all__ = ["connect", "worker_threads", "run_on_cluster", "StopCheck", "CaseStopped"]

CONNECT_TIMEOUT_S = 10


class CaseStopped(RuntimeError):
    """A task on the cluster that ended because the caller asked it to (:class:`StopCheck`)."""


def connect(address: str):
    """A Dask client of the scheduler at ``address``, or an InputError on ``--scheduler`` saying why not:
    Dask not installed, not an address, or no scheduler answering there within ``CONNECT_TIMEOUT_S``."""
    try:
        from distributed import Client
    except ImportError:
        raise InputError("--scheduler", address, 'needs Dask: pip install -e ".[dask]"') from None
    try:
        return Client(address, timeout=CONNECT_TIMEOUT_S)
    except ValueError as err:
        raise InputError("--scheduler", address, f"not a scheduler's address ({err}); e.g. tcp://host:8786") from None
    except (OSError, TimeoutError) as err:
        raise InputError("--scheduler", address, f"no Dask scheduler answers there within {CONNECT_TIMEOUT_S} s "
                         f"({type(err).__name__}: {err}); start one (dask scheduler) or check the address") from None


class StopCheck:
    """Called between two steps of a task on the cluster: raises :class:`CaseStopped` once the caller has set
    the run's stop event; asks the scheduler at its first call, then at most once every ``every_s`` seconds."""

    def __init__(self, event_name: str, every_s: float = 1.0):
        from distributed import Event

        self.event, self.every_s, self.next = Event(event_name), every_s, 0.0

    def __call__(self, *_) -> None:
        now = time.monotonic()
        if now < self.next:
            return
        self.next = now + self.every_s
        if self.event.is_set():
            raise CaseStopped("stopped by the caller")


def _task(fn: Callable, args: tuple, queue_name: str, event_name: str):
    """On a worker: ``fn(*args, progress=..., stop=...)`` with the run's queue and stop event."""
    from distributed import Queue

    stop = StopCheck(event_name)
    stop()   # a task that starts after the stop ends at once
    queue = Queue(queue_name)
    try:
        return fn(*args, progress=queue.put, stop=stop)
    finally:
        queue.close()   # the scheduler drops the queue once no one holds it


def worker_threads(client) -> int:
    """The threads of the cluster's workers: how many tasks run at once."""
    return max(1, sum(client.nthreads().values()))


def run_on_cluster(client, fn: Callable, calls: Sequence[tuple], progress: Callable[[str], None] | None = None,
                   finished: Callable[[int, Any], None] | None = None) -> list:
    """``fn(*args, progress=, stop=)`` for every ``args`` of ``calls`` on the Dask cluster of ``client``
    (:func:`connect`); the results in the calls' order.  ``fn`` passes ``stop`` (a callable) to a point it
    reaches often and its lines to ``progress``, which reach the caller's ``progress`` here;
    ``finished(i, result)`` is called as each call ends.  A failed call stops the others and its error is
    raised here; so is an interrupt."""
    from distributed import Event, Queue

    run = uuid.uuid4().hex
    queue_name, event_name = f"bridge-progress-{run}", f"bridge-stop-{run}"
    queue, stop = Queue(queue_name, client=client), Event(event_name, client=client)

    def drain() -> None:
        while progress is not None and queue.qsize():
            for line in queue.get(batch=True):
                progress(line)

    futures = [client.submit(_task, fn, args, queue_name, event_name, pure=False) for args in calls]
    results: dict[int, Any] = {}
    try:
        while len(results) < len(futures):
            time.sleep(0.5)
            drain()
            for i, f in enumerate(futures):
                if i not in results and f.done():
                    results[i] = f.result()   # a failed call raises its error here (the others are stopped below)
                    if finished is not None:
                        finished(i, results[i])
        drain()
        stop.clear()   # nothing is left to stop: the scheduler forgets the event
        return [results[i] for i in range(len(futures))]
    except BaseException:
        try:
            stop.set()
        finally:
            client.cancel(futures)
            with contextlib.suppress(Exception):
                drain()   # the lines that came before the stop
        raise
    finally:
        with contextlib.suppress(Exception):
            queue.close()
