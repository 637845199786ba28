"""Oracles the tests check the learners against: plain definitions of what the compiled programs
compute fast, and small measures shared by several test files."""

from __future__ import annotations

import contextlib
import functools
from unittest import mock

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs import physics
from envs.base import GoalEnv, State
from splid_jax.common.networks import Policy, PolicyState
from splid_jax.learners.imitation.explore import Trajectory, draws, rollout

# for a test of the kernels inside a task's step: on a MuJoCo they were not checked on, the tasks run stock MJX
needs_kernels = pytest.mark.skipif(
    not physics.kernels_checked(), reason=f"the physics kernels run on MuJoCo {physics.KERNELS_CHECKED} alone"
)


def explore(
    env: GoalEnv, policy: Policy, pstate: PolicyState, key: jax.Array, num_envs: int, sigma: jax.Array
) -> Trajectory:
    """One episode in each of ``num_envs`` envs, resets and noise drawn from ``key`` as an iteration draws them."""
    return rollout(env, policy, pstate, *draws(env, key, num_envs), sigma)


def policy_reaches(
    env: GoalEnv, policy: Policy, pstate: PolicyState, state: State, goal: jax.Array, h, at_final=False
):
    """Whether the deterministic policy, restored at ``state``, hits ``goal`` within ``h`` steps (or,
    ``at_final``, is at it after exactly ``h`` steps): the definition SELECT's work queue must agree with."""

    def one_step(_, carry):
        s, hit = carry
        s = env.step(s, policy.act(pstate, s.obs, s.desired_goal))
        now = s.success & ~s.invalid
        return s, jnp.where(at_final, now, hit | now)

    _, hit = jax.lax.fori_loop(0, h, one_step, (env.with_goal(state, goal), jnp.bool_(False)))
    return hit


def random_policy_success(env: GoalEnv, episodes: int = 256) -> float:
    """Success at any step of uniformly random actions on a 2-D action task: the floor a learner must beat."""

    def episode(key):
        k0, k1 = jax.random.split(key)
        s = env.reset(k0)

        def one(s, k):
            s = env.step(s, jax.random.uniform(k, (2,), minval=-1, maxval=1))
            return s, s.success

        return jnp.any(jax.lax.scan(one, s, jax.random.split(k1, env.episode_length))[1])

    return float(jnp.mean(jax.jit(jax.vmap(episode))(jax.random.split(jax.random.PRNGKey(7), episodes))))


def with_counted_jit(learner, compiler_options=None):
    """``learner`` with ``jitted``, its jitted chunk (compiled with ``compiler_options``), and ``traces``,
    how often Python traced it: one per compilation."""
    learner.traces = 0

    def counted(state, hyper):
        learner.traces += 1
        return learner.chunk(state, hyper)

    learner.jitted = jax.jit(counted, compiler_options=compiler_options)
    return learner


@functools.cache
def lowered_step(env: GoalEnv, batch: tuple[int, ...], gpu: bool) -> str:
    """The text of ``env``'s step vmapped over each axis of ``batch`` (envs last), traced and lowered for this
    CPU or, ``gpu``, for a GPU (Pallas's Triton lowering needs no device; the tasks read the backend while
    traced): once per task, batch and backend for every test reading it (conftest puts their files on one worker)."""
    state = jax.eval_shape(jax.vmap(env.reset), jax.random.split(jax.random.PRNGKey(0), batch[-1]))
    state = jax.tree.map(lambda x: jax.ShapeDtypeStruct(batch[:-1] + x.shape, x.dtype), state)
    actions = jax.ShapeDtypeStruct((*batch, env.action_size), jnp.float32)
    step = env.step
    for _ in batch:
        step = jax.vmap(step)
    backend = mock.patch.object(jax, "default_backend", lambda: "gpu") if gpu else contextlib.nullcontext()
    with backend:
        traced = jax.jit(lambda s, a: step(s, a)).trace(state, actions)  # a new function: jit caches traces by function
        return traced.lower(**({"lowering_platforms": ("cuda",)} if gpu else {})).as_text()


def triton_calls_for_gpu(env: GoalEnv, batch: tuple[int, ...] = (4,)) -> int:
    """How many Triton kernel calls ``env``'s batched step holds as traced for, and lowered for, a GPU."""
    return lowered_step(env, batch, gpu=True).count("xla.gpu.triton")


def triton_calls_in_step(env: GoalEnv, batch: tuple[int, ...] = (4,)) -> tuple[int, int]:
    """How many Triton kernel calls ``env``'s batched step holds as traced on this CPU and as traced for a GPU."""
    return lowered_step(env, batch, gpu=False).count("xla.gpu.triton"), triton_calls_for_gpu(env, batch)


@functools.cache
def solver_program(choice: str):
    """Six steps of four Push envs with the MJX solver's loops as ``choice`` has them: the traced episode
    program and its start. One substep keeps the written-out programs' compiles short; two Newton trips of
    two line-search trips each tell a wrong count of either (about 1e-2); the library's Cholesky, one
    operation where the unrolled one is many, keeps them shorter still. The loops' program is the reference
    of test_solver_loops and test_fused_solver alike (conftest puts the files on one worker)."""
    env = envs.make("push", substeps=1, iterations=2, ls_iterations=2, cholesky="library", solver_loops=choice)
    state = jax.jit(lambda key: jax.vmap(env.reset)(jax.random.split(key, 4)))(jax.random.PRNGKey(0))
    actions = jax.random.uniform(jax.random.PRNGKey(1), (6, 4, 4), minval=-1.0, maxval=1.0)

    def step(s, a):
        s = jax.vmap(env.step)(s, a)
        return s, s.physics.qpos

    return jax.jit(lambda s: jax.lax.scan(step, s, actions)[1]).trace(state), state


@functools.cache
def solver_path(choice: str) -> np.ndarray:
    """The qpos path [6, 4, nq] of ``solver_program(choice)``, computed once for every test reading it."""
    traced, state = solver_program(choice)
    return np.asarray(traced.lower().compile()(state))
