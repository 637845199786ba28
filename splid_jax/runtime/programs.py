"""The chunk as the device runs it: one program, or a learner's training and report (its evaluation and
metrics) as two programs compiled side by side and called as one.

XLA optimises a program's HLO on one thread, and each copy of the physics step in a program costs
seconds of it (exploration's, SELECT's and evaluation's in a SPLID chunk), so two programs compile in
about the time of the larger, not of both."""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from typing import Any

import jax

from splid_jax.common import ticks
from splid_jax.runtime.memory import largest_value
from splid_jax.runtime.signals import Signals


def parts(algo, stacked: bool) -> list[Callable]:
    """The functions a chunk is made of: ``trained`` then ``report`` where the algorithm splits its chunk,
    else ``chunk``; vmapped over a sweep's members when ``stacked``."""
    trained, report = getattr(algo, "trained", None), getattr(algo, "report", None)
    fns = [algo.chunk] if trained is None or report is None else [trained, report]
    return [jax.vmap(f) for f in fns] if stacked else fns


def trace(fns: list[Callable], state_like, hyper_like, watch: ticks.Watcher | None = None) -> list[jax.stages.Traced]:
    """Each part traced on abstract arguments; the report's state is the training's (the same shapes
    and placement), the rest of its input the training's second output, placed as the state. With
    ``watch``, the training carries the learner's progress ticks (``common.ticks``), traced anew."""
    train = fns[0] if watch is None else functools.wraps(fns[0])(lambda *a: fns[0](*a))  # no cached trace reused
    with ticks.watching(watch):
        first = jax.jit(train).trace(state_like, hyper_like)
    if len(fns) == 1:
        return [first]
    sharding = jax.tree.leaves(state_like)[0].sharding
    done_like = jax.tree.map(
        lambda x: jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=sharding, weak_type=getattr(x, "weak_type", False)),
        first.out_info[1],
    )
    return [first, jax.jit(fns[1]).trace(state_like, hyper_like, done_like)]


def largest(traced: list[jax.stages.Traced]) -> int:
    """Bytes of the largest set of values one operation of any part makes."""
    return max(largest_value(t.jaxpr.jaxpr) for t in traced)


@dataclasses.dataclass(frozen=True)
class Chunk:
    """The compiled parts, called as the chunk: ``(state, hyper) -> (state, metrics)``."""

    programs: tuple

    def __call__(self, state, hyper) -> tuple[Any, dict]:
        if len(self.programs) == 1:
            return self.programs[0](state, hyper)
        train, report = self.programs
        state, done = train(state, hyper)  # dispatched back to back: the device runs them in turn
        return state, report(state, hyper, done)

    def bytes_needed(self) -> int | None:
        """Device bytes the larger program needs as compiled (arguments, outputs and temporaries less
        what they share), or None where the backend does not say."""
        needs = []
        for program in self.programs:
            a = program.memory_analysis()
            if a is None:
                return None
            needs.append(
                a.argument_size_in_bytes + a.output_size_in_bytes + a.temp_size_in_bytes - a.alias_size_in_bytes
            )
        return max(needs)


def compile_all(traced: list[jax.stages.Traced], signals: Signals) -> Chunk:
    """Every part lowered and compiled at once, each in its own thread (a compile left running by an
    error or a signal ends with the process, as ``Signals.wait`` leaves its threads)."""
    pending = [signals.begin(lambda t=t: t.lower().compile()) for t in traced[1:]]
    first = signals.wait(lambda: traced[0].lower().compile())
    return Chunk((first, *(signals.wait(p) for p in pending)))
