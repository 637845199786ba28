"""HER's replay: whole episodes in a FIFO ring, and the relabelling that samples transitions from them
with hindsight goals (Baselines' "future", mrl's "futureactual")."""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
from flax import struct

from splid_jax.common import ring_buffer


@struct.dataclass
class EpisodeBuffer:
    """Whole episodes in a FIFO ring, so a transition's future achieved goals stay reachable."""

    obs: jax.Array  # [E, T + 1, O]
    achieved: jax.Array  # [E, T + 1, G]
    goal: jax.Array  # [E, G]
    actions: jax.Array  # [E, T, A] executed actions
    ptr: jax.Array  # [] int32, next episode slot to write
    size: jax.Array  # [] int32, filled slots

    @property
    def capacity(self) -> int:
        return self.obs.shape[0]


def buffer_init(episodes: int, T: int, obs_size: int, goal_size: int, action_size: int) -> EpisodeBuffer:
    return EpisodeBuffer(
        obs=jnp.zeros((episodes, T + 1, obs_size), jnp.float32),
        achieved=jnp.zeros((episodes, T + 1, goal_size), jnp.float32),
        goal=jnp.zeros((episodes, goal_size), jnp.float32),
        actions=jnp.zeros((episodes, T, action_size), jnp.float32),
        ptr=jnp.int32(0),
        size=jnp.int32(0),
    )


def buffer_insert(buf: EpisodeBuffer, new: EpisodeBuffer, mask: jax.Array) -> EpisodeBuffer:
    """Append the episodes of ``new`` where ``mask`` holds, in order, overwriting the oldest past
    capacity (of a batch larger than the capacity only the newest ``capacity`` are kept)."""
    rows = {"obs": new.obs, "achieved": new.achieved, "goal": new.goal, "actions": new.actions}
    return ring_buffer.insert(buf, rows, mask)


class Transitions(NamedTuple):
    obs: jax.Array  # [B, O]
    goal: jax.Array  # [B, G] the episode's own goal, a later achieved goal, or another episode's goal
    action: jax.Array  # [B, A]
    next_obs: jax.Array  # [B, O]
    reward: jax.Array  # [B] the task's reward of the next achieved goal for that goal
    episode: jax.Array  # [B] int32, the slot sampled
    t: jax.Array  # [B] int32, the step sampled
    future: jax.Array  # [B] int32 in [t + 1, T], where a relabelled goal was achieved
    relabelled: jax.Array  # [B] bool, the goal is the achieved goal at ``future``
    actual: jax.Array  # [B] bool, the goal is the desired goal of the stored episode ``other``
    other: jax.Array  # [B] int32, a uniform filled slot


def sample_transitions(
    buf: EpisodeBuffer,
    key: jax.Array,
    batch_size: int,
    future_p: float,
    reward_of,
    actual_p: float = 0.0,
    actual_on: jax.Array | bool = True,
) -> Transitions:
    """A uniform episode and step, and its goal relabelled: with probability ``future_p`` the achieved goal
    of a uniform later step of the same episode (Baselines' and mrl's "future"), with probability ``actual_p``
    the desired goal of a uniform stored episode (mrl's "actual"), else the episode's own goal. With "actual" goals
    configured, while ``actual_on`` is False every goal is a future one, as in mrl's first ``future_warm_up`` steps.
    The reward is recomputed. An empty buffer yields slot 0 (callers weight the loss by ``size > 0``)."""
    T = buf.actions.shape[1]
    k_ep, k_t, k_future, k_relabel = jax.random.split(key, 4)
    filled = jnp.maximum(buf.size, 1)
    ep = jax.random.randint(k_ep, (batch_size,), 0, filled)
    t = jax.random.randint(k_t, (batch_size,), 0, T)
    future = jax.random.randint(k_future, (batch_size,), t + 1, T + 1)
    # drawn only where "actual" goals can occur, so the future strategy alone draws what it always drew
    other = jax.random.randint(jax.random.fold_in(key, 1), (batch_size,), 0, filled) if actual_p else ep
    u = jax.random.uniform(k_relabel, (batch_size,))
    mixed = u < future_p + actual_p
    actual = mixed & (u >= future_p) & actual_on
    warming = ~jnp.asarray(actual_on) if actual_p else jnp.bool_(False)  # mrl: the whole batch future until then
    relabelled = (mixed & ~actual) | warming
    goal = jnp.where(relabelled[:, None], buf.achieved[ep, future], buf.goal[ep])
    goal = jnp.where(actual[:, None], buf.goal[other], goal)
    return Transitions(
        obs=buf.obs[ep, t],
        goal=goal,
        action=buf.actions[ep, t],
        next_obs=buf.obs[ep, t + 1],
        reward=reward_of(buf.achieved[ep, t + 1], goal),
        episode=ep,
        t=t,
        future=future,
        relabelled=relabelled,
        actual=actual,
        other=other,
    )
