"""The written-out MJX solver: the loops' arithmetic to float rounding, and nothing else swapped."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

import envs
from envs import solver_loops


def _path(**options):
    env = envs.make("push", substeps=2, iterations=2, ls_iterations=2, **options)
    state = jax.vmap(env.reset)(jax.random.split(jax.random.PRNGKey(0), 4))
    actions = jax.random.uniform(jax.random.PRNGKey(1), (6, 4, 4), minval=-1.0, maxval=1.0)

    def step(s, a):
        s = jax.vmap(env.step)(s, a)
        return s, s.physics.qpos

    return np.asarray(jax.jit(lambda s: jax.lax.scan(step, s, actions)[1])(state))


def _loop_primitives(**options) -> set[str]:
    env = envs.make("push", substeps=1, iterations=2, ls_iterations=2, **options)
    state = env.reset(jax.random.PRNGKey(0))
    text = str(jax.make_jaxpr(env.step)(state, jnp.zeros(4)))
    return {p for p in ("while[", "scan[") if p in text}


def test_written_out_solver_leaves_no_loop_in_the_step():
    assert _loop_primitives() == {"while[", "scan["}  # the Newton loop, its line search (and the substeps)
    assert _loop_primitives(solver_loops="unrolled") == {"scan["}  # the substeps' loop alone
    assert _loop_primitives(solver_loops="auto") == {"while[", "scan["}  # the loops on the CPU


def test_auto_writes_the_solver_out_on_a_gpu_only():
    assert [solver_loops.writes_out("auto", b) for b in ("gpu", "cpu", "tpu")] == [True, False, False]
    assert solver_loops.writes_out("unrolled", "cpu") and not solver_loops.writes_out("loops", "gpu")


def test_written_out_solver_follows_the_loops_path():
    loops, written = _path(), _path(solver_loops="unrolled")
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
    assert envs.make("push", solver_loops="unrolled").settings()["solver_loops"] == "unrolled"
