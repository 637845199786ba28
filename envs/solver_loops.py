"""MJX's constraint solver with its line search written out: a fixed number of line-search steps per Newton
trip, the Newton loop left as MJX's own.

Why: on a GPU every trip of an XLA loop reads its condition back to the host before the next trip, and each
of an MJX step's Newton trips runs up to ``ls_iterations`` line-search trips. At the small batches SPLID and
HER step (16 to 125 envs) those round trips, not arithmetic, may set the step's latency. Written out, each
trip runs its body and keeps the result only where the loop would still be running (``jnp.where`` on the
loop's own condition), so once converged a state stays as the loop left it: the same arithmetic as the loop,
equal to float rounding. The price is compile time: the line search's body is traced ``ls_iterations`` times.

``envs/mjx_patch.py`` puts ``written_out_scan`` in place of the solver's scan-based line-search loop.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp


def writes_out(choice: str, backend: str) -> bool:
    """Whether a task's ``solver_loops`` choice writes out the line search on ``backend``. ``search`` does
    everywhere; ``gpu-search`` (the Fetch tasks' default) on a GPU only, where the loop's host round trips
    cost (an XLA:CPU loop reads no condition back). ``fused`` and ``gpu-fused`` replace MJX's solve with
    ``envs/fused_solver.py``'s; where MJX's still runs, ``gpu-fused`` is ``gpu-search`` (a GPU's batches
    above the task's ``kernel_envs``; a CPU's solves)."""
    return choice == "search" or (choice in ("gpu-search", "gpu-fused") and backend == "gpu")


def written_out_scan(cond, body, init, max_iter: int):
    """MJX's solver's ``_while_loop_scan`` (its line search) written out as ``max_iter`` trips (MJX passes
    ``ls_iterations``)."""
    val = init
    for _ in range(max_iter):
        go = cond(val)
        nxt = body(val)
        val = jax.tree.map(lambda a, b, go=go: jnp.where(go, a, b), nxt, val)
    return val
