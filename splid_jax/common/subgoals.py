"""Steering a goal-conditioned policy at subgoals: in evaluations, and in exploration where explore_subgoal_reach says.

A policy taught with hindsight goals a few steps ahead has seen goals only so far from the achieved goal
(Push's relabel buffer: 90 % within 0.19 m of the cube); a farther goal is an input outside that range,
and such episodes end short. Given instead the point on the line to the goal at most ``reach`` from where
the achieved goal is now, and the goal itself once within reach, the policy is asked only what it learnt.
Success is still judged against the task's goal."""

from __future__ import annotations

import dataclasses
from typing import Any

import jax
import jax.numpy as jnp

from envs.base import GoalEnv


def subgoal(achieved: jax.Array, goal: jax.Array, reach: float) -> jax.Array:
    """``goal`` where it lies within ``reach`` of ``achieved``, else the point at ``reach`` on the line to it."""
    gap = goal - achieved
    far = jnp.linalg.norm(gap, axis=-1, keepdims=True)
    step = jnp.minimum(reach, far) / jnp.maximum(far, 1e-12)  # finite at an infinite reach: no NaN to discard
    return jnp.where(far > reach, achieved + gap * step, goal)


def traced_reach(reach: float) -> jax.Array:
    """``reach`` as a value a compiled program takes: 0 (no subgoals) is infinite, where ``subgoal`` gives the
    goal itself, so one program serves every reach."""
    return jnp.float32(reach or jnp.inf)


@dataclasses.dataclass(frozen=True)
class Steered:
    """``policy`` acting towards ``subgoal``s, the achieved goal read off the observation at ``achieved_slice``."""

    policy: Any
    achieved_slice: tuple[int, int]
    reach: float

    def act(self, pstate: Any, obs: jax.Array, goal: jax.Array) -> jax.Array:
        lo, hi = self.achieved_slice
        return self.policy.act(pstate, obs, subgoal(obs[..., lo:hi], goal, self.reach))


def steered(policy: Any, env: GoalEnv, reach: float) -> Any:
    """The policy an evaluation acts with: ``policy`` itself at ``reach`` 0, else steered within ``reach``
    (the task's goal units: metres on the Fetch tasks) of ``env``'s achieved goal."""
    if not reach:
        return policy
    start = env.achieved_goal_start
    return Steered(policy, (start, start + env.goal_size), float(reach))
