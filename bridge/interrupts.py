"""Ctrl-C on the command line: one line and exit status 130, wherever it lands; SIGTERM (what a batch
system or a CI time-out sends) is handled the same way, with exit status 143.

Three moments need care:

* while the modules load (the first second after ``python -m bridge.scenario``): nothing has been written,
  so :func:`stop_quietly_while_loading` says so and leaves;
* during the run: :class:`Interrupts` marks the interruption, so that whatever exception it turns into
  (a KeyboardInterrupt, or an ImportError raised half-way through an import) is reported as what it was;
  an interrupt that Python swallows in a destructor or weakref callback ("Exception ignored in ...") is
  delivered again to the main flow;
* at the exit: :func:`exit_command` leaves at once with 130 after the report, so that nothing the
  interrupt left half-done (an import, a clean-up) can turn the exit into a death by SIGINT (seen about
  0.25 s after start, exit status -2).
Worker processes are stopped on the way out (:mod:`bridge.workers`), and end by themselves if the program
is killed outright.
Only the standard library is imported here: this module loads before everything else.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time

__all__ = ["Interrupts", "stop_quietly_while_loading", "exit_command", "sigint_held", "INTERRUPTED", "TERMINATED"]

INTERRUPTED = 128 + signal.SIGINT    # 130, the shell's convention
TERMINATED = 128 + signal.SIGTERM    # 143
_WORDS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated (SIGTERM)"}


def stop_quietly_while_loading() -> None:
    """Until the command installs :class:`Interrupts`: Ctrl-C (or SIGTERM) prints one line and exits with
    130 (143)."""
    for signum in _WORDS:
        signal.signal(signum, lambda n, _: (print(f"{_WORDS[n]}; nothing written", file=sys.stderr),
                                            os._exit(128 + n)))


def exit_command(status: int) -> None:
    """End the process with ``status``; after an interruption, at once (see the module docstring)."""
    if status in (INTERRUPTED, TERMINATED):
        # the semaphores of a worker pool's queues unregister themselves from the resource tracker before
        # the hard exit, as at a normal exit (multiprocessing's own exit hook runs these finalisers), else the
        # tracker warns of them as "leaked"
        mp_util = sys.modules.get("multiprocessing.util")
        if mp_util is not None:
            with contextlib.suppress(Exception):
                mp_util._run_finalizers(0)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    sys.exit(status)


@contextlib.contextmanager
def sigint_held():
    """Ctrl-C held back for the block: one that lands meanwhile is delivered (to the usual handler) when the
    block ends.  For the steps that must not be cut in half (a result folder renamed into place, a worker
    process started and handed its start-up data) and for starting worker processes, which inherit the
    blocked signal (:mod:`bridge.workers`).

    Two things are needed.  Blocking SIGINT in the calling thread is what a child started here inherits.  But
    the signal may reach the process through another thread (a pool's manager thread, a queue's feeder), whose
    C handler only flags it for the main thread's Python handler, which runs at the next bytecode whatever
    this thread's mask: so in the main thread the Python handler is also swapped for one that only notes the
    signal, and the noted one is raised again when the block ends."""
    main = threading.current_thread() is threading.main_thread() and signal.getsignal(signal.SIGINT) is not None
    noted: list[int] = []
    old_handler = signal.signal(signal.SIGINT, lambda signum, frame: noted.append(signum)) if main else None
    masked = hasattr(signal, "pthread_sigmask")
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if masked else None
    try:
        yield
    finally:
        if masked:
            signal.pthread_sigmask(signal.SIG_SETMASK, before)   # a signal pending on this thread lands now
        if main:
            signal.signal(signal.SIGINT, old_handler)
            if noted:
                signal.raise_signal(signal.SIGINT)


class Interrupts:
    """While active, SIGINT and SIGTERM set ``fired`` before raising KeyboardInterrupt, so an exception that
    the interrupt caused elsewhere (a library turning it into an ImportError half-way through an import,
    say) is still reported as the interruption it was, and the clean-up of ``finally`` and ``except``
    blocks (workers stopped, temporary files removed) runs for both.
    """

    def __init__(self):
        self.fired = False
        self.signum = signal.SIGINT     # the first signal received (its exit status is 128 + signum)
        self.finished = False
        self._previous = None
        self._previous_term = None
        self._hook = None
        self._in_hook = False        # the unraisable hook is running (see _handler)
        self._delivered = False      # the handler has raised KeyboardInterrupt in the main flow
        self._redelivering = False

    def finish(self) -> None:
        """The interruption is being reported: further Ctrl-C or SIGTERM (or one re-delivered late) is
        ignored, so the exit status stays 130 (143)."""
        self.finished = True
        with contextlib.suppress(ValueError):
            for signum in _WORDS:
                signal.signal(signum, signal.SIG_IGN)

    def reported(self, message) -> int:
        """After an exception: if it came from the interrupt, print ``message()`` (one line: what was
        kept; it starts with "interrupted", which is replaced by "terminated (SIGTERM)" after SIGTERM) and
        return the exit status 130 (143 after SIGTERM); otherwise re-raise it.  Call from an ``except
        BaseException`` block."""
        if not self.fired:
            raise
        self.finish()
        text = message()
        if self.signum != signal.SIGINT and text.startswith("interrupted"):
            text = _WORDS[self.signum] + text[len("interrupted"):]
        print(text, file=sys.stderr)
        return 128 + self.signum

    def _redeliver(self) -> None:
        """Send SIGINT again until the handler has raised it in the main flow (a signal that lands while
        the unraisable hook still runs is deferred by the handler, so try again), or the command ends."""
        try:
            time.sleep(0.001)
            while not (self.finished or self._delivered):
                os.kill(os.getpid(), signal.SIGINT)
                deadline = time.monotonic() + 0.5   # a busy main thread may take a while to run the handler
                while not (self.finished or self._delivered) and time.monotonic() < deadline:
                    time.sleep(0.001)
        finally:
            self._redelivering = False

    def _redeliver_soon(self) -> None:
        if not self._redelivering:
            self._redelivering = True
            threading.Thread(target=self._redeliver, daemon=True).start()

    def _handler(self, signum, frame):
        if not self.fired:
            self.signum = signum
        self.fired = True
        if self._in_hook:   # raised here, Python would swallow it like the first one: deliver it later
            self._redeliver_soon()
            return
        self._delivered = True
        raise KeyboardInterrupt

    def _unraisable(self, info) -> None:
        """An interrupt that landed in a destructor or weakref callback is swallowed there (Python prints
        "Exception ignored in ..." and goes on): deliver it again, to the main flow, from another thread
        (raised inside this hook, Python would swallow it once more)."""
        if isinstance(info.exc_value, KeyboardInterrupt):
            self._in_hook = True
            try:
                self._delivered = False
                self._redeliver_soon()
            finally:
                self._in_hook = False
        else:
            self._hook(info)

    def __enter__(self):
        try:
            self._previous = signal.signal(signal.SIGINT, self._handler)
            self._previous_term = signal.signal(signal.SIGTERM, self._handler)
        except ValueError:  # not the main thread (e.g. called from a worker): leave the signals alone
            self._previous = None
            return self
        self._hook, sys.unraisablehook = sys.unraisablehook, self._unraisable
        return self

    def __exit__(self, *exc):
        self.finished = True
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            signal.signal(signal.SIGTERM, self._previous_term)
            sys.unraisablehook = self._hook
        return False
