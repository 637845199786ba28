"""Stage 2 of Algorithm 2: hindsight relabelling and SELECT by first hit time.

For every explored step t and every h in 1..H the candidate is (s_t, g' = m(s_{t+h}), a_t). SELECT
restores s_t pursuing g' and runs the current deterministic policy for up to h steps: if the policy
reaches g', the explored actions were no faster and the pair is rejected.

Most candidates need no replay (the object did not move: the policy "reaches" g' in zero steps), and
a replay ends as soon as the policy hits g'. So SELECT runs as a work queue: a fixed number of
vmapped replay lanes, each taking the next valid candidate from the queue as soon as its current one
is decided, in one ``lax.while_loop`` that ends when the queue is empty. Every valid candidate is
decided, no lane steps past its verdict, and the simulator step appears once in the compiled
program (MJX compile time).

``hold=True`` adds the candidates Algorithm 2 leaves out: those whose goal is already achieved at
s_t and still achieved H steps later (the explored actions kept the object there). Their verdict is
taken at the final step: the pair is kept only if the policy, restored at s_t, is NOT at g' after H
steps. Without them the buffer never holds a state whose goal is achieved, so the policy is never
shown what to do there and pushes through the goal.

``stop=True`` labels those held pairs with the zero action instead of the explored one: on the Fetch
tasks it holds the gripper where it is (the target is the current grip position, the fingers keep
their opening), so at a goal already reached the policy is taught to stand still rather than to copy
exploration noise that happened not to disturb the object."""

from __future__ import annotations

from typing import NamedTuple

import chex
import jax
import jax.numpy as jnp

from envs.base import GoalEnv, State, step_batch
from splid_jax.common.networks import Policy, PolicyState
from splid_jax.learners.imitation.candidates import Candidates
from splid_jax.learners.imitation.explore import Trajectory


def num_candidates(episode_length: int, max_horizon: int, num_envs: int) -> int:
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


def within(env: GoalEnv, achieved: jax.Array, goal: jax.Array, radius: float = 1.0) -> jax.Array:
    """The task's success test with its threshold scaled by ``radius`` (tasks whose success is a
    distance threshold): 1 is the task's own; below 1 SELECT asks for the object nearer the goal."""
    if radius == 1.0:
        return env.success(achieved, goal)
    return env.success(goal + (achieved - goal) / radius, goal)


def held_pairs(env: GoalEnv, obs: jax.Array, goal: jax.Array, radius: float = 1.0) -> jax.Array:
    """Which stored (observation, goal) pairs are held-goal ones: the goal already achieved at the
    observation, the test that sets SELECT's held candidates apart from its moved ones."""
    start = env.achieved_goal_start
    return within(env, obs[..., start : start + env.goal_size], goal, radius)


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
    radius: float = 1.0,
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

    def body(q: _Queue) -> _Queue:
        s = step_batch(env, q.state, policy.act(pstate, q.state.obs, q.state.desired_goal))
        steps = q.steps + 1
        hit = within(env, s.achieved_goal, s.desired_goal, radius) & ~s.invalid
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

    q = jax.lax.while_loop(lambda q: jnp.any(q.active), body, q)
    return q.reached[:m], q.replay_steps


def select(
    env: GoalEnv,
    policy: Policy,
    pstate: PolicyState,
    traj: Trajectory,
    max_horizon: int,
    horizon: jax.Array,
    use_select: bool,
    lanes: float = 1.0,
    hold: bool = False,
    settle: bool = False,
    radius: float = 1.0,
    stop: bool = False,
    hold_horizon: int = 0,
    rest: bool = False,
    rest_horizon: int = 0,
) -> Candidates:
    """``max_horizon`` fixes the shapes; ``horizon`` (traced, <= max_horizon) masks the candidates
    of larger h, so runs with different H share one compiled program. ``use_select=False`` is the
    ablation: every valid pair is stored, nothing is replayed. ``lanes`` sets the width of the
    replay batch as a multiple of the T x N explored steps (at most H); it changes speed, never a verdict.
    ``hold`` adds the held-goal candidates (module docstring), one per explored step, at h = H.
    ``settle`` (with ``hold``) keeps only moved candidates whose object then stays at g' for the next
    H steps (or to the episode's end), and judges every candidate at its final step: the explored
    actions are imitated where they leave the object at g' and the policy does not. ``radius`` scales
    the task's success threshold for every test here (``within``). ``stop`` (with ``hold``) labels the
    held candidates with the zero action (module docstring). ``hold_horizon`` (> 0) takes the held
    candidates at that h instead of H: at a long H their replays, one per explored step, would
    outweigh every other. ``rest`` (with ``settle``) keeps, of each explored step's settled moved
    candidates, only the one of largest h: their goals all lie within the threshold of one resting
    place, so the others would replay the same question with less time to answer it. ``rest_horizon``
    (> 0, with ``rest``; ``max_horizon`` covers it) keeps Algorithm 2's candidates within ``horizon``
    and adds resting places up to ``rest_horizon`` steps ahead, judged at their final step: a strike
    and where it leaves the object can lie further apart than the steps a first hit is learnt over."""
    T, H = env.episode_length, max_horizon
    n = traj.actions.shape[1]
    hs = jnp.arange(1, H + 1)
    t = jnp.arange(T)
    later = jnp.minimum(t[None, :] + hs[:, None], T)  # [H, T] index of s_{t+h}, clamped
    goal = traj.achieved[later]  # [H, T, N, G]
    real = (t[None, :] + hs[:, None] <= T)[..., None] & ~traj.invalid[:T][None] & ~traj.invalid[later]
    achieved_at_t = within(env, traj.achieved[:T][None], goal, radius)
    away = real & ~achieved_at_t
    moved = away & (hs <= horizon)[:, None, None]  # Algorithm 2's candidates
    hold_at = horizon if hold_horizon == 0 else jnp.minimum(horizon, hold_horizon)
    held = real & achieved_at_t & (hs == hold_at)[:, None, None] & hold
    settled = jnp.zeros_like(moved)
    if settle:
        after = jnp.minimum(later[..., None] + jnp.arange(1, H + 1), T)  # [H, T, H] the steps after t + h
        stays = jnp.all(within(env, traj.achieved[after], goal[:, :, None], radius), axis=2)
        settled = (moved if rest_horizon == 0 else away) & stays
        if rest:  # none settled at a larger h for the same step
            settled = settled & (jnp.flip(jnp.cumsum(jnp.flip(settled, 0), 0), 0) == 1)
        moved = settled if rest_horizon == 0 else moved | settled
    at_final = (held | settled).reshape(-1)
    valid, held = (moved | held).reshape(-1), held.reshape(-1)
    goal = goal.reshape(H * T * n, -1)
    if use_select:
        starts = jax.tree_util.tree_map(lambda x: x.reshape((T * n,) + x.shape[2:]), traj.states)
        flat = jnp.arange(H * T * n, dtype=jnp.int32)
        reached, steps = replay_queue(
            env,
            policy,
            pstate,
            starts,
            goal,
            flat % (T * n),
            flat // (T * n) + 1,
            valid,
            num_lanes(T, n, lanes, H),
            at_final=at_final,
            radius=radius,
        )
        accept = valid & ~reached
    else:
        accept, steps = valid, jnp.int32(0)
    tile = lambda x: jnp.broadcast_to(x[None], (H,) + x.shape).reshape((H * T * n,) + x.shape[2:])  # noqa: E731
    action = tile(traj.actions)
    if stop:
        action = jnp.where(held[:, None], jnp.zeros_like(action), action)
    out = Candidates(tile(traj.states.obs), goal, action, valid, accept, held, steps)
    chex.assert_shape([out.valid, out.accept, out.held], (num_candidates(T, H, n),))
    return out
