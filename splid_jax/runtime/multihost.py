"""Several processes, on one host or many, as one sweep (``jax.distributed``).

Every process computes its share of the members on its own devices; process 0 alone touches the run
directory, reading and writing, and the others take what they need from it through collectives. So
the others' run directories may be absent, and a checkpoint holds the whole state as one process
saves it: it resumes under any process layout. With one process each function is the plain call."""

from __future__ import annotations

import contextlib
import dataclasses
import os
import pickle
import socket
import time
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

    @property
    def address(self) -> tuple[str, int]:
        """The coordinator's host (an IPv6 one without its brackets) and port."""
        host, _, port = self.coordinator.rpartition(":")
        return host.strip("[]"), int(port)


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
_NOTE_AFTER_S = 5.0  # a wait longer than this is shown
# XLA:GPU otherwise splits autotuning across the processes, each waiting in its compile for the others'
# results; process 0 alone compiles some programs (restoring a checkpoint), and each process its own groups.
SOLO_AUTOTUNING = "--xla_gpu_shard_autotuning=false"


def start(where: Launch | None, show: Callable[[str], None] = print) -> None:
    """Joins the run's processes, before any other JAX use. The CPU backend's collectives need gloo
    (the setting is read by the CPU backend only, so it is set whatever the platform)."""
    if where is None:
        return
    meet(where, JOIN_S, show)
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


def meet(where: Launch, within: float, show: Callable[[str], None] = print) -> None:
    """Every process reaches process 0 at the coordinator's address before JAX's coordination service
    starts. That service ends a process whose peers never come with an abort after its timeout, and
    a port in use crashes its server (a segmentation fault under jaxlib 0.10); here either is one line
    naming the flag. A wait of more than a few seconds is shown."""
    start, shown = time.monotonic(), False

    def waiting() -> bool:  # False once ``within`` is past
        nonlocal shown
        late = time.monotonic() - start
        if late > _NOTE_AFTER_S and not shown:
            shown = True
            show(f"process {where.process_id} of {where.num_processes}: waiting up to {within:g} s for the others "
                 f"at {where.coordinator}")  # fmt: skip
        return late < within

    (_gather if where.process_id == 0 else _reach)(where, within, waiting)


def _reach(where: Launch, within: float, waiting: Callable[[], bool]) -> None:
    """Process i > 0: tells process 0 its index and waits for the word to go on."""
    reply = None
    while reply is None:
        try:
            with socket.create_connection(where.address, timeout=1.0) as conn:
                conn.sendall(f"{where.process_id}\n".encode())
                conn.settimeout(within + 30.0)  # process 0 gives up first, and says so by closing
                reply = conn.makefile().readline().strip()
        except OSError:
            if not waiting():
                allowed = f"HOST:PORT where process 0 of the run listens (none answered within {within:g} s)"
                raise InvalidConfig("coordinator", where.coordinator, allowed) from None
            time.sleep(0.2)
    if reply == "taken":
        allowed = f"an integer in [0, {where.num_processes}) that no other process of the run has (--process-id)"
        raise InvalidConfig("process_id", where.process_id, allowed)
    if reply != "go":
        allowed = "HOST:PORT that every process reaches (process 0 stopped waiting for the others)"
        raise InvalidConfig("coordinator", where.coordinator, allowed)


def _gather(where: Launch, within: float, waiting: Callable[[], bool]) -> None:
    """Process 0: listens on every interface at PORT, as the coordination service then does, until
    each other index has come once; then tells them all to go on."""
    peers: dict[int, socket.socket] = {}
    with socket.socket() as server, contextlib.ExitStack() as closing:
        server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            server.bind(("", where.address[1]))
        except OSError as e:
            allowed = f"HOST:PORT with a port free on process 0 ({e.strerror})"
            raise InvalidConfig("coordinator", where.coordinator, allowed) from None
        server.listen()
        server.settimeout(0.2)
        while len(peers) < where.num_processes - 1:
            if not waiting():
                missing = ", ".join(str(i) for i in range(1, where.num_processes) if i not in peers)
                allowed = f"HOST:PORT that every process reaches (process {missing} did not within {within:g} s)"
                raise InvalidConfig("coordinator", where.coordinator, allowed)
            try:
                conn = closing.enter_context(server.accept()[0])
                conn.settimeout(5.0)
                i = int(conn.makefile().readline())
            except (OSError, ValueError):  # no one came, or not a process of this run
                continue
            if i in peers or not 0 < i < where.num_processes:
                conn.sendall(b"taken\n")
            else:
                peers[i] = conn
        for conn in peers.values():
            conn.sendall(b"go\n")
        for conn in peers.values():  # each peer closes first, so no closed port waits on process 0
            with contextlib.suppress(OSError):
                conn.recv(1)


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
