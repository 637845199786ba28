"""Settings given as text (``KEY=VALUE[,KEY=VALUE...]``, as ``--env-options`` and ``figures --set``
take them) read into values, and checked against a dataclass field's declared type."""

from __future__ import annotations

import math

from splid_jax.common.errors import InvalidConfig


def parse_overrides(text: str, field: str = "env_options") -> dict:
    """``"finger=capsule,substeps=20"`` -> ``{"finger": "capsule", "substeps": 20}``: integers, floats
    and words; an empty text is no override. A malformed item fails naming ``field``."""
    overrides = {}
    for part in filter(None, (p.strip() for p in text.split(","))):
        key, sep, value = (x.strip() for x in part.partition("="))
        if not sep or not key or not value:
            raise InvalidConfig(field, text, "KEY=VALUE[,KEY=VALUE...] with task fields as keys")
        overrides[key] = read_value(value)
    return overrides


def read_value(text: str) -> int | float | str:
    """A setting's text as an integer, else a float, else the word itself."""
    try:
        return int(text)
    except ValueError:
        try:
            return float(text)
        except ValueError:
            return text


def typed_value(where: str, kind: str, value):
    """A setting (as ``read_value`` reads it) as its field's declared type ``kind``, or one error naming
    ``where``: ``20.5`` is no integer, ``big`` no number. A tuple of integers arrives with colons
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
