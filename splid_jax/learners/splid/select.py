"""Stage 2 of Algorithm 2: hindsight relabelling and SELECT by first hit time.

For every explored step t and every h in 1..H the candidate is (s_t, g' = m(s_{t+h}), a_t). SELECT
restores s_t pursuing g' and runs the current deterministic policy for up to h steps: if the policy
reaches g', the explored actions were no faster and the pair is rejected. Which candidates an explored
step gives, and their action labels, is the relabelling's (``relabel``).

Most candidates need no replay (the object did not move: the policy "reaches" g' in zero steps), and
a replay ends as soon as the policy hits g'. So SELECT runs as a work queue: a fixed number of
vmapped replay lanes, each taking the next valid candidate from the queue as soon as its current one
is decided, in one ``lax.while_loop`` that ends when the queue is empty. Every valid candidate is
decided, no lane steps past its verdict, and the simulator step appears once in the compiled
program (MJX compile time)."""

from __future__ import annotations

from typing import NamedTuple

import chex
import jax
import jax.numpy as jnp

from envs.base import GoalEnv, State, step_batch
from splid_jax.common import ticks
from splid_jax.common.networks import Policy, PolicyState
from splid_jax.learners.imitation.candidates import Candidates
from splid_jax.learners.imitation.explore import Trajectory
from splid_jax.learners.splid.relabel import STRATEGIES, hindsight


def num_candidates(episode_length: int, max_horizon: int, num_envs: int) -> int:
    """H rows of hindsight goals x T x N."""
    return max_horizon * episode_length * num_envs


def num_lanes(episode_length: int, num_envs: int, lanes: float, max_horizon: int) -> int:
    """Parallel replay lanes: ``lanes`` times the T x N explored steps, at most one per candidate. Above 1
    the candidates of one explored step replay side by side, in fewer rounds of the queue: a GPU steps a
    wider batch in little more time, until the batch fills it (experiments/NOTES.md, "SELECT's lanes above
    one per explored step")."""
    steps = episode_length * num_envs
    return max(1, min(max_horizon * steps, int(round(lanes * steps))))


class _Queue(NamedTuple):
    state: State  # [L] the lanes' simulator states
    cand: jax.Array  # [L] int32, the candidate each lane decides
    steps: jax.Array  # [L] int32, steps taken on it
    active: jax.Array  # [L] bool
    next: jax.Array  # [] int32, queue position of the next candidate to hand out
    reached: jax.Array  # [M + 1] bool, verdicts; the last slot absorbs writes of idle lanes
    replay_steps: jax.Array  # [] int32


def replay_queue(
    env: GoalEnv,
    policy: Policy,
    pstate: PolicyState,
    starts: State,
    goals: jax.Array,
    start_of: jax.Array,
    horizon_of: jax.Array,
    valid: jax.Array,
    lanes: int,
    at_final: jax.Array | None = None,
) -> tuple[jax.Array, jax.Array]:
    """For every valid candidate c: does the policy, restored at ``starts[start_of[c]]`` pursuing
    ``goals[c]``, hit it within ``horizon_of[c]`` steps (where ``at_final[c]``: is it at the goal
    after exactly that many)? Returns (reached [M], replay steps [])."""
    m = valid.shape[0]
    at_final = jnp.zeros(m, bool) if at_final is None else at_final
    # longest replays first: the lanes that finish last are then the short ones
    order = jnp.argsort(jnp.where(valid, -horizon_of, 1), stable=True).astype(jnp.int32)
    count = jnp.sum(valid, dtype=jnp.int32)
    lane = jnp.arange(lanes, dtype=jnp.int32)

    def restore(cand):  # [L] candidates -> their start states, pursuing their goals
        return jax.vmap(env.with_goal)(jax.tree_util.tree_map(lambda x: x[start_of[cand]], starts), goals[cand])

    def load(state, cand, take):
        pick = lambda new, old: jnp.where(take.reshape(take.shape + (1,) * (new.ndim - 1)), new, old)  # noqa: E731
        return jax.tree_util.tree_map(pick, restore(cand), state)

    first = order[jnp.minimum(lane, m - 1)]
    active = lane < count
    q = _Queue(
        restore(first),
        first,
        jnp.zeros(lanes, jnp.int32),
        active,
        jnp.minimum(count, lanes),
        jnp.zeros(m + 1, bool),
        jnp.int32(0),
    )

    def one_round(q: _Queue) -> _Queue:
        s = step_batch(env, q.state, policy.act(pstate, q.state.obs, q.state.desired_goal))
        steps = q.steps + 1
        hit = env.success(s.achieved_goal, s.desired_goal) & ~s.invalid
        done = q.active & ((hit & ~at_final[q.cand]) | (steps >= horizon_of[q.cand]))
        reached = q.reached.at[jnp.where(done, q.cand, m)].set(hit)
        # finished lanes take the next candidates in queue order
        pos = q.next + jnp.cumsum(done, dtype=jnp.int32) - 1
        take = done & (pos < count)
        cand = jnp.where(take, order[jnp.clip(pos, 0, m - 1)], q.cand)
        return _Queue(
            state=load(s, cand, take),
            cand=cand,
            steps=jnp.where(done, 0, steps),
            active=jnp.where(done, take, q.active),
            next=jnp.minimum(q.next + jnp.sum(done, dtype=jnp.int32), count),
            reached=reached,
            replay_steps=q.replay_steps + jnp.sum(q.active, dtype=jnp.int32),
        )

    def body(q: _Queue) -> _Queue:
        q = one_round(q)
        ticks.tick(ticks.ROUND, lambda: count - q.next + jnp.sum(q.active, dtype=jnp.int32))  # verdicts left
        return q

    q = jax.lax.while_loop(lambda q: jnp.any(q.active), body, q)
    return q.reached[:m], q.replay_steps


def select(
    env: GoalEnv,
    policy: Policy,
    pstate: PolicyState,
    traj: Trajectory,
    max_horizon: int,
    horizon: jax.Array,
    use_select: bool = True,
    lanes: float = 1.0,
    relabel: str = "paper",
) -> Candidates:
    """Algorithm 2, lines 12-19, for every explored episode at once. ``max_horizon`` fixes the shapes;
    ``horizon`` (traced, <= max_horizon) masks larger h, so runs of different H share one program.
    ``use_select=False`` stores every candidate (the ablation). ``lanes``: the replay batch, times the
    T x N explored steps (speed, never a verdict). ``relabel`` names the strategy (``relabel.STRATEGIES``)."""
    strategy, (T, H, n) = STRATEGIES[relabel], (env.episode_length, max_horizon, traj.actions.shape[1])
    hs = hindsight(env, traj, H)  # lines 12-14: for t = 1..T, h = 1..H: g' = m(s_{t+h})
    moved, held = strategy.candidates(hs, horizon)  # paper: every g' the object moved to, h <= H
    valid, held, goal = (moved | held).reshape(-1), held.reshape(-1), hs.goal.reshape(H * T * n, -1)
    reached, steps = jnp.zeros_like(valid), jnp.int32(0)
    if use_select:  # line 15: SELECT(s_t, g'): does the policy, restored at s_t, reach g' within h steps?
        starts = jax.tree_util.tree_map(lambda x: x.reshape((T * n,) + x.shape[2:]), traj.states)
        flat = jnp.arange(H * T * n, dtype=jnp.int32)
        start_of, h_of, lanes = flat % (T * n), flat // (T * n) + 1, num_lanes(T, n, lanes, H)
        at_final = valid if strategy.on_time else held
        reached, steps = replay_queue(env, policy, pstate, starts, goal, start_of, h_of, valid, lanes, at_final)
    tile = lambda x: jnp.broadcast_to(x[None], (H,) + x.shape).reshape((H * T * n,) + x.shape[2:])  # noqa: E731
    action = strategy.label(tile(traj.actions), held)  # line 16: store (s_t, g', a_t) where the policy did not
    out = Candidates(tile(traj.states.obs), goal, action, valid, valid & ~reached, held, steps)
    chex.assert_shape([out.valid, out.accept, out.held], (num_candidates(T, H, n),))
    return out
