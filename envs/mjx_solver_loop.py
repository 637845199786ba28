"""MJX's constraint-solver loop as a loop of fixed trip count.

Why: under ``jax.vmap`` MJX's Newton solver is a ``lax.while_loop`` whose predicate (some lane has
not converged) the GPU hands to the host after every iteration. The same loop as a ``lax.scan`` of
``iterations`` trips, each a ``lax.cond`` on the same predicate (a no-op once it fails), computes
the same values lane by lane, and a scan's trip count is known to the compiler."""

from __future__ import annotations

import contextlib
import threading

import jax

SOLVER_MODULE = "mujoco.mjx._src.solver"
_lock = threading.RLock()


def fixed_trips(cond_fun, body_fun, init_val, trips: int):
    """``while cond_fun(x): x = body_fun(x)``, run at most ``trips`` times, as a scan."""

    def trip(val, _):
        return jax.lax.cond(cond_fun(val), body_fun, lambda v: v, val), None

    return jax.lax.scan(trip, init_val, None, length=trips)[0]


@contextlib.contextmanager
def fixed_solver_trips(iterations: int, enabled: bool = True):
    """Within the block, MJX's solver loop (and no other ``lax.while_loop``) runs as
    ``fixed_trips(..., iterations)``."""
    if not enabled:
        yield
        return
    with _lock:
        original = jax.lax.while_loop

        def while_loop(cond_fun, body_fun, init_val):
            if getattr(body_fun, "__module__", None) == SOLVER_MODULE:
                return fixed_trips(cond_fun, body_fun, init_val, iterations)
            return original(cond_fun, body_fun, init_val)

        jax.lax.while_loop = while_loop
        try:
            yield
        finally:
            jax.lax.while_loop = original
