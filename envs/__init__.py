"""Goal-conditioned tasks as pure JAX functions, behind one registry: ``envs.make(name)``."""

from __future__ import annotations

import dataclasses
import importlib
import math

from envs.base import GoalEnv, InvalidConfig, State

# name -> "module:class"; imported lazily so the point task never pays for MuJoCo.
_REGISTRY = {
    "point": "envs.point_fourrooms:PointFourRooms",
    "reach": "envs.fetch.tasks:Reach",
    "push": "envs.fetch.tasks:Push",
    "slide": "envs.fetch.tasks:Slide",
    "pick_and_place": "envs.fetch.tasks:PickAndPlace",
    "reacher": "envs.reacher:Reacher",
    "sawyer_door": "envs.sawyer_door:SawyerDoor",
}


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


def names() -> list[str]:
    return list(_REGISTRY)


def task_class(name: str) -> type[GoalEnv]:
    """The dataclass of task ``name`` (importing its module); an unknown name fails naming it."""
    if name not in _REGISTRY:
        raise InvalidConfig("env", name, "one of " + ", ".join(_REGISTRY))
    module, cls_name = _REGISTRY[name].split(":")
    return getattr(importlib.import_module(module), cls_name)


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


def make(name: str, **overrides) -> GoalEnv:
    """Build task ``name`` with field ``overrides``; unknown names or fields, and values not of the
    field's type, fail naming them."""
    cls = task_class(name)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    typed = {}
    for key, value in overrides.items():
        if key not in fields:
            raise InvalidConfig(f"{name}.{key}", value, "one of the fields " + ", ".join(sorted(fields)))
        kind = fields[key].type if isinstance(fields[key].type, str) else fields[key].type.__name__
        typed[key] = typed_value(f"{name}.{key}", kind, value)
    return cls(**typed)


__all__ = [
    "GoalEnv",
    "InvalidConfig",
    "State",
    "make",
    "names",
    "parse_overrides",
    "read_value",
    "task_class",
    "typed_value",
]
