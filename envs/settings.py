"""The one error a mistake in a setting raises, wherever it is checked (the command line, a config, a task's
fields), and the check that a setting given as text has its field's type. Its message names the field and the
range it must be in, and the commands turn it into one line and exit code 2. The tasks own it so that they stand
alone; the trainer raises the same class."""

from __future__ import annotations

import math
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


def typed_value(where: str, kind: str, value):
    """A setting (an integer, float or word, as text reads into) as its field's declared type ``kind``, or one
    error naming ``where``: ``20.5`` is no integer, ``big`` no number. A tuple of integers arrives with colons
    between its widths (``64:64``), since commas separate the settings."""
    if kind == "bool":
        words = {"true": True, "1": True, "false": False, "0": False}
        if str(value).lower() not in words:
            raise InvalidConfig(where, value, "true or false")
        return words[str(value).lower()]
    if kind.startswith("tuple"):
        try:
            return tuple(int(w) for w in str(value).split(":"))
        except ValueError:
            raise InvalidConfig(where, str(value).replace(":", ","), "comma-separated integers, e.g. 64,64") from None
    if kind == "int":
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        raise InvalidConfig(where, value, "an integer")
    if kind == "float":
        if isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value):
            return float(value)
        raise InvalidConfig(where, value, "a finite number")
    if kind == "str":
        return str(value)
    return value
