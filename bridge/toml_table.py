"""The TOML reader's table: a scenario table being read, key by key, with every value checked.

Every reader of a scenario's tables (bridge.config, bridge.cfd.sections, the options of each stage) uses it,
so that a missing or unknown key, a wrong type or a value out of range is reported the same way: an
:class:`bridge.errors.InputError` naming the dotted key, the value and what is allowed.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .errors import InputError, check_range

__all__ = ["Table"]


class Table:
    """A TOML table being read: tracks which keys were used so unknown keys can be rejected."""

    def __init__(self, data: Mapping[str, Any], where: str):
        if not isinstance(data, Mapping):
            raise InputError(where, data, "must be a table")
        self.data, self.where, self.used = data, where, set()

    def key(self, name: str) -> str:
        return f"{self.where}.{name}" if self.where else name

    def raw(self, name: str, default: Any = ...) -> Any:
        self.used.add(name)
        if name not in self.data:
            if default is ...:
                raise InputError(self.key(name), None, "missing (required key)")
            return default
        return self.data[name]

    def number(self, name: str, low: float | None = 0.0, high: float | None = None, low_open: bool = True,
               high_open: bool = False, default: Any = ...) -> float:
        value = self.raw(name, default)
        return check_range(self.key(name), value, low, high, low_open, high_open)

    def integer(self, name: str, low: int = 0, high: int | None = None, default: Any = ...) -> int:
        value = self.raw(name, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise InputError(self.key(name), value, "must be an integer")
        check_range(self.key(name), value, low, high)
        return value

    def string(self, name: str, choices: tuple[str, ...] | None = None, default: Any = ...) -> str:
        value = self.raw(name, default)
        if not isinstance(value, str):
            raise InputError(self.key(name), value, "must be a string")
        if choices is not None and value not in choices:
            raise InputError(self.key(name), value, f"must be one of {', '.join(choices)}")
        return value

    def table(self, name: str, default: Any = ...) -> Table:
        value = self.raw(name, default)
        return Table(value, self.key(name))

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise InputError(self.key(unknown[0]), self.data[unknown[0]], "unknown key")
