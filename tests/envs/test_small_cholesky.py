"""The unrolled Cholesky that MJX steps use: equal to jax.scipy.linalg's to float rounding, in
and live in a Push step (no library Cholesky left in its program)."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import jax.scipy.linalg as jsl
import numpy as np
import pytest

import envs
from envs import small_cholesky
from tests.helpers import needs_kernels


def _spd(n, seed):
    m = np.random.default_rng(seed).normal(size=(n, n + 3))
    return jnp.asarray(m @ m.T / (n + 3) + 0.1 * np.eye(n), jnp.float32)


@pytest.mark.parametrize("n", [1, 3, 9, 11])
@pytest.mark.parametrize("lower", [False, True])
def test_factor_and_solve_match_the_library(n, lower):
    a = _spd(n, n)
    b = jnp.asarray(np.random.default_rng(100 + n).normal(size=(n,)), jnp.float32)
    bm = jnp.stack([b, 2.0 * b + 1.0], axis=1)
    ours = small_cholesky.cho_factor(a, lower=lower)
    ref = jsl.cho_factor(a, lower=lower)
    assert ours[1] == lower
    tri = jnp.tril(ref[0]) if lower else jnp.triu(ref[0])  # the library leaves junk in the other half
    np.testing.assert_allclose(ours[0], tri, rtol=2e-5, atol=2e-6)
    np.testing.assert_allclose(small_cholesky.cho_solve(ours, b), jsl.cho_solve(ref, b), rtol=1e-4, atol=1e-5)
    np.testing.assert_allclose(small_cholesky.cho_solve(ours, bm), jsl.cho_solve(ref, bm), rtol=1e-4, atol=1e-5)
    np.testing.assert_allclose(a @ small_cholesky.cho_solve(ours, b), b, rtol=1e-3, atol=1e-4)


def test_large_or_batched_matrices_go_to_the_library():
    a = _spd(small_cholesky.MAX_UNROLLED + 1, 0)
    np.testing.assert_array_equal(small_cholesky.cho_factor(a)[0], jsl.cho_factor(a)[0])
    batch = jnp.stack([_spd(3, 1), _spd(3, 2)])
    np.testing.assert_array_equal(small_cholesky.cho_factor(batch)[0], jsl.cho_factor(batch)[0])


@needs_kernels
@pytest.mark.slow
def test_push_step_has_no_library_cholesky_and_steps_alike(fetch, primitives):
    fast, library = envs.make("push"), envs.make("push", cholesky="library")
    state, actions, w = fetch.reset(fast), fetch.random_actions(1), jnp.zeros(fetch.B)
    prims_fast = primitives(fetch.program(fast), state, actions, w)  # the traces the runs then compile
    prims_lib = primitives(fetch.program(library), state, actions, w)
    assert "cholesky" in prims_lib and "cholesky" not in prims_fast
    assert "triangular_solve" not in prims_fast
    a, b = (jax.tree_util.tree_map(lambda x: x[2], fetch.run(env, actions)[2]) for env in (fast, library))
    np.testing.assert_allclose(a.physics.qpos, b.physics.qpos, atol=1e-4)  # after 3 steps
    np.testing.assert_allclose(a.physics.qvel, b.physics.qvel, atol=1e-2)
