"""The one place MJX's private functions are replaced: each given function in place inside the block, MJX's own
everywhere else, also after a failed trace."""

from __future__ import annotations

import jax
import jax.scipy.linalg as jsl
import pytest
from mujoco.mjx._src import collision_driver
from mujoco.mjx._src import solver as mjx_solver

from envs import fused_collision, fused_solver, small_cholesky, solver_loops
from envs.mjx_patch import patched_mjx


def _mjx_own():
    return (jsl.cho_factor, jsl.cho_solve, jax.lax.while_loop, mjx_solver._while_loop_scan, mjx_solver.solve,
            dict(collision_driver._COLLISION_FUNC))  # fmt: skip


def test_every_replacement_holds_inside_the_block_alone():
    before = _mjx_own()
    solve, groups = fused_solver.fused(), fused_collision.groups()
    with patched_mjx(cholesky=small_cholesky.UNROLLED, line_search=solver_loops.written_out_scan, solve=solve,
                     collide=groups):  # fmt: skip
        assert (jsl.cho_factor, jsl.cho_solve) == small_cholesky.UNROLLED
        assert mjx_solver._while_loop_scan is solver_loops.written_out_scan
        assert jax.lax.while_loop is before[2]  # JAX's own loops are never replaced
        assert mjx_solver.solve is solve
        table = collision_driver._COLLISION_FUNC
        assert {k for k, f in table.items() if f is not before[5][k]} == set(groups)
    assert _mjx_own() == before


def test_nothing_given_nothing_replaced_and_a_failed_trace_restores_mjx():
    before = _mjx_own()
    with patched_mjx(cholesky=small_cholesky.UNROLLED):
        with patched_mjx():
            assert jsl.cho_factor is small_cholesky.cho_factor and mjx_solver.solve is before[4]
    assert _mjx_own() == before
    with pytest.raises(RuntimeError), patched_mjx(cholesky=small_cholesky.UNROLLED, solve=fused_solver.fused()):
        raise RuntimeError("a failed trace")
    assert _mjx_own() == before
