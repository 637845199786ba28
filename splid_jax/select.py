"""Stage 2 of Algorithm 2: hindsight relabelling and SELECT by first hit time.

For every explored step t and every h in 1..H the candidate is (s_t, g' = m(s_{t+h}), a_t). SELECT
restores s_t pursuing g' and runs the current deterministic policy for h steps: if the policy
reaches g', the explored actions were no faster and the pair is rejected. All candidates of one
h are one vmapped replay of exactly h steps, so no step is simulated past its own horizon."""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from envs.base import GoalEnv, State
from splid_jax.explore import Trajectory
from splid_jax.networks import Policy, PolicyState


class Candidates(NamedTuple):
    """Flat batch of relabelled pairs; the layout is static, validity lives in masks."""

    obs: jax.Array  # [M, O]
    goal: jax.Array  # [M, G]
    action: jax.Array  # [M, A]
    valid: jax.Array  # [M] a real candidate: the achieved goal moved, no NaN, h <= horizon
    accept: jax.Array  # [M] valid and not solved by the current policy within h steps


def policy_reaches(env: GoalEnv, policy: Policy, pstate: PolicyState, state: State, goal: jax.Array, h: int):
    """Whether the deterministic policy, restored at ``state``, hits ``goal`` within ``h`` steps."""

    def one_step(carry, _):
        s, hit = carry
        s = env.step(s, policy.act(pstate, s.obs, s.desired_goal))
        return (s, hit | (s.success & ~s.invalid)), None

    start = env.with_goal(state, goal)
    (_, hit), _ = jax.lax.scan(one_step, (start, jnp.bool_(False)), None, length=h)
    return hit


def num_candidates(episode_length: int, max_horizon: int, num_envs: int) -> int:
    return num_envs * sum(episode_length - h + 1 for h in range(1, max_horizon + 1))


def replay_steps(episode_length: int, horizon: int, num_envs: int) -> int:
    """Simulator steps SELECT takes per iteration (for reporting)."""
    return num_envs * sum(h * (episode_length - h + 1) for h in range(1, horizon + 1))


def select(
    env: GoalEnv,
    policy: Policy,
    pstate: PolicyState,
    traj: Trajectory,
    max_horizon: int,
    horizon: jax.Array,
    use_select: bool,
) -> Candidates:
    """``max_horizon`` fixes the shapes; ``horizon`` (traced, <= max_horizon) masks, so runs with
    different H can share one compiled program. ``use_select=False`` stores every valid pair."""
    T = env.episode_length
    parts = []
    for h in range(1, max_horizon + 1):
        n_t = T - h + 1  # t = 0..T-h so that t + h <= T
        states = jax.tree_util.tree_map(lambda x, n=n_t: x[:n], traj.states)
        goal = traj.achieved[h : T + 1]
        valid = (
            ~env.success(traj.achieved[:n_t], goal)  # nothing achieved between t and t + h
            & ~traj.invalid[:n_t]
            & ~traj.invalid[h : T + 1]
            & (h <= horizon)
        )
        flat = jax.tree_util.tree_map(lambda x: x.reshape((-1,) + x.shape[2:]), (states, goal, traj.actions[:n_t]))
        states_f, goal_f, action_f = flat
        valid = valid.reshape(-1)
        if use_select:
            reached = jax.vmap(lambda s, g, h=h: policy_reaches(env, policy, pstate, s, g, h))(states_f, goal_f)
            accept = valid & ~reached
        else:
            accept = valid
        parts.append(Candidates(states_f.obs, goal_f, action_f, valid, accept))
    return Candidates(*(jnp.concatenate(xs, axis=0) for xs in zip(*parts, strict=True)))
