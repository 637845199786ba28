"""Where a run's arrays live: one device, or a one-axis mesh of the devices it may use.

A sweep splits its members into equal groups, one per device (``MEMBERS``): each device runs the
one-device program of its group, so a group computes exactly what a sweep of its members computes
on one device (``loop._Groups``). A single run of a behaviour-cloning learner splits its envs
(``ENVS``): each device explores and SELECTs its slice, the relabelled pairs are gathered in the
one-device layout, and the buffer, the BC step and the parameters are replicated
(``trainer.Trainer``)."""

from __future__ import annotations

import dataclasses

import jax
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec

from envs.base import InvalidConfig

MEMBERS, ENVS = "members", "envs"


@dataclasses.dataclass(frozen=True)
class Placement:
    mesh: Mesh  # one axis, named MEMBERS or ENVS
    axis: str

    @property
    def count(self) -> int:
        return self.mesh.size

    @property
    def first(self) -> jax.Device:
        return self.mesh.devices.flat[0]

    def split(self) -> NamedSharding:
        """Arrays whose leading axis is the mesh's axis."""
        return NamedSharding(self.mesh, PartitionSpec(self.axis))

    def replicated(self) -> NamedSharding:
        return NamedSharding(self.mesh, PartitionSpec())

    def state_sharding(self) -> NamedSharding:
        """A sweep's stacked state is split by member; a run's state is whole on every device."""
        return self.split() if self.axis == MEMBERS else self.replicated()

    def record(self) -> dict:
        """What a run's config.json keeps of its hardware."""
        return {"kind": self.first.device_kind, "count": self.count, "processes": jax.process_count()}


def place(wanted: int, size: int, axis: str) -> Placement:
    """A mesh of ``wanted`` devices (0: as many as there are and ``size`` divides) along ``axis``,
    ``size`` being the member count or the env count it splits."""
    available = jax.devices()
    if wanted > len(available):
        seen = f"an integer in [0, {len(available)}] (the devices this process sees)"
        raise InvalidConfig("num_devices", wanted, seen)
    what = "sweep members" if axis == MEMBERS else "num_envs"
    if wanted and size % wanted:
        raise InvalidConfig("num_devices", wanted, f"a divisor of the {size} {what} (or 0 to choose)")
    count = wanted or max(d for d in range(1, len(available) + 1) if size % d == 0)
    if count > 1 and available[0].platform != "cpu":
        # measured on two H200s (jax 0.11.2): XLA:GPU crashes compiling the envs split by shard_map
        # and did not finish compiling the members' per-device programs within two minutes
        raise InvalidConfig(
            "num_devices", wanted, f"1 on {available[0].platform} devices for now (split work runs on CPU devices)"
        )
    return Placement(Mesh(np.asarray(available[:count]), (axis,)), axis)
