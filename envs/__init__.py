"""Goal-conditioned tasks as pure JAX functions, behind one registry: ``envs.make(name)``."""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import io

from envs.base import GoalEnv, State
from envs.settings import InvalidConfig, typed_value

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


# Task options runs were once recorded with that left the package (experiments/NOTES.md, "Retired options"): a run
# holding one is refused with that reason rather than as a typo
RETIRED = frozenset({"puck_support", "weld_timeconst", "pad_friction", "pad_top_friction"})


def names() -> list[str]:
    return list(_REGISTRY)


def task_class(name: str) -> type[GoalEnv]:
    """The dataclass of task ``name`` (importing its module); an unknown name fails naming it."""
    if name not in _REGISTRY:
        raise InvalidConfig("env", name, "one of " + ", ".join(_REGISTRY))
    module, cls_name = _REGISTRY[name].split(":")
    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a notice on import when Warp is absent
        return getattr(importlib.import_module(module), cls_name)


def make(name: str, **overrides) -> GoalEnv:
    """Build task ``name`` with field ``overrides``; unknown names or fields, and values not of the
    field's type, fail naming them."""
    cls = task_class(name)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    typed = {}
    for key, value in overrides.items():
        if key not in fields:
            gone = "unset: the option left the package (experiments/NOTES.md, Retired options)"
            known = "one of the fields " + ", ".join(sorted(fields))
            raise InvalidConfig(f"{name}.{key}", value, gone if key in RETIRED else known)
        kind = fields[key].type if isinstance(fields[key].type, str) else fields[key].type.__name__
        typed[key] = typed_value(f"{name}.{key}", kind, value)
    return cls(**typed)


__all__ = [
    "GoalEnv",
    "State",
    "make",
    "names",
    "task_class",
]
