"""MJX's constraint solver with its loops written out: a fixed number of Newton iterations, each with a
fixed number of line-search steps, and no loop left in the compiled step.

Why: on a GPU every trip of an XLA loop reads its condition back to the host before the next trip, and
an MJX step runs up to ``iterations`` Newton trips of ``ls_iterations`` line-search trips each. At the
small batches SPLID and HER step (16 to 125 envs) those round trips, not arithmetic, may set the
step's latency. Written out, each trip runs its body and keeps the result only where the loop would
still be running (``jnp.where`` on the loop's own condition), so once converged a state stays as the
loop left it: the same arithmetic as the loops, equal to float rounding. The price is compile time:
the solver's body is traced ``iterations * (1 + ls_iterations)`` times.

``unrolled_in_mjx()`` swaps the loops in for the duration of a trace, as ``small_cholesky`` does:
``jax.lax.while_loop`` is replaced only for loops whose body is MJX's solver's (its module), and the
solver's scan-based line-search loop by its written-out form.
"""

from __future__ import annotations

import contextlib

import jax
import jax.numpy as jnp
from mujoco.mjx._src import solver as mjx_solver

from envs.small_cholesky import TRACE_LOCK

_SOLVER_MODULE = mjx_solver.__name__


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


@contextlib.contextmanager
def unrolled_in_mjx(iterations: int, newton: bool = True, line_search: bool = True):
    """Within the block, MJX's Newton loop runs ``iterations`` written-out trips (``newton``) and its
    line search ``ls_iterations`` (``line_search``; MJX passes that count); other loops are left as
    they are."""
    if not (newton or line_search):
        yield
        return
    with TRACE_LOCK:
        while_loop, search_loop = jax.lax.while_loop, mjx_solver._while_loop_scan

        def solver_while(cond, body, init):
            if getattr(body, "__module__", None) != _SOLVER_MODULE:
                return while_loop(cond, body, init)
            return _written_out(cond, body, init, iterations)

        if newton:
            jax.lax.while_loop = solver_while
        if line_search:
            mjx_solver._while_loop_scan = lambda cond, body, init, max_iter: _written_out(cond, body, init, max_iter)
        try:
            yield
        finally:
            jax.lax.while_loop, mjx_solver._while_loop_scan = while_loop, search_loop
