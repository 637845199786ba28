"""The written-out MJX solver (whole, or its line search alone): the loops' arithmetic to float rounding,
and nothing else swapped."""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs import solver_loops


@functools.cache
def _path(choice: str):
    """Six steps of four envs with the solver's loops as ``choice`` has them; the loops' path is computed
    once for both written-out choices. One substep keeps the written-out programs' compiles short; two
    Newton trips of two line-search trips each tell a wrong count of either (about 1e-2)."""
    env = envs.make("push", substeps=1, iterations=2, ls_iterations=2, solver_loops=choice)
    state = jax.jit(lambda key: jax.vmap(env.reset)(jax.random.split(key, 4)))(jax.random.PRNGKey(0))
    actions = jax.random.uniform(jax.random.PRNGKey(1), (6, 4, 4), minval=-1.0, maxval=1.0)

    def step(s, a):
        s = jax.vmap(env.step)(s, a)
        return s, s.physics.qpos

    return np.asarray(jax.jit(lambda s: jax.lax.scan(step, s, actions)[1])(state))


def _loop_primitives(**options) -> set[str]:
    env = envs.make("push", substeps=1, iterations=2, ls_iterations=2, **options)
    state = jax.eval_shape(env.reset, jax.random.PRNGKey(0))  # its shapes are all a trace needs
    text = str(jax.make_jaxpr(env.step)(state, jnp.zeros(4)))
    return {p for p in ("while[", "scan[") if p in text}


def test_written_out_solver_leaves_no_loop_in_the_step():
    assert _loop_primitives(solver_loops="loops") == {"while[", "scan["}  # Newton, its line search, the substeps
    assert _loop_primitives(solver_loops="unrolled") == {"scan["}  # the substeps' loop alone
    assert _loop_primitives(solver_loops="auto") == {"while[", "scan["}  # the loops on the CPU
    assert _loop_primitives() == {"while[", "scan["}  # the default, gpu-search: the loops on the CPU


def test_written_out_line_search_keeps_the_newton_loop_alone():
    env = envs.make("push", substeps=1, iterations=2, ls_iterations=2, solver_loops="search")
    text = str(jax.make_jaxpr(env.step)(jax.eval_shape(env.reset, jax.random.PRNGKey(0)), jnp.zeros(4)))
    assert text.count("while[") == 1 and text.count("scan[") == 1  # the Newton loop and the substeps'


def test_gpu_choices_write_the_solver_out_on_a_gpu_only():
    on = [solver_loops.writes_out("auto", b) for b in ("gpu", "cpu", "tpu")]
    assert on == [(True, True), (False, False), (False, False)]
    assert solver_loops.writes_out("unrolled", "cpu") == (True, True)
    assert solver_loops.writes_out("search", "gpu") == (False, True)
    assert solver_loops.writes_out("loops", "gpu") == (False, False)
    on = [solver_loops.writes_out("gpu-search", b) for b in ("gpu", "cpu")]
    assert on == [(False, True), (False, False)]


@pytest.mark.parametrize("choice", ["unrolled", "search"])
def test_written_out_solver_follows_the_loops_path(choice):
    loops, written = _path("loops"), _path(choice)
    assert np.isfinite(written).all()
    np.testing.assert_allclose(written, loops, atol=1e-5)


def test_only_the_solvers_loops_are_swapped_and_only_inside_the_block():
    before = jax.lax.while_loop
    with solver_loops.unrolled_in_mjx(iterations=3):
        # a loop that is not the solver's keeps its own trip count
        n = jax.jit(lambda x: jax.lax.while_loop(lambda i: i < 10, lambda i: i + 1, x))(jnp.int32(0))
    assert int(n) == 10
    assert jax.lax.while_loop is before


def test_settings_record_the_written_out_solver_only_when_chosen():
    # a run recorded before the option existed matches a task at its default
    assert "solver_loops" not in envs.make("push").settings()
    assert envs.make("push", solver_loops="loops").settings()["solver_loops"] == "loops"
    assert envs.make("push", solver_loops="unrolled").settings()["solver_loops"] == "unrolled"
