"""Subgoals: the point at the reach on the line to a far goal, the goal itself within reach, and an
evaluation that steers only when asked."""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from envs.point_fourrooms import PointFourRooms
from splid_jax.common.evaluation import evaluate
from splid_jax.common.networks import make_policy
from splid_jax.common.subgoals import Steered, steered, subgoal


def test_a_far_goal_becomes_the_point_at_the_reach_on_the_line_to_it():
    achieved = jnp.array([[1.0, 2.0, 0.4], [0.0, 0.0, 0.0]])
    goal = jnp.array([[1.3, 2.4, 0.4], [0.03, 0.04, 0.0]])  # 0.5 away, and 0.05 away
    got = np.asarray(subgoal(achieved, goal, 0.2))
    np.testing.assert_allclose(got[0], [1.12, 2.16, 0.4], atol=1e-6)  # 0.2 along the same direction
    assert np.array_equal(got[1], np.asarray(goal[1]))  # within reach: the goal itself, bit for bit


def test_steered_policy_acts_on_the_subgoal_read_off_the_observation():
    @dataclasses.dataclass(frozen=True)
    class Echo:  # acts with the goal it was given
        def act(self, pstate, obs, goal):
            return goal

    obs = jnp.array([9.0, 0.0, 0.0, 0.0, 5.0])  # the achieved goal at [1, 4)
    policy = Steered(Echo(), (1, 4), 0.1)
    np.testing.assert_allclose(policy.act(None, obs, jnp.array([0.0, 1.0, 0.0])), [0.0, 0.1, 0.0], atol=1e-7)


def test_no_reach_keeps_the_policy_and_a_reach_steers_only_far_goals_in_an_evaluation():
    env = PointFourRooms()
    policy = make_policy(env.obs_size, env.goal_size, env.action_size, (8,), normalise=False)
    assert steered(policy, env, 0.0) is policy
    pstate, key = policy.init(jax.random.PRNGKey(0)), jax.random.PRNGKey(1)
    plain = evaluate(env, policy, pstate, key, 16)
    far = evaluate(env, steered(policy, env, 1e6), pstate, key, 16)  # every goal within reach: the same episodes
    jax.tree_util.tree_map(np.testing.assert_array_equal, plain, far)
    near = evaluate(env, steered(policy, env, 1e-3), pstate, key, 16)
    assert float(near["eval_return"]) != float(plain["eval_return"])  # a tiny reach changes the actions


def test_an_infinite_reach_is_the_goal_itself_without_a_nan_on_the_way():
    at = jnp.array([[0.3, -0.2], [1.0, 1.0]])
    goal = jnp.array([[5.0, 7.0], [1.0, 1.0]])  # far, and already achieved
    with jax.debug_nans(True):  # exploration's default reach: no branch may make a NaN
        np.testing.assert_array_equal(subgoal(at, goal, jnp.inf), goal)
