"""Evaluation judges the policy on the task's standard starts, whatever the training task explores."""

from __future__ import annotations

import dataclasses

import jax
import numpy as np

import envs
from envs.point_fourrooms import PointFourRooms
from splid_jax.common.evaluation import evaluate
from splid_jax.common.networks import make_policy


@dataclasses.dataclass(frozen=True)
class _TrainingOnlyStarts(PointFourRooms):
    def evaluation_task(self):
        return PointFourRooms()

    def reset(self, key):
        raise AssertionError("evaluation reset the training task")


def test_evaluation_resets_the_standard_task():
    env = _TrainingOnlyStarts()
    policy = make_policy(env.obs_size, env.goal_size, env.action_size, (8,), normalise=False)
    pstate = policy.init(jax.random.PRNGKey(0))
    metrics = evaluate(env, policy, pstate, jax.random.PRNGKey(1), 4)
    assert 0.0 <= float(metrics["eval_success"]) <= 1.0


def test_rollout_and_the_reference_starts_reset_the_standard_task():
    from splid_jax.reference.mapping import our_starts
    from splid_jax.rollout import rollout

    env = _TrainingOnlyStarts()
    policy = make_policy(env.obs_size, env.goal_size, env.action_size, (8,), normalise=False)
    states = rollout(env, policy, policy.init(jax.random.PRNGKey(0)), jax.random.PRNGKey(1), 4)
    assert states.obs.shape[:2] == (env.episode_length + 1, 4)
    grasping = envs.make("pick_and_place", grasped_starts=1.0)
    start = our_starts(grasping, jax.random.PRNGKey(1), 8)["state"]
    np.testing.assert_allclose(start.achieved_goal[:, 2], grasping.layout.object_rest_z, atol=1e-6)  # on the table
