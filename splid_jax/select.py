"""Stage 2 of Algorithm 2: hindsight relabelling and SELECT by first hit time.

For every explored step t and every h in 1..H the candidate is (s_t, g' = m(s_{t+h}), a_t). SELECT
restores s_t pursuing g' and runs the current deterministic policy for h steps: if the policy
reaches g', the explored actions were no faster and the pair is rejected.

Layout: candidates are [H, T, N] (h-major), flattened. A ``lax.scan`` over h replays all T x N
candidates of one h in one vmapped loop of exactly h steps, so the simulator step appears once in
the compiled program (MJX compile time) and no step is simulated past its own horizon."""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from envs.base import GoalEnv, State
from splid_jax.explore import Trajectory
from splid_jax.networks import Policy, PolicyState


class Candidates(NamedTuple):
    """Flat batch of relabelled pairs; the layout is static, validity lives in masks."""

    obs: jax.Array  # [M, O], M = H * T * N
    goal: jax.Array  # [M, G]
    action: jax.Array  # [M, A]
    valid: jax.Array  # [M] a real candidate: t + h <= T, the goal moved, no NaN, h <= horizon
    accept: jax.Array  # [M] valid, replayed, and not solved by the current policy within h steps
    dropped: jax.Array  # [] int32, valid candidates left undecided because the replay budget was full


def policy_reaches(env: GoalEnv, policy: Policy, pstate: PolicyState, state: State, goal: jax.Array, h):
    """Whether the deterministic policy, restored at ``state``, hits ``goal`` within ``h`` steps
    (``h`` may be traced: the loop runs exactly h steps)."""

    def one_step(_, carry):
        s, hit = carry
        s = env.step(s, policy.act(pstate, s.obs, s.desired_goal))
        return s, hit | (s.success & ~s.invalid)

    _, hit = jax.lax.fori_loop(0, h, one_step, (env.with_goal(state, goal), jnp.bool_(False)))
    return hit


def num_candidates(episode_length: int, max_horizon: int, num_envs: int) -> int:
    return max_horizon * episode_length * num_envs


def replay_slots(episode_length: int, num_envs: int, budget: float) -> int:
    """Candidates replayed per h: all T x N starts, or the ``budget`` fraction of them."""
    return max(1, min(episode_length * num_envs, int(round(budget * episode_length * num_envs))))


def replay_steps(episode_length: int, horizon: int, num_envs: int, budget: float = 1.0) -> int:
    """Simulator steps SELECT takes per iteration: h steps for each replayed slot, per h."""
    return replay_slots(episode_length, num_envs, budget) * horizon * (horizon + 1) // 2


def select(
    env: GoalEnv,
    policy: Policy,
    pstate: PolicyState,
    traj: Trajectory,
    max_horizon: int,
    horizon: jax.Array,
    use_select: bool,
    key: jax.Array | None = None,
    budget: float = 1.0,
) -> Candidates:
    """``max_horizon`` fixes the shapes; ``horizon`` (traced, <= max_horizon) masks and skips
    the replays of larger h, so runs with different H share one compiled program.
    ``use_select=False`` is the ablation: every valid pair is stored, nothing is replayed.

    ``budget`` < 1 replays, per h, only that fraction of the T x N slots, filled with valid
    candidates chosen uniformly at random (``key``): most candidates of object tasks are invalid
    (the object did not move), and replaying them is wasted work. Valid candidates beyond the
    budget are left undecided (not stored) and counted in ``dropped``."""
    T, H = env.episode_length, max_horizon
    n = traj.actions.shape[1]
    hs = jnp.arange(1, H + 1)
    t = jnp.arange(T)
    later = jnp.minimum(t[None, :] + hs[:, None], T)  # [H, T] index of s_{t+h}, clamped
    goal = traj.achieved[later]  # [H, T, N, G]
    valid = (
        (t[None, :] + hs[:, None] <= T)[..., None]
        & ~env.success(traj.achieved[:T][None], goal)  # nothing achieved between t and t + h
        & ~traj.invalid[:T][None]
        & ~traj.invalid[later]
        & (hs <= horizon)[:, None, None]
    ).reshape(-1)
    goal = goal.reshape(H, T * n, -1)
    dropped = jnp.int32(0)
    if use_select:
        starts = jax.tree_util.tree_map(lambda x: x.reshape((T * n,) + x.shape[2:]), traj.states)
        replay = jax.vmap(lambda s, g, h: policy_reaches(env, policy, pstate, s, g, h), in_axes=(0, 0, None))
        valid_h = valid.reshape(H, T * n)
        slots = replay_slots(T, n, budget)
        if slots < T * n:
            key = jax.random.PRNGKey(0) if key is None else key
            # a random priority among valid candidates; invalid ones sort last
            score = jax.random.uniform(key, valid_h.shape) + valid_h.astype(jnp.float32)
            chosen = jax.lax.top_k(score, slots)[1]  # [H, slots]
            decided = jnp.zeros_like(valid_h).at[jnp.arange(H)[:, None], chosen].set(True) & valid_h
            dropped = jnp.sum(valid_h & ~decided, dtype=jnp.int32)
        else:
            chosen = jnp.broadcast_to(jnp.arange(T * n), (H, T * n))
            decided = valid_h

        def per_h(_, xs):
            h, goal_h, idx = xs
            picked = jax.tree_util.tree_map(lambda x: x[idx], starts)
            hit = replay(picked, goal_h[idx], jnp.where(h <= horizon, h, 0))
            return None, jnp.zeros(T * n, bool).at[idx].set(hit)

        _, reached = jax.lax.scan(per_h, None, (hs, goal, chosen))
        accept = (decided & ~reached).reshape(-1)
    else:
        accept = valid
    tile = lambda x: jnp.broadcast_to(x[None], (H,) + x.shape).reshape((H * T * n,) + x.shape[2:])  # noqa: E731
    return Candidates(tile(traj.states.obs), goal.reshape(H * T * n, -1), tile(traj.actions), valid, accept, dropped)
