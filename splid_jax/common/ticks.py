"""Progress from inside a compiled chunk, for a CPU, where one chunk of a Fetch task runs for minutes.

A learner calls ``tick`` where a stage ends (an iteration, its exploration, a round of SELECT's queue)
with a traced counter. Outside ``watching`` a tick adds nothing to the program; inside it (the host loop
traces a CPU run's training so while its display is on) each tick is a host callback handing the counter
to the watcher (``runtime.progress.Watch``), which shows what the chunk has done.

JAX keeps no program that calls back into Python in its persistent compile cache, so only those
programs carry ticks: GPU programs, sweeps and quiet runs stay cacheable and unchanged."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from typing import Any, Protocol

import jax

EXPLORED, ROUND, ITERATION = "explored", "round", "iteration"  # value: iterations done before, verdicts left, done


class Watcher(Protocol):
    def seen(self, stage: str, value: Any) -> None:
        """Called on the host, in the program's order, as each tick is reached."""


_watcher: Watcher | None = None  # set only while the host loop traces a watched program


@contextlib.contextmanager
def watching(watcher: Watcher | None) -> Iterator[None]:
    """Programs traced inside carry ticks to ``watcher`` (none when it is None)."""
    global _watcher
    before, _watcher = _watcher, watcher
    try:
        yield
    finally:
        _watcher = before


def tick(stage: str, value: Callable[[], jax.Array], after: Any = None) -> None:
    """Where ``stage`` ends in a traced program: inside ``watching``, ``value()`` (a traced integer
    scalar) goes to the watcher once ``after`` (scalars the stage made last) is computed; outside,
    nothing is traced, not even ``value``."""
    watcher = _watcher
    if watcher is not None:
        jax.debug.callback(lambda v, _: watcher.seen(stage, v), value(), after)
