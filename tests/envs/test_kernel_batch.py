"""The kernels' batch limit (``kernel_envs``): a kernel where the innermost vmap holds at most that many envs, XLA's
batched code above it, whatever vmaps enclose it; above it the arithmetic is MJX's own, bit for bit."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
import pytest
from mujoco import mjx
from mujoco.mjx._src import solver as mjx_solver

import envs
from envs import fused_solver, kernel_batch
from splid_jax.common.errors import InvalidConfig
from tests.helpers import lowered_step, needs_kernels, triton_calls_for_gpu


# the kernels' limit and warps, lowered once for both tests below; the library's Cholesky (which no kernel
# calls) keeps the traces short
def _limited():
    return envs.make("push", substeps=1, kernel_envs=8, kernel_warps=4, cholesky="library")


@needs_kernels
def test_kernels_take_batches_up_to_the_limit_and_xla_larger_ones():
    # one env per program loses to batched operations at thousands of envs; a sweep's members (the outer axis)
    # do not count against the limit, the envs of one step (the inner axis) do (one vmap alone over the limit:
    # test_no_limit_keeps_the_kernel_function_itself)
    counts = [triton_calls_for_gpu(_limited(), b) for b in ((3, 8), (2, 9))]
    assert counts == [3, 0]  # at 8 envs Push's two contact groups and the solve
    with pytest.raises(InvalidConfig, match="kernel_envs"):
        envs.make("push", kernel_envs=-1)


@needs_kernels
def test_a_batch_above_the_limit_is_mjxs_own_solve():
    env = envs.make("push")
    model = env.mjx_model
    # Push at rest from MuJoCo's own forward step, its constraints in MJX's layout (MJX's forward compiles seconds)
    at_rest = mujoco.MjData(env.mj_model)
    mujoco.mj_forward(env.mj_model, at_rest)
    data = mjx.put_data(env.mj_model, at_rest)
    assert fused_solver.covers(model, data)  # a solve the fused one takes, below the limit
    warm = data.qacc + 0.1 * jax.random.normal(jax.random.PRNGKey(4), (5, model.nv))

    def solved(solve):  # only the warm start batched: the other fields reach the solve unbatched
        return jax.jit(jax.vmap(lambda w: solve(data.replace(qacc_warmstart=w)).qacc))(warm)

    mjxs = solved(lambda d: mjx_solver.solve(model, d))
    assert float(jnp.abs(data._impl.efc_J).max()) > 0  # the cube and the fingers rest on the table
    np.testing.assert_array_equal(solved(lambda d: fused_solver.solve(model, d, True, max_envs=4)), mjxs)


def test_no_limit_keeps_the_kernel_function_itself():
    def kernel(x):
        return x + 1

    assert kernel_batch.by_batch(kernel, lambda x: x, 0) is kernel
    limited = kernel_batch.by_batch(kernel, lambda x: x - 1, 2)
    assert float(limited(jnp.float32(1.0))) == 2.0  # unbatched: the kernel
    np.testing.assert_array_equal(jax.vmap(limited)(jnp.ones(2)), [2.0, 2.0])
    np.testing.assert_array_equal(jax.vmap(limited)(jnp.ones(3)), [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(jax.vmap(jax.vmap(limited))(jnp.ones((3, 2))), np.full((3, 2), 2.0))
    np.testing.assert_array_equal(jax.vmap(jax.vmap(limited))(jnp.ones((2, 3))), np.zeros((2, 3)))


@needs_kernels
def test_every_physics_kernel_takes_the_tasks_warps():
    # one warp per env is the faster kernel at every batch measured (BENCHMARKS.md); 4 is Triton's default
    # at the default's, as test_fused_collision lowers Push's step, and at 4, as the test above does
    for warps, env, batch in ((1, envs.make("push", substeps=1), (4,)), (4, _limited(), (3, 8))):
        text = lowered_step(env, batch, gpu=True)
        assert text.count("xla.gpu.triton") == 3  # the two contact groups and the solve
        assert text.count("num_warps = ") == text.count(f"num_warps = {warps} : i32") == 3
    with pytest.raises(InvalidConfig, match="kernel_warps"):
        envs.make("push", kernel_warps=3)
