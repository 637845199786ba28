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


__all__ = ["GoalEnv", "InvalidConfig", "State", "make", "names"]
