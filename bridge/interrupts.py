"""Ctrl-C on the command line: one line and exit status 130, wherever it lands.

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
Only the standard library is imported here: this module loads before everything else.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time

__all__ = ["Interrupts", "stop_quietly_while_loading", "exit_command", "INTERRUPTED"]

INTERRUPTED = 130  # the shell's convention: 128 + SIGINT


def stop_quietly_while_loading() -> None:
    """Until the command installs :class:`Interrupts`: Ctrl-C prints one line and exits with 130."""
    signal.signal(signal.SIGINT, lambda *_: (print("interrupted; nothing written", file=sys.stderr),
                                             os._exit(INTERRUPTED)))


def exit_command(status: int) -> None:
    """End the process with ``status``; after an interruption, at once (see the module docstring)."""
    if status == INTERRUPTED:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(INTERRUPTED)
    sys.exit(status)


class Interrupts:
    """While active, SIGINT sets ``fired`` before raising KeyboardInterrupt, so an exception that the
    interrupt caused elsewhere (a library turning it into an ImportError half-way through an import,
    say) is still reported as the interruption it was.
    """

    def __init__(self):
        self.fired = False
        self.finished = False
        self._previous = None
        self._hook = None
        self._in_hook = False        # the unraisable hook is running (see _handler)
        self._delivered = False      # the handler has raised KeyboardInterrupt in the main flow
        self._redelivering = False

    def finish(self) -> None:
        """The interruption is being reported: further Ctrl-C (or one re-delivered late) is ignored, so
        the exit status stays 130."""
        self.finished = True
        with contextlib.suppress(ValueError):
            signal.signal(signal.SIGINT, signal.SIG_IGN)

    def reported(self, message) -> int:
        """After an exception: if it came from the interrupt, print ``message()`` (one line: what was
        kept) and return the exit status 130; otherwise re-raise it.  Call from an ``except
        BaseException`` block."""
        if not self.fired:
            raise
        self.finish()
        print(message(), file=sys.stderr)
        return INTERRUPTED

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
        except ValueError:  # not the main thread (e.g. called from a worker): leave SIGINT alone
            self._previous = None
            return self
        self._hook, sys.unraisablehook = sys.unraisablehook, self._unraisable
        return self

    def __exit__(self, *exc):
        self.finished = True
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            sys.unraisablehook = self._hook
        return False
