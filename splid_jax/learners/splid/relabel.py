"""The hindsight relabellings that SELECT judges (``--relabel``): which (s_t, g', a) candidates an
explored step gives, and the action each is labelled with.

- ``paper``: Algorithm 2's. For every t and h in 1..H, g' = m(s_{t+h}), where g' is not already
  achieved at s_t (nothing to learn where the object did not move).
- ``hold``: also the held goals, one per explored step at h = H: g' already achieved at s_t and still
  achieved H steps later. Their verdict is taken at the final step: the pair is kept only if the policy,
  restored at s_t, is NOT at g' after H steps. Without them the buffer never holds a state whose goal is
  achieved, so the policy is never shown what to do there and pushes through the goal.
- ``stop``: ``hold`` with the held pairs labelled with the zero action: on the Fetch tasks the gripper
  holds where it is, so at a goal already reached the policy is taught to stand still rather than to
  copy exploration noise that happened not to disturb the object.
- ``exact``: ``hold``'s candidates with every verdict taken at exactly h steps: a moved goal counts as reached
  only if the policy, restored at s_t, is at g' after h steps, not on its way past. The first-hit verdict keeps
  an explored action only where it got to g' sooner than the policy, so where the object slides on (Slide's
  puck) it favours the hardest hits; at exactly h a gentler push that stops nearer g' is kept too."""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import jax
import jax.numpy as jnp

from envs.base import GoalEnv
from splid_jax.learners.imitation.explore import Trajectory


class Hindsight(NamedTuple):
    """Every explored step's hindsight goals, in layout [H, T, N]."""

    goal: jax.Array  # [H, T, N, G] g' = m(s_{t+h})
    real: jax.Array  # [H, T, N] bool: t + h within the episode, neither s_t nor s_{t+h} invalid
    achieved: jax.Array  # [H, T, N] bool: g' already achieved at s_t
    h: jax.Array  # [H] 1..H


def hindsight(env: GoalEnv, traj: Trajectory, max_horizon: int) -> Hindsight:
    """g' = m(s_{t+h}) for every explored t and every h in 1..``max_horizon``."""
    T = env.episode_length
    h, t = jnp.arange(1, max_horizon + 1), jnp.arange(T)
    later = jnp.minimum(t[None, :] + h[:, None], T)  # [H, T] index of s_{t+h}, clamped
    goal = traj.achieved[later]
    real = (t[None, :] + h[:, None] <= T)[..., None] & ~traj.invalid[:T][None] & ~traj.invalid[later]
    return Hindsight(goal, real, env.success(traj.achieved[:T][None], goal), h)


def moved(hs: Hindsight, horizon: jax.Array) -> jax.Array:
    """[H, T, N] Algorithm 2's candidates: h <= H and g' not already achieved at s_t."""
    return hs.real & ~hs.achieved & (hs.h <= horizon)[:, None, None]


def held(hs: Hindsight, horizon: jax.Array) -> jax.Array:
    """[H, T, N] the held-goal candidates: g' achieved at s_t, judged H steps on."""
    return hs.real & hs.achieved & (hs.h == horizon)[:, None, None]


class Strategy(NamedTuple):
    """A relabelling: its candidates (moved, held), whether the held ones are labelled with the zero action, and
    whether every verdict, not only the held goals', is taken at exactly h steps."""

    candidates: Callable[[Hindsight, jax.Array], tuple[jax.Array, jax.Array]]
    stands_still: bool = False
    on_time: bool = False

    def label(self, actions: jax.Array, held: jax.Array) -> jax.Array:
        """[M, A] the action each candidate is cloned with: the explored one, or zero on held goals."""
        if not self.stands_still:
            return actions
        return jnp.where(held[:, None], jnp.zeros_like(actions), actions)


def _paper(hs: Hindsight, horizon: jax.Array) -> tuple[jax.Array, jax.Array]:
    return moved(hs, horizon), jnp.zeros_like(hs.real)


def _hold(hs: Hindsight, horizon: jax.Array) -> tuple[jax.Array, jax.Array]:
    return moved(hs, horizon), held(hs, horizon)


STRATEGIES = {
    "paper": Strategy(_paper),
    "hold": Strategy(_hold),
    "stop": Strategy(_hold, stands_still=True),
    "exact": Strategy(_hold, on_time=True),
}
NAMES = tuple(STRATEGIES)
HOLDING = tuple(name for name, s in STRATEGIES.items() if s.candidates is _hold)  # add held-goal candidates
