"""The brax adapter: resets and steps under jit, works through brax's VmapWrapper and EpisodeWrapper,
and its own auto-reset draws a fresh goal where brax's AutoResetWrapper would repeat the first."""

from __future__ import annotations

import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from brax.envs.base import Env
from brax.envs.wrappers.training import AutoResetWrapper, EpisodeWrapper, VmapWrapper

import envs
from envs.brax_adapter import BraxGoalEnv


def _roll(env, state, n, action):
    def body(s, _):
        s = env.step(s, action)
        return s, (s.done, s.reward, s.metrics["success"], s.obs)

    return jax.lax.scan(body, state, None, length=n)


def test_point_resets_and_steps_under_jit_with_done_at_episode_end():
    goal_env = envs.make("point", max_episode_steps=3)
    env = BraxGoalEnv(goal_env)
    assert isinstance(env, Env) and env.observation_size == 4 and env.action_size == 2
    s = jax.jit(env.reset)(jax.random.PRNGKey(0))
    chex.assert_shape(s.obs, (4,))
    np.testing.assert_array_equal(s.obs[2:], s.pipeline_state.desired_goal)
    assert float(s.done) == 0.0
    _, (done, reward, success, _) = jax.jit(lambda s: _roll(env, s, 3, jnp.zeros(2)))(s)
    np.testing.assert_array_equal(done, [0.0, 0.0, 1.0])
    np.testing.assert_array_equal(reward, success)  # the point task's reward is 1 on the goal


def test_vmap_and_episode_wrappers():
    env = VmapWrapper(EpisodeWrapper(BraxGoalEnv(envs.make("point", max_episode_steps=50)), 4, 1), batch_size=5)
    s = jax.jit(env.reset)(jax.random.PRNGKey(1))
    chex.assert_shape(s.obs, (5, 4))
    _, (done, reward, success, obs) = jax.jit(lambda s: _roll(env, s, 4, jnp.ones((5, 2)) * 0.1))(s)
    chex.assert_shape(done, (4, 5))
    np.testing.assert_array_equal(done[-1], 1.0)  # EpisodeWrapper's length 4 ends the episode
    assert not np.asarray(done[:-1]).any()


def test_fresh_key_auto_reset_draws_new_goals_where_brax_repeats_the_first():
    goal_env = envs.make("point", max_episode_steps=2)
    ours = VmapWrapper(BraxGoalEnv(goal_env, auto_reset=True), batch_size=3)
    theirs = AutoResetWrapper(VmapWrapper(BraxGoalEnv(goal_env), batch_size=3))
    for env, same in [(ours, False), (theirs, True)]:
        s0 = jax.jit(env.reset)(jax.random.PRNGKey(2))
        s, (done, *_) = jax.jit(lambda s, env=env: _roll(env, s, 4, jnp.zeros((3, 2))))(s0)
        np.testing.assert_array_equal(done[:, 0], [0.0, 1.0, 0.0, 1.0])
        goals_equal = np.array_equal(s.pipeline_state.desired_goal, s0.pipeline_state.desired_goal)
        assert goals_equal == same
        np.testing.assert_array_equal(s.pipeline_state.step, 0)  # restarted after the second episode


@pytest.mark.slow
def test_reach_through_vmap_wrapper_under_jit():
    env = VmapWrapper(BraxGoalEnv(envs.make("reach"), auto_reset=True), batch_size=2)
    assert env.backend == "mjx" and env.observation_size == 13 and env.action_size == 4
    s = jax.jit(env.reset)(jax.random.PRNGKey(0))
    s = jax.jit(env.step)(s, jnp.ones((2, 4)))
    chex.assert_shape(s.obs, (2, 13))
    chex.assert_shape([s.reward, s.done, s.metrics["success"]], (2,))
    assert np.all(np.asarray(s.obs[:, 0] - 1.342) > 0.02)  # the gripper moved along +x
    assert not np.asarray(s.metrics["invalid"]).any()
