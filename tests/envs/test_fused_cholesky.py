"""The Cholesky kernels: the library's factor and solve to float rounding (their programs run with XLA here), a Push
path through them equal to the written-out one's, one Triton call each in a step lowered for a GPU, none on a CPU."""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import jax.scipy.linalg as jsl
import numpy as np
import pytest

import envs
from envs import fused_cholesky
from tests.helpers import triton_calls_in_step


def _spd(n, seed):
    m = np.random.default_rng(seed).normal(size=(n, n + 3))
    return jnp.asarray(m @ m.T / (n + 3) + 0.1 * np.eye(n), jnp.float32)


@pytest.mark.parametrize("max_envs", [0, 2])  # the kernels at every batch / the written-out code above 2
@pytest.mark.parametrize("lower", [False, True])
def test_factor_and_solve_match_the_library_for_a_batch(max_envs, lower):
    a = jnp.stack([_spd(9, s) for s in range(3)])
    b = jnp.asarray(np.random.default_rng(7).normal(size=(3, 9)), jnp.float32)
    ref = jax.vmap(lambda m: jsl.cho_factor(m, lower=lower)[0])(a)
    want = jax.vmap(lambda m, v: jsl.cho_solve(jsl.cho_factor(m), v))(a, b)
    with fused_cholesky.fused_in_mjx(max_envs=max_envs, interpret=True):
        assert jsl.cho_factor(a[0], lower=lower)[1] == lower

        def both(m, v):
            return jsl.cho_factor(m, lower=lower)[0], jsl.cho_solve(jsl.cho_factor(m), v)

        factor, x = jax.jit(jax.vmap(both))(a, b)
    tri = jnp.tril(ref) if lower else jnp.triu(ref)  # the library leaves junk in the other half
    np.testing.assert_allclose(factor, tri, rtol=2e-5, atol=2e-6)
    np.testing.assert_allclose(x, want, rtol=1e-4, atol=1e-5)


@functools.cache
def _path(kernels: bool) -> np.ndarray:
    """qpos over six steps of four Push envs (one substep each), the Cholesky kernels' programs run by XLA or
    the written-out Cholesky."""
    env = envs.make("push", substeps=1, cholesky="library" if kernels else "unrolled")
    state = jax.jit(lambda key: jax.vmap(env.reset)(jax.random.split(key, 4)))(jax.random.PRNGKey(0))
    actions = jax.random.uniform(jax.random.PRNGKey(1), (6, 4, 4), minval=-1.0, maxval=1.0)

    def step(s, a):
        s = jax.vmap(env.step)(s, a)
        return s, s.physics.qpos

    with fused_cholesky.fused_in_mjx(kernels, interpret=True):  # the task's "library" leaves the swap to it
        return np.asarray(jax.jit(lambda s: jax.lax.scan(step, s, actions)[1])(state))


def test_push_path_through_the_kernels_follows_the_written_out_cholesky():
    kernels, unrolled = _path(True), _path(False)
    assert np.isfinite(kernels).all()
    assert np.abs(unrolled[-1] - unrolled[0]).max() > 1e-3  # the envs moved
    np.testing.assert_allclose(kernels, unrolled, atol=1e-5)


def test_push_factors_and_solves_in_kernels_on_a_gpu_only(monkeypatch):
    env = envs.make("push", substeps=1, cholesky="gpu-fused")
    # the default's three (two contact groups, the constraint solve), and per substep two factors and two solves
    assert triton_calls_in_step(env, monkeypatch) == (0, 7)
    assert "cholesky=unrolled" in env.kernel_fallback(RuntimeError("Triton compilation failed"))
