"""Oracles the tests check the learners against: plain definitions of what the compiled programs
compute fast, and small measures shared by several test files."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import pytest

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


def _triton_calls(env: GoalEnv, batch: tuple[int, ...], gpu: bool) -> int:
    """Triton kernel calls in ``env``'s step vmapped over each axis of ``batch`` (envs last), traced and lowered
    for this CPU or for a GPU (Pallas's Triton lowering needs no device; the caller sets the backend)."""
    state = jax.eval_shape(jax.vmap(env.reset), jax.random.split(jax.random.PRNGKey(0), batch[-1]))
    state = jax.tree.map(lambda x: jax.ShapeDtypeStruct(batch[:-1] + x.shape, x.dtype), state)
    actions = jax.ShapeDtypeStruct((*batch, env.action_size), jnp.float32)
    step = env.step
    for _ in batch:
        step = jax.vmap(step)
    traced = jax.jit(lambda s, a: step(s, a)).trace(state, actions)  # a new function: jit caches traces by function
    return traced.lower(**({"lowering_platforms": ("cuda",)} if gpu else {})).as_text().count("xla.gpu.triton")


def triton_calls_for_gpu(env: GoalEnv, monkeypatch, batch: tuple[int, ...] = (4,)) -> int:
    """How many Triton kernel calls ``env``'s batched step holds as traced for, and lowered for, a GPU."""
    with monkeypatch.context() as patched:
        patched.setattr(jax, "default_backend", lambda: "gpu")
        return _triton_calls(env, batch, gpu=True)


def triton_calls_in_step(env: GoalEnv, monkeypatch, batch: tuple[int, ...] = (4,)) -> tuple[int, int]:
    """How many Triton kernel calls ``env``'s batched step holds as traced on this CPU and as traced for a GPU."""
    return _triton_calls(env, batch, gpu=False), triton_calls_for_gpu(env, monkeypatch, batch)
