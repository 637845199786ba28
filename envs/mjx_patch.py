"""The one place where MJX's private functions are replaced: the physics kernels' way into a step.

MJX looks up the functions below when its code runs, which under ``jit`` is trace time only, so a step traced
inside ``patched_mjx`` keeps the replacements in its compiled program and nothing changes outside the block. It is
reached only through a task whose ``physics`` is ``kernels`` on the MuJoCo version the kernels were checked against
(``envs/physics.py``); every other step calls MJX as the library it is.

What may be replaced, each by its module's function (``None`` or ``False`` leaves MJX's):
- ``jax.scipy.linalg.cho_factor`` / ``cho_solve``: ``envs/small_cholesky.py``'s unrolled ones;
- the solver's scan-based line search: ``envs/solver_loops.py``'s written-out one;
- ``mujoco.mjx._src.solver.solve``: ``envs/fused_solver.py``'s solve;
- entries of ``mujoco.mjx._src.collision_driver._COLLISION_FUNC``: ``envs/fused_collision.py``'s pair groups, and
  ``envs/box_cylinder.py``'s, a pair MJX lacks: added within the block, removed again on the way out.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable

import jax.scipy.linalg as jsl

TRACE_LOCK = threading.RLock()  # held while MJX's functions are replaced: two threads never trace through at once


@contextlib.contextmanager
def patched_mjx(
    *,
    cholesky: tuple[Callable, Callable] | None = None,
    line_search: Callable | None = None,
    solve: Callable | None = None,
    collide: dict | None = None,
):
    """Within the block, MJX factors with ``cholesky`` (cho_factor, cho_solve), runs its solver's line search with
    ``line_search``, solves with ``solve`` and collides the geom-type pairs
    of ``collide`` ({(type1, type2): group function}) as given; each restored on the way out, also after an
    error."""
    from mujoco.mjx._src import collision_driver
    from mujoco.mjx._src import solver as mjx_solver

    with TRACE_LOCK:
        table = collision_driver._COLLISION_FUNC
        saved = (jsl.cho_factor, jsl.cho_solve, mjx_solver._while_loop_scan, mjx_solver.solve)
        saved_groups = {key: table.get(key) for key in collide or {}}
        try:
            if cholesky:
                jsl.cho_factor, jsl.cho_solve = cholesky
            if line_search:
                mjx_solver._while_loop_scan = line_search
            if solve:
                mjx_solver.solve = solve
            table.update(collide or {})
            yield
        finally:
            jsl.cho_factor, jsl.cho_solve, mjx_solver._while_loop_scan, mjx_solver.solve = saved
            for key, group in saved_groups.items():
                if group is None:
                    del table[key]
                else:
                    table[key] = group
