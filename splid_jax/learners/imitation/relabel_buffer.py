"""A functional FIFO ring buffer of (observation, relabelled goal, action) triples.

Insertion takes a fixed-size batch plus a mask, so the shapes stay static under jit however many
pairs SELECT accepted."""

from __future__ import annotations

from typing import NamedTuple

import chex
import jax
import jax.numpy as jnp
from flax import struct

from splid_jax.common import ring_buffer


@struct.dataclass
class Buffer:
    obs: jax.Array  # [C, O]
    goal: jax.Array  # [C, G]
    action: jax.Array  # [C, A]
    ptr: jax.Array  # [] int32, next slot to write
    size: jax.Array  # [] int32, filled slots

    @property
    def capacity(self) -> int:
        return self.obs.shape[0]


def init(capacity: int, obs_size: int, goal_size: int, action_size: int) -> Buffer:
    return Buffer(
        obs=jnp.zeros((capacity, obs_size), jnp.float32),
        goal=jnp.zeros((capacity, goal_size), jnp.float32),
        action=jnp.zeros((capacity, action_size), jnp.float32),
        ptr=jnp.int32(0),
        size=jnp.int32(0),
    )


def insert(buf: Buffer, obs: jax.Array, goal: jax.Array, action: jax.Array, mask: jax.Array) -> Buffer:
    """Append the rows where ``mask`` holds, in order; past capacity the oldest are overwritten.
    If one batch holds more than the capacity, only its newest ``capacity`` rows are kept."""
    chex.assert_rank([obs, goal, action, mask], [2, 2, 2, 1])  # at trace time: a wrong layout fails here
    chex.assert_equal_shape_prefix([obs, goal, action, mask], 1)
    chex.assert_equal_shape_suffix([obs, buf.obs], 1)
    chex.assert_equal_shape_suffix([goal, buf.goal], 1)
    chex.assert_equal_shape_suffix([action, buf.action], 1)
    return ring_buffer.insert(buf, {"obs": obs, "goal": goal, "action": action}, mask)


def filled(buf: Buffer) -> jax.Array:
    """[C] bool: the slots that hold a pair."""
    return jnp.arange(buf.capacity) < buf.size


class Held(NamedTuple):
    """The held-goal pairs in the cloning window as a list of slots, made once per epoch of BC steps."""

    slots: jax.Array  # [C] int32, the held pairs' slots first
    count: jax.Array  # [] int32, how many of ``slots`` are held pairs


def held_slots(buf: Buffer, window: jax.Array | int | None = None) -> Held:
    """The slots of the newest ``window`` pairs (all with None) whose action is zero: the held goals of
    ``--relabel stop``, which labels them so; an explored action is never exactly zero."""
    age = (buf.ptr - 1 - jnp.arange(buf.capacity)) % buf.capacity  # 0: the last written
    inside = filled(buf) if window is None else filled(buf) & (age < window)
    held = inside & jnp.all(buf.action == 0, axis=-1)
    slots = jnp.nonzero(held, size=buf.capacity, fill_value=0)[0].astype(jnp.int32)
    return Held(slots, jnp.sum(held, dtype=jnp.int32))


def sample(
    buf: Buffer,
    key: jax.Array,
    batch_size: int,
    window: jax.Array | int | None = None,
    held: Held | None = None,
    held_share: jax.Array | float = 0.0,
) -> tuple[jax.Array, jax.Array, jax.Array]:
    """Uniform over filled slots (with replacement). An empty buffer yields row 0 of zeros:
    callers weight the loss by ``size > 0``. With ``window``, uniform over the newest ``window`` pairs, as a
    FIFO buffer of that capacity holds them; while they are all the pairs, the draw is the whole buffer's.
    With ``held``, each row comes from the held pairs instead with probability ``held_share`` (while there are
    any); the uniform draw uses ``key`` alone, so at share 0 the batch is the uniform one exactly."""
    if window is None:
        idx = jax.random.randint(key, (batch_size,), 0, jnp.maximum(buf.size, 1))
    else:
        drawn = jax.random.randint(key, (batch_size,), 0, jnp.maximum(jnp.minimum(buf.size, window), 1))
        idx = jnp.where(buf.size <= window, drawn, (buf.ptr - 1 - drawn) % buf.capacity)
    if held is not None:
        k_pick, k_which = jax.random.split(jax.random.fold_in(key, 1))
        which = held.slots[jax.random.randint(k_which, (batch_size,), 0, jnp.maximum(held.count, 1))]
        use = (jax.random.uniform(k_pick, (batch_size,)) < held_share) & (held.count > 0)
        idx = jnp.where(use, which, idx)
    return buf.obs[idx], buf.goal[idx], buf.action[idx]
