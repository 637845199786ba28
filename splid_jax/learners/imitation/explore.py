"""Stage 1 of Algorithm 2: roll pi_theta + N(0, sigma^2) for a whole episode in every env,
keeping each state so SELECT can restore it."""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from envs.base import GoalEnv, State, step_batch
from splid_jax.common.networks import Policy, PolicyState
from splid_jax.common.subgoals import subgoal


class Trajectory(NamedTuple):
    """Time-major batch of episodes: T actions taken from T states, T + 1 achieved goals."""

    states: State  # [T, N, ...] the state each action was taken in
    actions: jax.Array  # [T, N, A] executed (clipped) actions
    achieved: jax.Array  # [T + 1, N, G] achieved goal before and after every step
    invalid: jax.Array  # [T + 1, N] NaN flag of those same states

    def seen(self) -> Seen:
        return Seen(self.states.obs, self.states.success, self.actions, self.achieved, self.invalid)


class Seen(NamedTuple):
    """What learning keeps of a trajectory beyond SELECT: no simulator states, so that devices
    exploring slices of the envs can gather it cheaply."""

    obs: jax.Array  # [T, N, O]
    success: jax.Array  # [T, N]
    actions: jax.Array  # [T, N, A]
    achieved: jax.Array  # [T + 1, N, G]
    invalid: jax.Array  # [T + 1, N]


def draws(env: GoalEnv, key: jax.Array, num_envs: int) -> tuple[jax.Array, jax.Array]:
    """Every env's reset key ([N]) and standard normal exploration noise ([T, N, A]), drawn for the whole batch, so
    that a device holding a slice of the envs rolls them exactly as one device holding all would."""
    k_reset, k_noise = jax.random.split(key)
    noise = jax.vmap(lambda k: jax.random.normal(k, (num_envs, env.action_size)))(
        jax.random.split(k_noise, env.episode_length)
    )
    return jax.random.split(k_reset, num_envs), noise


def hold_fingers(noise: jax.Array, hold: jax.Array) -> jax.Array:
    """``noise`` ([T, N, A]) with its last action's (the fingers') draws held for ``hold`` steps: the
    value drawn at each multiple of ``hold`` repeats until the next, while the arm's stay fresh."""
    t = jnp.arange(noise.shape[0])
    return noise.at[:, :, -1].set(noise[(t // hold) * hold, :, -1])


def rollout(
    env: GoalEnv,
    policy: Policy,
    pstate: PolicyState,
    reset_keys: jax.Array,
    noise: jax.Array,
    sigma: jax.Array,
    reach: jax.Array | float = jnp.inf,
) -> Trajectory:
    """One episode in each of the envs ``reset_keys`` starts, acting ``policy.mean + sigma * noise`` towards
    the goal, or towards its subgoal within ``reach`` of the achieved goal (``common.subgoals``); the
    trajectory keeps the task's goal."""
    start = jax.vmap(env.reset)(reset_keys)

    def one_step(state: State, eps: jax.Array):
        goal = subgoal(state.achieved_goal, state.desired_goal, reach)
        action = jnp.clip(policy.mean(pstate, state.obs, goal) + sigma * eps, -1.0, 1.0)
        nxt = step_batch(env, state, action)
        return nxt, (state, action, nxt.achieved_goal, nxt.invalid)

    _, (states, actions, ag_next, inv_next) = jax.lax.scan(one_step, start, noise)
    achieved = jnp.concatenate([start.achieved_goal[None], ag_next], axis=0)
    invalid = jnp.concatenate([start.invalid[None], inv_next], axis=0)
    return Trajectory(states=states, actions=actions, achieved=achieved, invalid=invalid)
