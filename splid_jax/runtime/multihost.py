"""Several processes, on one host or many, as one sweep (``jax.distributed``).

Every process computes its share of the members on its own devices; process 0 alone touches the run
directory, reading and writing, and the others take what they need from it through collectives. So
the others' run directories may be absent, and a checkpoint holds the whole state as one process
saves it: it resumes under any process layout. With one process each function is the plain call."""

from __future__ import annotations

import dataclasses
import os
import pickle
import socket
from collections.abc import Callable
from typing import TypeVar

import jax
import numpy as np
from jax.experimental import multihost_utils

from splid_jax.common.errors import InvalidConfig

T = TypeVar("T")


@dataclasses.dataclass(frozen=True)
class Launch:
    """Where this process stands among the processes of one run."""

    coordinator: str  # HOST:PORT of process 0, which every process reaches
    num_processes: int
    process_id: int


def launch(coordinator: str | None, num_processes: int | None, process_id: int | None) -> Launch | None:
    """The checked launch options; None for a run of one process, which has nothing to join."""
    n = 1 if num_processes is None else num_processes
    if n < 1:
        raise InvalidConfig("num_processes", n, "an integer >= 1 (--num-processes: the processes of the run)")
    if (process_id is not None or n > 1) and not (process_id is not None and 0 <= process_id < n):
        allowed = f"an integer in [0, {n}) (--process-id, one per process of --num-processes {n})"
        raise InvalidConfig("process_id", process_id, allowed)
    if coordinator is None and n > 1:
        allowed = "HOST:PORT of process 0 (--coordinator, needed with --num-processes > 1)"
        raise InvalidConfig("coordinator", None, allowed)
    if coordinator is not None:
        host, colon, port = coordinator.rpartition(":")
        if not (colon and host and port.isdigit() and 1 <= int(port) <= 65535):
            raise InvalidConfig("coordinator", coordinator, "HOST:PORT with a port in [1, 65535] (--coordinator)")
    return Launch(coordinator, n, process_id) if n > 1 else None


# A process may compile for minutes (a sweep's chunk on a GPU, several devices' programs at once) or start
# later than the others: neither may count as a dead process.
HEARTBEAT_S = 900
JOIN_S = 900
# XLA:GPU otherwise splits autotuning across the processes, each waiting in its compile for the others'
# results; process 0 alone compiles some programs (restoring a checkpoint), and each process its own groups.
SOLO_AUTOTUNING = "--xla_gpu_shard_autotuning=false"


def start(where: Launch | None) -> None:
    """Joins the run's processes, before any other JAX use. The CPU backend's collectives need gloo
    (the setting is read by the CPU backend only, so it is set whatever the platform)."""
    if where is None:
        return
    if where.process_id == 0:
        _check_port(where.coordinator)
    jax.config.update("jax_cpu_collectives_implementation", "gloo")
    flags = os.environ.get("XLA_FLAGS", "")
    if "xla_gpu_shard_autotuning" not in flags:
        os.environ["XLA_FLAGS"] = f"{flags} {SOLO_AUTOTUNING}".strip()
    jax.distributed.initialize(
        coordinator_address=where.coordinator,
        num_processes=where.num_processes,
        process_id=where.process_id,
        initialization_timeout=JOIN_S,
        heartbeat_timeout_seconds=HEARTBEAT_S,
    )


def _check_port(coordinator: str) -> None:
    """Process 0 serves the coordinator on every interface at PORT; a port in use crashes that server
    (a segmentation fault under jaxlib 0.10), so it is tried first, as the server binds it."""
    with socket.socket() as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(("", int(coordinator.rpartition(":")[2])))
        except OSError as e:
            allowed = f"HOST:PORT with a port free on process 0 ({e.strerror})"
            raise InvalidConfig("coordinator", coordinator, allowed) from None


def is_first() -> bool:
    """This process writes the run directory."""
    return jax.process_index() == 0


def concat(tree: T) -> T:
    """Every process's ``tree`` (host arrays, same shapes everywhere) joined along the leading axis,
    in process order, on every process."""
    if jax.process_count() == 1:
        return tree
    return jax.tree.map(np.asarray, multihost_utils.process_allgather(tree, tiled=True))


def any_of(value: int) -> int:
    """The largest of every process's ``value``: what one process saw, all act on."""
    return value if jax.process_count() == 1 else int(np.max(concat(np.asarray([value], np.int64))))


def barrier(name: str) -> None:
    """Every process waits here for the others: none leaves while process 0 still writes what it must."""
    if jax.process_count() > 1:
        multihost_utils.sync_global_devices(name)


def from_first(fn: Callable[[], T]) -> T:
    """``fn()`` as process 0 computes it, returned, or raised, on every process: a decision made
    from the run directory, which the others cannot read."""
    if jax.process_count() == 1:
        return fn()
    data = _outcome(fn) if is_first() else b""
    sizes = concat(np.asarray([len(data)], np.int64))
    sent = np.zeros(int(sizes.max()), np.uint8)
    sent[: len(data)] = np.frombuffer(data, np.uint8)
    return _result(concat(sent)[: sizes[0]].tobytes())


def _outcome(fn: Callable[[], T]) -> bytes:
    """``fn()``'s value (arrays as host arrays) or error, pickled. An error travels as its class, args
    and fields: unpickling would call its ``__init__`` with its args, which need not fit (``InvalidConfig``)."""
    try:
        return pickle.dumps((True, jax.device_get(fn())))
    except Exception as err:  # raised by every process alike
        return pickle.dumps((False, (type(err), err.args, vars(err))))


def _result(data: bytes):
    ok, value = pickle.loads(data)
    if ok:
        return value
    cls, args, fields = value
    err = cls.__new__(cls, *args)
    err.args = args
    vars(err).update(fields)
    raise err
