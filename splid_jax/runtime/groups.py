"""A sweep's members split over several devices as equal groups, one single-device program each."""

from __future__ import annotations

import threading

import jax
import numpy as np

from splid_jax.runtime import checkpoint, devices, multihost
from splid_jax.runtime.signals import Signals


class Groups:
    """A sweep's members in equal groups, one per device, each group a single-device program (the
    vmapped chunk as one device runs it). Each device's program is called from a thread of its own, so
    the devices run at once; a group computes exactly what a sweep of its members computes on one
    device, and no collective or SPMD partitioning is involved (XLA:CPU can hang in multi-device
    programs). The devices' programs compile at once, each in a thread. Over several processes each
    runs the groups of its own devices, and the members' metrics and checkpointed state are gathered
    between chunks (``multihost.concat``)."""

    def __init__(self, place: devices.Placement, members: int):
        every = list(place.mesh.devices.flat)
        self.size = members // len(every)
        self.devices = {i: d for i, d in enumerate(every) if d.process_index == jax.process_index()}  # group: device

    def first(self, tree):
        return jax.tree.map(lambda x: _slice(x, 0, self.size), tree)

    def on(self, tree, device):
        sharding = jax.sharding.SingleDeviceSharding(device)
        return jax.tree.map(lambda x: jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=sharding), tree)

    def split(self, tree) -> tuple:
        """This process's groups of the whole sweep's ``tree``."""
        host = jax.device_get(tree)
        return tuple(
            jax.device_put(jax.tree.map(lambda x, i=i: _slice(x, i * self.size, self.size), host), device)
            for i, device in self.devices.items()
        )

    def join(self, groups: tuple):
        """The whole sweep's state to checkpoint, on the host of every process, from this process's groups."""
        return checkpoint.on_host(multihost.concat(_concat(jax.device_get(groups))))

    def begin(self, compile_on, signals: Signals) -> list:
        """The other devices' programs, each traced and compiled in a thread of its own from now, beside the
        first device's: one after another they took the first's time once per device."""
        return [signals.begin(lambda d=d: compile_on(d)) for d in list(self.devices.values())[1:]]

    def compile(self, first, pending: list, signals: Signals):
        programs = [first, *(signals.wait(p) for p in pending)]

        def run(states: tuple, hypers: tuple):
            outs = _at_once([lambda p=p, s=s, h=h: p(s, h) for p, s, h in zip(programs, states, hypers, strict=True)])
            return tuple(o[0] for o in outs), multihost.concat(_concat([o[1] for o in outs]))

        return run


def _at_once(calls: list) -> list:
    """Each call in a thread of its own, their results in order (the first error raised): a GPU program can
    hold its caller's thread while it runs (XLA:GPU reads a loop's condition back to the host), so calls
    made in turn from one thread could run the devices one after another."""
    if len(calls) == 1:
        return [calls[0]()]
    box: list = [None] * len(calls)

    def call(i):
        try:
            box[i] = (True, calls[i]())
        except BaseException as e:  # re-raised in the caller's thread
            box[i] = (False, e)

    threads = [threading.Thread(target=call, args=(i,), daemon=True) for i in range(len(calls))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for ok, value in box:
        if not ok:
            raise value
    return [value for _, value in box]


def _concat(groups):
    return jax.tree.map(lambda *xs: np.concatenate([np.asarray(x) for x in xs]), *groups)


def _slice(x, start: int, size: int):
    if isinstance(x, jax.ShapeDtypeStruct):
        return jax.ShapeDtypeStruct((size,) + x.shape[1:], x.dtype, sharding=x.sharding)
    return x[start : start + size]
