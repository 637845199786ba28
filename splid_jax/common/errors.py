"""The one error a mistake in a setting raises, wherever it is checked (the command line, a config,
a task's fields): its message names the field and the range it must be in, and the commands turn it
into one line and exit code 2."""

from __future__ import annotations

from typing import Any


class InvalidConfig(ValueError):
    """A configuration value is out of its allowed range; the message names field and range."""

    def __init__(self, field: str, value: Any, allowed: str):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"invalid {field}={value!r}: must be {allowed}")


def check(ok: bool, field: str, value: Any, allowed: str) -> None:
    """Raise ``InvalidConfig`` naming ``field`` unless ``ok``."""
    if not ok:
        raise InvalidConfig(field, value, allowed)


def check_integer(field: str, value: Any, low: int, high: int | None = None) -> None:
    """``check`` for an integer field in [low, high] (no upper bound when ``high`` is None)."""
    ok = isinstance(value, int) and low <= value and (high is None or value <= high)
    check(ok, field, value, f"an integer >= {low}" if high is None else f"an integer in [{low}, {high}]")
