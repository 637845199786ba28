"""MJX's constraint solver with its loops written out: a fixed number of Newton iterations, each with a
fixed number of line-search steps, and no loop left in the compiled step.

Why: on a GPU every trip of an XLA loop reads its condition back to the host before the next trip, and
an MJX step runs up to ``iterations`` Newton trips of ``ls_iterations`` line-search trips each. At the
small batches SPLID and HER step (16 to 125 envs) those round trips, not arithmetic, may set the
step's latency. Written out, each trip runs its body and keeps the result only where the loop would
still be running (``jnp.where`` on the loop's own condition), so once converged a state stays as the
loop left it: the same arithmetic as the loops, equal to float rounding. The price is compile time:
the solver's body is traced ``iterations * (1 + ls_iterations)`` times.

``envs/mjx_patch.py`` puts them in for a task's step: ``solver_while`` in place of ``jax.lax.while_loop``,
written out only for loops whose body is MJX's solver's (its module), and ``written_out_scan`` in place of
the solver's scan-based line-search loop.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
from mujoco.mjx._src import solver as mjx_solver

_SOLVER_MODULE = mjx_solver.__name__
_WHILE_LOOP = jax.lax.while_loop  # JAX's own, for every loop not the solver's


def _written_out(cond, body, val, trips: int):
    for _ in range(trips):
        go = cond(val)
        nxt = body(val)
        val = jax.tree.map(lambda a, b, go=go: jnp.where(go, a, b), nxt, val)
    return val


def writes_out(choice: str, backend: str) -> tuple[bool, bool]:
    """Which of the solver's loops a task's ``solver_loops`` choice writes out on ``backend``, as (Newton
    loop, line search). ``search`` writes out the line search alone: the Newton loop's few trips stay a
    loop, so its body is traced once and the compile grows little. ``gpu-search`` (the Fetch tasks'
    default) and ``auto`` write out the line search, or both, on a GPU only, where the loops' host
    round trips cost; an XLA:CPU loop reads no condition back, and the written-out solver there
    compiles twice as long and steps slower. ``fused`` and ``gpu-fused`` replace MJX's solve with
    ``envs/fused_solver.py``'s; where MJX's still runs, ``gpu-fused`` is ``gpu-search`` (a GPU's batches
    above the task's ``kernel_envs``; a CPU's solves)."""
    gpu = backend == "gpu"
    newton = choice == "unrolled" or (choice == "auto" and gpu)
    return newton, newton or choice == "search" or (choice in ("gpu-search", "gpu-fused") and gpu)


def solver_while(iterations: int):
    """``jax.lax.while_loop`` with the loops of MJX's solver module (its Newton loop) written out as ``iterations``
    trips; other loops are left as they are."""

    def while_loop(cond, body, init):
        if getattr(body, "__module__", None) != _SOLVER_MODULE:
            return _WHILE_LOOP(cond, body, init)
        return _written_out(cond, body, init, iterations)

    return while_loop


def written_out_scan(cond, body, init, max_iter: int):
    """MJX's solver's ``_while_loop_scan`` (its line search) written out as ``max_iter`` trips (MJX passes
    ``ls_iterations``)."""
    return _written_out(cond, body, init, max_iter)
