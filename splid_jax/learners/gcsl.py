"""GCSL's relabelling (Ghosh et al.): every explored (s_t, a_t) is paired with a goal the same
episode achieved later, and every pair is cloned: no SELECT, no critic.

``final`` pairs every step with the episode's last achieved goal, as the SPLID paper describes
GCSL; ``future`` draws the later step uniformly from t + 1..T, as GCSL's own paper does."""

from __future__ import annotations

import jax
import jax.numpy as jnp

from envs.base import GoalEnv
from splid_jax.learners.imitation.candidates import Candidates
from splid_jax.learners.imitation.explore import Seen

RELABELS = ("final", "future")


def relabel(env: GoalEnv, traj: Seen, mode: str, key: jax.Array) -> Candidates:
    """One candidate per explored step, layout [T, N]; every valid one is accepted."""
    T, n = env.episode_length, traj.actions.shape[1]
    t = jnp.arange(T)[:, None]
    if mode == "final":
        later = jnp.full((T, n), T)
    elif mode == "future":
        later = jax.random.randint(key, (T, n), t + 1, T + 1)
    else:
        raise ValueError(f"mode must be one of {RELABELS}, got {mode!r}")
    cols = jnp.arange(n)[None, :]
    goal = traj.achieved[later, cols]  # [T, N, G]
    valid = ~traj.invalid[:T] & ~traj.invalid[later, cols]
    flat = lambda x: x.reshape((T * n,) + x.shape[2:])  # noqa: E731
    valid = flat(valid)
    return Candidates(
        flat(traj.obs), flat(goal), flat(traj.actions), valid, valid, jnp.zeros_like(valid), jnp.int32(0)
    )
