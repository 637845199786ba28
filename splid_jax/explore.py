"""Stage 1 of Algorithm 2: roll pi_theta + N(0, sigma^2) for a whole episode in every env,
keeping each state so SELECT can restore it."""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from envs.base import GoalEnv, State, step_batch
from splid_jax.networks import Policy, PolicyState


class Trajectory(NamedTuple):
    """Time-major batch of episodes: T actions taken from T states, T + 1 achieved goals."""

    states: State  # [T, N, ...] the state each action was taken in
    actions: jax.Array  # [T, N, A] executed (clipped) actions
    achieved: jax.Array  # [T + 1, N, G] achieved goal before and after every step
    invalid: jax.Array  # [T + 1, N] NaN flag of those same states


def explore(
    env: GoalEnv, policy: Policy, pstate: PolicyState, key: jax.Array, num_envs: int, sigma: jax.Array
) -> Trajectory:
    k_reset, k_noise = jax.random.split(key)
    start = jax.vmap(env.reset)(jax.random.split(k_reset, num_envs))

    def one_step(state: State, k: jax.Array):
        mean = policy.mean(pstate, state.obs, state.desired_goal)
        noise = sigma * jax.random.normal(k, mean.shape)
        action = jnp.clip(mean + noise, -1.0, 1.0)
        nxt = step_batch(env, state, action)
        return nxt, (state, action, nxt.achieved_goal, nxt.invalid)

    _, (states, actions, ag_next, inv_next) = jax.lax.scan(
        one_step, start, jax.random.split(k_noise, env.episode_length)
    )
    achieved = jnp.concatenate([start.achieved_goal[None], ag_next], axis=0)
    invalid = jnp.concatenate([start.invalid[None], inv_next], axis=0)
    return Trajectory(states=states, actions=actions, achieved=achieved, invalid=invalid)
