"""Goal-conditioned tasks as pure JAX functions, behind one registry: ``envs.make(name)``."""

from __future__ import annotations

import dataclasses
import importlib

from envs.base import GoalEnv, InvalidConfig, State

# name -> "module:class"; imported lazily so the point task never pays for MuJoCo.
_REGISTRY = {
    "point": "envs.point_fourrooms:PointFourRooms",
    "reach": "envs.fetch.tasks:Reach",
    "push": "envs.fetch.tasks:Push",
    "slide": "envs.fetch.tasks:Slide",
    "pick_and_place": "envs.fetch.tasks:PickAndPlace",
}


def parse_overrides(text: str, field: str = "env_options") -> dict:
    """``"finger=capsule,substeps=20"`` -> ``{"finger": "capsule", "substeps": 20}``: integers, floats
    and words; an empty text is no override. A malformed item fails naming ``field``."""
    overrides = {}
    for part in filter(None, (p.strip() for p in text.split(","))):
        key, sep, value = (x.strip() for x in part.partition("="))
        if not sep or not key or not value:
            raise InvalidConfig(field, text, "KEY=VALUE[,KEY=VALUE...] with task fields as keys")
        try:
            overrides[key] = int(value)
        except ValueError:
            try:
                overrides[key] = float(value)
            except ValueError:
                overrides[key] = value
    return overrides


def names() -> list[str]:
    return list(_REGISTRY)


def make(name: str, **overrides) -> GoalEnv:
    """Build task ``name`` with field ``overrides``; unknown names or fields fail naming them."""
    if name not in _REGISTRY:
        raise InvalidConfig("env", name, "one of " + ", ".join(_REGISTRY))
    module, cls_name = _REGISTRY[name].split(":")
    cls = getattr(importlib.import_module(module), cls_name)
    fields = {f.name for f in dataclasses.fields(cls)}
    for key in overrides:
        if key not in fields:
            raise InvalidConfig(f"{name}.{key}", overrides[key], "one of the fields " + ", ".join(sorted(fields)))
    return cls(**overrides)


__all__ = ["GoalEnv", "InvalidConfig", "State", "make", "names", "parse_overrides"]
