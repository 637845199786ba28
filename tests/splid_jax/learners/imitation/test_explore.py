"""Exploration: the fingers' noise held for several steps while the arm's stays fresh, and acting towards
subgoals when asked."""

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

import envs
from splid_jax.learners.imitation.explore import draws, hold_fingers, rollout


def test_the_fingers_noise_is_held_and_the_arms_is_not():
    noise = jax.random.normal(jax.random.PRNGKey(0), (10, 3, 4))
    held = np.asarray(jax.jit(hold_fingers)(noise, jnp.int32(4)))
    np.testing.assert_array_equal(held[..., :3], noise[..., :3])
    for t in range(10):
        np.testing.assert_array_equal(held[t, :, 3], noise[t - t % 4, :, 3])  # drawn at 0, 4 and 8
    np.testing.assert_array_equal(hold_fingers(noise, jnp.int32(1)), noise)  # 1: every step afresh


@dataclasses.dataclass(frozen=True)
class _Towards:
    """A policy that steps straight at the goal it is given, so its actions show that goal."""

    env: envs.GoalEnv

    def mean(self, pstate, obs, goal):
        lo = self.env.achieved_goal_start
        return jnp.clip((goal - obs[..., lo : lo + self.env.goal_size]) / 10.0, -1.0, 1.0)


def test_exploration_acts_towards_subgoals_within_reach_and_keeps_the_tasks_goal():
    env = envs.make("point")
    keys, noise = draws(env, jax.random.PRNGKey(0), 8)
    run = jax.jit(lambda reach: rollout(env, _Towards(env), None, keys, noise, jnp.float32(0.0), reach))
    plain, far, near = run(jnp.inf), run(jnp.float32(100.0)), run(jnp.float32(0.5))
    np.testing.assert_array_equal(plain.actions, far.actions)  # every goal within reach: the goal itself
    given = np.asarray(near.actions) * 10.0  # the subgoal minus the achieved goal
    assert np.linalg.norm(given, axis=-1).max() <= 0.5 + 1e-5
    assert np.linalg.norm(np.asarray(plain.actions) * 10.0, axis=-1).max() > 1.0
    np.testing.assert_array_equal(near.states.desired_goal, plain.states.desired_goal)  # judged at the goal
