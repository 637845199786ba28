"""Where a run's arrays live: one device, or a one-axis mesh of the devices it may use.

A sweep splits its members into equal groups, one per device (``MEMBERS``): each device runs the
one-device program of its group, so a group computes exactly what a sweep of its members computes
on one device (``groups.Groups``). A single run of a behaviour-cloning learner splits its envs
(``ENVS``): each device explores and SELECTs its slice, the relabelled pairs are gathered in the
one-device layout, and the buffer, the BC step and the parameters are replicated
(``trainer.Trainer``).

Both run on CPU and GPU devices alike. Over several processes (``splid_jax.runtime.multihost``) a
sweep's mesh takes ``num_devices`` devices of each process, and each process runs the groups on its
own; a single run stays in one process."""

from __future__ import annotations

import dataclasses
import os

import jax
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec

from splid_jax.common.errors import InvalidConfig

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
        """The first of the mesh's devices that this process drives."""
        return next(d for d in self.mesh.devices.flat if d.process_index == jax.process_index())

    def split(self) -> NamedSharding:
        """Arrays whose leading axis is the mesh's axis."""
        return NamedSharding(self.mesh, PartitionSpec(self.axis))

    def replicated(self) -> NamedSharding:
        return NamedSharding(self.mesh, PartitionSpec())

    def state_sharding(self) -> NamedSharding:
        """A sweep's stacked state is split by member; a run's state is whole on every device."""
        return self.split() if self.axis == MEMBERS else self.replicated()

    def record(self, member: int | None = None, members: int = 1) -> dict:
        """What a run's config.json keeps of its hardware: the devices' kind, count, processes and ids, and
        for member ``member`` of a sweep of ``members`` split by member, the id of the device it ran on. Ids
        are JAX's, counted within CUDA_VISIBLE_DEVICES, which is kept when set."""
        ids = [d.id for d in self.mesh.devices.flat]
        rec = {"kind": self.first.device_kind, "count": self.count, "processes": jax.process_count(), "ids": ids}
        if member is not None and self.axis == MEMBERS:
            rec["member_on"] = ids[member // max(members // self.count, 1)]
        visible = os.environ.get("CUDA_VISIBLE_DEVICES")
        return rec if visible is None or self.first.platform == "cpu" else {**rec, "cuda_visible_devices": visible}


def place(wanted: int, size: int, axis: str) -> Placement:
    """A mesh of ``wanted`` devices of each process (0: as many as it sees and ``size`` divides) along
    ``axis``, ``size`` being the member count or the env count it splits."""
    processes, available = jax.process_count(), jax.local_devices()
    if wanted > len(available):
        seen = f"an integer in [0, {len(available)}] (the devices this process sees)"
        raise InvalidConfig("num_devices", wanted, seen)
    if processes > 1 and axis == ENVS:
        allowed = "1 for a single run (a sweep, python -m splid_jax.sweep, splits its members across processes)"
        raise InvalidConfig("num_processes", processes, allowed)
    if size % processes:
        raise InvalidConfig("num_processes", processes, f"a divisor of the {size} sweep members (an equal share each)")
    what = "sweep members" if axis == MEMBERS else "num_envs"
    if wanted and size % (wanted * processes):
        each = f" (each of the {processes} processes' share)" if processes > 1 else ""
        allowed = f"a divisor of the {size // processes} {what}{each} (or 0 to choose)"
        raise InvalidConfig("num_devices", wanted, allowed)
    count = wanted or max(d for d in range(1, len(available) + 1) if size % (d * processes) == 0)
    # in process order: process p holds the mesh's devices p * count onwards, so its groups' members are one block
    mesh = [[d for d in jax.devices() if d.process_index == p][:count] for p in range(processes)]
    return Placement(Mesh(np.asarray(mesh).reshape(-1), (axis,)), axis)
