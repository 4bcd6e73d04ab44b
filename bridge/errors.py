"""Errors that reach the user as one clear line.

``InputError`` names the input key, the value given and the allowed range; the command line turns it
into exit status 2.  ``ConvergenceError`` says which iteration failed and its last residual (exit status 3).
``InternalError`` is a broken invariant of the program itself: a bug, never the user's input, and it says so.
Functions of the library (bridge.cfd, ...) called with a bad argument raise ``ValueError`` naming the argument;
the program checks every user input before it calls them, so that what reaches a user as ``ValueError`` is a
bug too (the command line then shows its traceback).
"""

from __future__ import annotations

import math

__all__ = ["InputError", "ConvergenceError", "DivergedError", "InternalError", "check_range"]


class InputError(ValueError):
    """Bad input: ``key`` (dotted path, e.g. ``girder.mass_per_length_kg_m``), ``value``, ``allowed``."""

    def __init__(self, key: str, value: object, allowed: str):
        self.key, self.value, self.allowed = key, value, allowed
        super().__init__(f"{key} = {value!r}: {allowed}")

    def __reduce__(self):   # picklable, so that a worker process can raise it (the aero stage's cases)
        return type(self), (self.key, self.value, self.allowed)


class ConvergenceError(RuntimeError):
    """An iteration that did not converge; the message carries the last residual."""

    def __init__(self, what: str, iterations: int, residual: float, tolerance: float):
        self.what, self.iterations, self.residual, self.tolerance = what, iterations, residual, tolerance
        super().__init__(
            f"{what} did not converge in {iterations} iterations: last residual {residual:.3e} "
            f"(tolerance {tolerance:.1e})"
        )

    def __reduce__(self):
        return type(self), (self.what, self.iterations, self.residual, self.tolerance)


class DivergedError(ConvergenceError):
    """A time-marching solution that stopped being finite (the CFD): ``what`` and where/when."""

    def __init__(self, what: str, detail: str):
        self.what, self.iterations, self.residual, self.tolerance = what, 0, float("inf"), 0.0
        self.detail = detail
        RuntimeError.__init__(self, f"{what} diverged: {detail}")

    def __reduce__(self):
        return type(self), (self.what, self.detail)


class InternalError(RuntimeError):
    """A broken invariant of the program (a bug): what broke, and a request to report it."""

    def __init__(self, what: str):
        self.what = what
        super().__init__(f"internal error (a bug in bridge, not in your input; please report it with the command "
                         f"that gave it): {what}")

    def __reduce__(self):
        return type(self), (self.what,)


def check_range(key: str, value: float, low: float | None = None, high: float | None = None,
                low_open: bool = False, high_open: bool = False) -> float:
    """Return ``float(value)`` if it is finite and lies in the range, else raise :class:`InputError` naming it.

    ``low_open``/``high_open`` exclude the end point (``low_open=True, low=0`` means "> 0").
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(key, value, "must be a number")
    v = float(value)
    if not math.isfinite(v):  # NaN fails every comparison and inf passes every open range: refuse both
        raise InputError(key, value, "must be a finite number")
    lo_ok = low is None or (v > low if low_open else v >= low)
    hi_ok = high is None or (v < high if high_open else v <= high)
    if not (lo_ok and hi_ok):
        lo = "" if low is None else (f"> {low:g}" if low_open else f">= {low:g}")
        hi = "" if high is None else (f"< {high:g}" if high_open else f"<= {high:g}")
        raise InputError(key, value, "allowed range " + " and ".join(s for s in (lo, hi) if s))
    return v


def check_table(where: str, mapping: object, allowed) -> None:
    """A scenario table: a mapping whose keys are all among ``allowed`` (InputError naming ``where``, or
    ``where.key`` and the keys allowed)."""
    from collections.abc import Mapping

    if not isinstance(mapping, Mapping):
        raise InputError(where, mapping, "must be a table")
    allowed = list(allowed)
    for key in mapping:
        if key not in allowed:
            raise InputError(f"{where}.{key}", mapping[key], f"unknown key; allowed: {', '.join(allowed)}")
