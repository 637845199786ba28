"""The chunk as the device runs it: one program, or a learner's training and report (its evaluation and
metrics) as two programs, the report traced and compiled while the training compiles, called as one.

XLA optimises a program's HLO on one thread, and each copy of the physics step in a program costs
seconds of it (exploration's, SELECT's and evaluation's in a SPLID chunk), so two programs compile in
about the time of the larger, not of both."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import jax

from splid_jax.runtime.signals import Signals


def parts(algo, stacked: bool) -> list[Callable]:
    """The functions a chunk is made of: ``trained`` then ``report`` where the algorithm splits its chunk,
    else ``chunk``; vmapped over a sweep's members when ``stacked``."""
    trained, report = getattr(algo, "trained", None), getattr(algo, "report", None)
    fns = [algo.chunk] if trained is None or report is None else [trained, report]
    return [jax.vmap(f) for f in fns] if stacked else fns


def done_like(first: jax.stages.Traced, state_like):
    """What the report takes beside the state and settings: the training's second output, abstract,
    placed as the state."""
    sharding = jax.tree.leaves(state_like)[0].sharding
    return jax.tree.map(
        lambda x: jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=sharding, weak_type=getattr(x, "weak_type", False)),
        first.out_info[1],
    )


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


def start(
    fns: list[Callable],
    first: jax.stages.Traced,
    state_like,
    hyper_like,
    signals: Signals,
    check: Callable[[jax.stages.Traced], None],
) -> Callable[[], Chunk]:
    """The chunk's compiles, begun: the first part's at once, each other part's once it is traced (beside
    the first's compile) and ``check`` has seen its trace. Returns the function that waits for them (a
    compile left running by an error or a signal ends with the process, as ``Signals.wait`` leaves its
    threads)."""
    compiling = [signals.begin(lambda: first.lower().compile())]
    for fn in fns[1:]:
        report = signals.wait(lambda fn=fn: jax.jit(fn).trace(state_like, hyper_like, done_like(first, state_like)))
        check(report)
        compiling.append(signals.begin(lambda r=report: r.lower().compile()))
    return lambda: Chunk(tuple(signals.wait(c) for c in compiling))
