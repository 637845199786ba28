"""What a relabelling step hands to the relabel buffer: pairs of (observation, hindsight goal, action)
in a static layout with masks, whether SELECT judged them (SPLID, PCHID) or every one is kept (GCSL)."""

from __future__ import annotations

from typing import NamedTuple

import jax


class Candidates(NamedTuple):
    """Flat batch of relabelled pairs; the layout is static, validity lives in masks."""

    obs: jax.Array  # [M, O], M = H * T * N, layout [H, T, N]
    goal: jax.Array  # [M, G]
    action: jax.Array  # [M, A]
    valid: jax.Array  # [M] a real candidate: t + h <= T, the goal moved (or is held), no NaN, h <= horizon
    accept: jax.Array  # [M] valid and not solved by the current policy within h steps
    held: jax.Array  # [M] valid candidates whose goal was already achieved at s_t (verdict at the final step)
    replay_steps: jax.Array  # [] int32, simulator control steps the replays took
