"""Point2D-FourRooms (the paper's appendix E): a point in [-5, 5]^2 moved by displacements,
four rooms joined by doorways. Pure JAX, microseconds a step: the CPU CI task."""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from envs.base import GoalEnv, State, flag_invalid
from envs.settings import check

BOUND = 5.0


def wall_boxes(half_width: float, door_centre: float, door_half: float) -> np.ndarray:
    """Axis-aligned wall rectangles [xmin, xmax, ymin, ymax]: a cross through the origin with
    one doorway in each of its four arms."""
    w, lo, hi = half_width, door_centre - door_half, door_centre + door_half
    vertical = [(-w, w, -BOUND, -hi), (-w, w, -lo, lo), (-w, w, hi, BOUND)]
    horizontal = [(-BOUND, -hi, -w, w), (-lo, -w, -w, w), (w, lo, -w, w), (hi, BOUND, -w, w)]
    return np.asarray(vertical + horizontal, np.float32)


def _move_axis(pos: jax.Array, delta: jax.Array, boxes: jax.Array, axis: int) -> jax.Array:
    """Move ``pos`` by ``delta`` along ``axis``, stopping at the first wall face it would cross."""
    other = 1 - axis
    lo, hi = boxes[:, 2 * axis], boxes[:, 2 * axis + 1]
    olo, ohi = boxes[:, 2 * other], boxes[:, 2 * other + 1]
    start = pos[axis]
    target = start + delta
    in_band = (pos[other] >= olo) & (pos[other] <= ohi)
    # Moving up: blocked by boxes whose low face lies in (start, target]; down: mirror image.
    up_block = jnp.where(in_band & (lo >= start) & (lo <= target), lo, jnp.inf)
    down_block = jnp.where(in_band & (hi <= start) & (hi >= target), hi, -jnp.inf)
    new = jnp.where(delta >= 0, jnp.minimum(target, jnp.min(up_block)), jnp.maximum(target, jnp.max(down_block)))
    new = jnp.clip(new, -BOUND, BOUND)
    return pos.at[axis].set(new)


@dataclasses.dataclass(frozen=True)
class PointFourRooms(GoalEnv):
    """A point that reaches goals across four rooms; success when the distance is <= radius."""

    max_episode_steps: int = 50
    success_radius: float = 1.0  # the paper's epsilon on the squared distance, here 1
    wall_half_width: float = 0.25
    door_centre: float = 2.5  # distance of each doorway's centre from the origin
    door_half_width: float = 0.75

    def __post_init__(self):
        check(self.max_episode_steps >= 2, "point.max_episode_steps", self.max_episode_steps, "an integer >= 2")
        check(self.success_radius > 0, "point.success_radius", self.success_radius, "> 0")
        check(0 < self.wall_half_width < 1, "point.wall_half_width", self.wall_half_width, "in (0, 1)")
        check(
            0 < self.door_half_width < self.door_centre - self.wall_half_width,
            "point.door_half_width",
            self.door_half_width,
            f"in (0, door_centre - wall_half_width = {self.door_centre - self.wall_half_width})",
        )
        check(
            self.door_centre + self.door_half_width < BOUND,
            "point.door_centre",
            self.door_centre,
            "with the door inside [-5, 5]",
        )

    obs_size = property(lambda self: 2)
    goal_size = property(lambda self: 2)
    achieved_goal_start = property(lambda self: 0)
    success_distance = property(lambda self: self.success_radius)
    action_size = property(lambda self: 2)
    episode_length = property(lambda self: self.max_episode_steps)

    @property
    def boxes(self) -> jax.Array:
        return jnp.asarray(wall_boxes(self.wall_half_width, self.door_centre, self.door_half_width))

    def in_wall(self, pos: jax.Array) -> jax.Array:
        b = self.boxes
        inside = (pos[..., None, 0] > b[:, 0]) & (pos[..., None, 0] < b[:, 1])
        inside &= (pos[..., None, 1] > b[:, 2]) & (pos[..., None, 1] < b[:, 3])
        return jnp.any(inside, axis=-1)

    def _free_point(self, key: jax.Array) -> jax.Array:
        """A uniform point outside the walls (16 tries cover all but ~1e-16 of the mass)."""
        cands = jax.random.uniform(key, (16, 2), minval=-BOUND, maxval=BOUND)
        return cands[jnp.argmin(self.in_wall(cands))]

    def _state(self, pos, goal, step, invalid) -> State:
        ok = self.success(pos, goal)
        return State(
            physics=pos,
            obs=pos,
            achieved_goal=pos,
            desired_goal=goal,
            reward=ok.astype(jnp.float32),
            success=ok,
            step=step,
            invalid=invalid,
        )

    def reset(self, key: jax.Array) -> State:
        k_start, k_goal = jax.random.split(key)
        pos, goal = self._free_point(k_start), self._free_point(k_goal)
        return self._state(pos, goal, jnp.int32(0), jnp.bool_(False))

    def step(self, state: State, action: jax.Array) -> State:
        action = jnp.clip(action, -1.0, 1.0)
        pos = _move_axis(state.physics, action[0], self.boxes, 0)
        pos = _move_axis(pos, action[1], self.boxes, 1)
        out = self._state(pos, state.desired_goal, state.step + 1, state.invalid)
        return flag_invalid(out)

    def with_goal(self, state: State, goal: jax.Array) -> State:
        return self._state(state.physics, goal, state.step, state.invalid)

    def success(self, achieved: jax.Array, desired: jax.Array) -> jax.Array:
        return jnp.sum((achieved - desired) ** 2, axis=-1) <= self.success_radius**2

    def reward_of(self, achieved: jax.Array, desired: jax.Array) -> jax.Array:
        """The paper's convention for this task: 1 on the goal, else 0."""
        return self.success(achieved, desired).astype(jnp.float32)
