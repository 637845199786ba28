"""Settings given as text (``KEY=VALUE[,KEY=VALUE...]``, as ``--env-options`` and ``figures --set``
take them) read into values, and checked against a dataclass field's declared type."""

from __future__ import annotations

import dataclasses
from typing import Any

from envs.settings import typed_value
from splid_jax.common.errors import InvalidConfig, check


def parse_overrides(text: str, field: str = "env_options") -> dict:
    """``"finger=capsule,substeps=20"`` -> ``{"finger": "capsule", "substeps": 20}``: integers, floats
    and words; an empty text is no override. A malformed item fails naming ``field``."""
    overrides = {}
    for part in filter(None, (p.strip() for p in text.split(","))):
        key, sep, value = (x.strip() for x in part.partition("="))
        if not sep or not key or not value:
            raise InvalidConfig(field, text, "KEY=VALUE[,KEY=VALUE...] with task fields as keys")
        if key in overrides:  # which of the two was meant is the user's to say
            raise InvalidConfig(field, text, f"KEY=VALUE items with each key once ({key} is given twice)")
        overrides[key] = read_value(value)
    return overrides


def format_overrides(overrides: dict) -> str:
    """``parse_overrides``'s inverse: ``{"finger": "capsule", "substeps": 20}`` -> ``"finger=capsule,substeps=20"``."""
    return ",".join(f"{key}={value}" for key, value in overrides.items())


def read_value(text: str) -> int | float | str:
    """A setting's text as an integer, else a float, else the word itself."""
    try:
        return int(text)
    except ValueError:
        try:
            return float(text)
        except ValueError:
            return text


def parse_options(cls, text: str, field: str, prefix: str):
    """A learner's config dataclass (``HerConfig``, ``EsConfig``) from ``KEY=VALUE[,KEY=VALUE...]``, read
    by ``parse_overrides``; a tuple field takes its widths comma-separated too (``hidden=64,64``).
    A bad key or value fails naming ``prefix.KEY``."""
    fields = {f.name: f for f in dataclasses.fields(cls)}
    items: list[str] = []
    for part in (p.strip() for p in text.split(",")):
        previous = items[-1].partition("=")[0].strip() if items else ""
        if part and "=" not in part and previous in fields and str(fields[previous].type).startswith("tuple"):
            items[-1] += ":" + part  # a further width of the tuple before
        else:
            items.append(part)
    try:
        overrides = parse_overrides(",".join(items), field)
    except InvalidConfig as e:
        twice = e.allowed if "twice" in e.allowed else ""
        raise InvalidConfig(field, text, twice or f"KEY=VALUE[,KEY=VALUE...] with {prefix} fields as keys") from None
    return cls(**typed_fields(cls, overrides, prefix))


def options_text(settings, **changed) -> str:
    """A learner's config dataclass (``HerConfig``) as ``KEY=VALUE,...`` text that ``parse_options`` reads
    back: the fields that differ from their defaults, with ``changed`` applied."""
    values = {f.name: getattr(settings, f.name) for f in dataclasses.fields(settings)}
    values.update(changed)
    defaults = {f.name: f.default for f in dataclasses.fields(settings)}
    return ",".join(f"{k}={_shown(v)}" for k, v in values.items() if v != defaults[k])


def merged_options(cls, base: str, given: str, field: str, prefix: str) -> str:
    """``given`` options text on top of ``base`` (a preset's), key by key, as one text that names every key
    either gives, so that reading it again against any defaults gives the same settings."""
    values = {}
    for text in (base, given):
        settings = parse_options(cls, text, field, prefix)
        keys = [part.partition("=")[0].strip() for part in text.split(",") if "=" in part]
        values.update({key: getattr(settings, key) for key in keys})
    return ",".join(f"{key}={_shown(value)}" for key, value in values.items())


def _shown(value) -> str:
    """A setting as options text writes it: a tuple's widths comma-separated (``hidden=64,64``)."""
    return ",".join(map(str, value)) if isinstance(value, tuple) else str(value)


def typed_fields(cls, values: dict[str, Any], prefix: str) -> dict[str, Any]:
    """``values`` (as ``parse_overrides`` reads them) as the declared types of ``cls``'s fields; an
    unknown key or a value of another type fails naming ``prefix.KEY``."""
    fields = {f.name: f for f in dataclasses.fields(cls)}
    typed = {}
    for key, value in values.items():
        where = f"{prefix}.{key}"
        check(key in fields, where, value, "one of the fields " + ", ".join(fields))
        typed[key] = typed_value(where, str(fields[key].type), value)
    return typed
