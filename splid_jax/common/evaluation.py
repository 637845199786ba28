"""Evaluation with the deterministic policy: success at any step (SPLID's convention), at the
final step (HER's), and the mean return."""

from __future__ import annotations

import jax
import jax.numpy as jnp

from envs.base import GoalEnv, State, step_batch
from splid_jax.common.networks import Policy, PolicyState


def evaluate(env: GoalEnv, policy: Policy, pstate: PolicyState, key: jax.Array, num_episodes: int) -> dict:
    """From the task's standard starts, whatever training-only starts ``env`` explores from."""
    env = env.evaluation_task()
    start = jax.vmap(env.reset)(jax.random.split(key, num_episodes))

    def one_step(state: State, _):
        nxt = step_batch(env, state, policy.act(pstate, state.obs, state.desired_goal))
        return nxt, (nxt.success & ~nxt.invalid, nxt.reward)

    final, (succ, rew) = jax.lax.scan(one_step, start, None, length=env.episode_length)
    return {
        "eval_success": jnp.mean(jnp.any(succ, axis=0)),
        "eval_success_final": jnp.mean(succ[-1]),
        "eval_return": jnp.mean(jnp.sum(rew, axis=0)),
        "eval_invalid": jnp.mean(final.invalid),
    }
