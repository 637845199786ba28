"""SELECT on the point task with a policy whose behaviour is known exactly: it always moves +x."""

import functools

import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs.base import State
from splid_jax.common.networks import make_policy
from splid_jax.learners.imitation.explore import Trajectory
from splid_jax.learners.splid.select import num_candidates, select
from tests.helpers import explore, policy_reaches

T, H, N = 10, 5, 3  # every trajectory has N envs: each function below compiles once for the module


@pytest.fixture(scope="module")
def env():
    return envs.make("point", max_episode_steps=T)


@pytest.fixture(scope="module")
def policy(env):
    return make_policy(env.obs_size, env.goal_size, env.action_size, (16,), normalise=False)


@pytest.fixture(scope="module")
def run_select(env, policy):
    """``run_select(pstate, traj, horizon=H, use_select=True, lanes=1.0, relabel="paper")``: SELECT jitted
    once per setting."""

    @functools.cache
    def jitted(use_select, lanes, relabel):
        return jax.jit(lambda ps, tr, hz: select(env, policy, ps, tr, H, hz, use_select, lanes, relabel))

    def run(pstate, traj, horizon=H, use_select=True, lanes=1.0, relabel="paper"):
        return jitted(use_select, lanes, relabel)(pstate, traj, jnp.int32(horizon))

    return run


def constant_policy(policy, action):
    """Parameters whose output is ``action`` everywhere: zero kernels, output bias = action."""
    pstate = policy.init(jax.random.PRNGKey(0))
    params = jax.tree_util.tree_map(jnp.zeros_like, pstate.params)
    params["params"]["Dense_1"]["bias"] = jnp.asarray(action, jnp.float32)
    return pstate.replace(params=params)


@functools.partial(jax.jit, static_argnums=0)
def _scripted(env, starts, actions) -> Trajectory:
    s0 = jax.vmap(env.reset)(jax.random.split(jax.random.PRNGKey(0), N))
    s0 = s0.replace(physics=starts, obs=starts, achieved_goal=starts)

    def one(s: State, _):
        nxt = jax.vmap(env.step)(s, actions)
        return nxt, (s, actions, nxt.achieved_goal, nxt.invalid)

    _, (states, acts, ag, inv) = jax.lax.scan(one, s0, None, length=T)
    return Trajectory(
        states, acts, jnp.concatenate([s0.achieved_goal[None], ag]), jnp.concatenate([s0.invalid[None], inv])
    )


def scripted_trajectory(env, actions, start=(-4.8, -4.8)) -> Trajectory:
    """Roll fixed per-env actions for T steps from ``start``; envs past the given rows stand still."""
    actions = jnp.asarray(actions, jnp.float32).reshape(-1, 2)
    return _scripted(
        env, jnp.broadcast_to(jnp.asarray(start), (N, 2)), jnp.zeros((N, 2)).at[: len(actions)].set(actions)
    )


def env_of(x):
    """Candidates [H * T * N] in layout [H, T, N] -> [H, T, N]."""
    return np.asarray(x).reshape(H, T, N)


def test_rejects_what_the_policy_solves_and_accepts_what_it_cannot(env, policy, run_select):
    pstate = constant_policy(policy, [1.0, 0.0])  # moves +1 in x each step
    # env 0 explored +x at 0.4 (the policy gets there sooner: reject); env 1 explored +y at 0.4 (the
    # policy cannot: accept); env 2 explored +x at full speed (ties on first hit time: reject).
    traj = scripted_trajectory(env, [[0.4, 0.0], [0.0, 0.4], [1.0, 0.0]])
    cands = run_select(pstate, traj)
    m = num_candidates(T, H, N)
    chex.assert_shape([cands.obs, cands.goal, cands.action], (m, 2))
    chex.assert_shape([cands.valid, cands.accept], (m,))
    valid, accept = env_of(cands.valid), env_of(cands.accept)
    assert valid[..., 1].sum() > 0 and valid[..., 0].sum() > 0 and valid[..., 2].sum() > 0
    assert accept[..., 0].sum() == 0
    assert accept[..., 2].sum() == 0
    np.testing.assert_array_equal(accept[..., 1], valid[..., 1])
    # accepted pairs carry the explored action and a goal the explored path reached
    accept = np.asarray(cands.accept)
    np.testing.assert_allclose(np.asarray(cands.action)[accept], np.tile([0.0, 0.4], (accept.sum(), 1)))


def test_pairs_with_no_progress_are_not_candidates(env, policy, run_select):
    traj = scripted_trajectory(env, [[0.0, 0.3]])
    valid = env_of(run_select(constant_policy(policy, [1.0, 0.0]), traj).valid)
    # 0.3 per step: only h >= 4 moves the point more than the 1.0 success radius
    hs, ts = np.arange(1, H + 1)[:, None], np.arange(T)[None]
    np.testing.assert_array_equal(valid[..., 0], (hs >= 4) & (ts + hs <= T))
    assert not valid[..., 1:].any()  # the envs that stand still


def test_horizon_mask_and_no_select_ablation(env, policy, run_select):
    pstate = constant_policy(policy, [1.0, 0.0])
    traj = scripted_trajectory(env, [[0.6, 0.0]])
    short = run_select(pstate, traj, horizon=3)
    assert not env_of(short.valid)[3:].any()
    every = run_select(pstate, traj, use_select=False)
    np.testing.assert_array_equal(every.accept, every.valid)
    assert int(every.accept.sum()) > 0 and int(run_select(pstate, traj).accept.sum()) == 0


def test_explore_shapes_and_noise(env, policy):
    pstate = constant_policy(policy, [0.0, 0.0])
    traj = _explore(env, policy, pstate, jax.random.PRNGKey(0), jnp.float32(1.0))
    chex.assert_shape(traj.actions, (T, N, 2))
    chex.assert_shape(traj.achieved, (T + 1, N, 2))
    chex.assert_shape(traj.states.obs, (T, N, 2))
    assert float(jnp.std(traj.actions)) > 0.3 and float(jnp.max(jnp.abs(traj.actions))) <= 1.0
    quiet = _explore(env, policy, pstate, jax.random.PRNGKey(0), jnp.float32(0.0))
    np.testing.assert_array_equal(quiet.actions, 0.0)


@functools.partial(jax.jit, static_argnums=(0, 1))
def _explore(env, policy, pstate, key, sigma):
    return explore(env, policy, pstate, key, N, sigma)


@functools.partial(jax.jit, static_argnums=(0, 1, 5))
def _each_alone(env, policy, pstate, starts, goal, at_final=False):
    """``policy_reaches`` for every candidate [H * T * N] on its own (``at_final``: at exactly h)."""
    i = jnp.arange(goal.shape[0])
    start = jax.tree_util.tree_map(lambda x: x[i % (T * N)], starts)
    reaches = lambda s, g, h: policy_reaches(env, policy, pstate, s, g, h, at_final=at_final)  # noqa: E731
    return jax.vmap(reaches)(start, goal, i // (T * N) + 1)


def test_work_queue_gives_every_valid_candidate_the_verdict_of_its_own_replay(env, policy, run_select):
    """Against ``policy_reaches`` run on each candidate alone, at several lane counts: lanes change
    the speed, never a verdict, and no lane steps past a verdict."""
    pstate = policy.init(jax.random.PRNGKey(3))
    traj = _explore(env, policy, pstate, jax.random.PRNGKey(1), jnp.float32(1.0))
    results = [run_select(pstate, traj, lanes=lanes) for lanes in (0.02, 0.3, 1.0, 3.0)]
    c = results[0]
    starts = jax.tree_util.tree_map(lambda x: x.reshape((T * N,) + x.shape[2:]), traj.states)
    expected = np.asarray(c.valid & ~_each_alone(env, policy, pstate, starts, c.goal))
    assert 0 < expected.sum() < np.asarray(c.valid).sum()  # both verdicts occur
    hs = np.arange(H * T * N) // (T * N) + 1
    for r in results:
        np.testing.assert_array_equal(r.accept, expected)
        # a rejected candidate stops at its hit, an accepted one runs its full h
        assert int(r.replay_steps) < hs[np.asarray(c.valid)].sum()
        assert int(r.replay_steps) >= hs[expected].sum()
    assert len({int(r.replay_steps) for r in results}) == 1


def test_no_valid_candidate_means_no_replay(env, policy, run_select):
    cands = run_select(constant_policy(policy, [1.0, 0.0]), scripted_trajectory(env, []))  # nothing moves
    assert not np.asarray(cands.valid).any() and int(cands.replay_steps) == 0


def test_held_goals_are_kept_where_the_policy_leaves_them_and_judged_at_the_final_step(env, policy, run_select):
    """``relabel=hold``: a point that stayed put (explored action 0) holds its goal for H steps; a policy that
    drifts +x leaves it (keep the pair), one that stays holds it too (reject). Only h = H is a held
    candidate, and the verdict is the final step's: a policy that passes through g' still fails."""
    traj = scripted_trajectory(env, [], start=(-2.0, -4.8))
    hs, ts = np.arange(1, H + 1)[:, None, None], np.arange(T)[None, :, None]
    drift, stay = constant_policy(policy, [1.0, 0.0]), constant_policy(policy, [0.0, 0.0])
    kept = run_select(drift, traj, relabel="hold")
    np.testing.assert_array_equal(env_of(kept.held), np.broadcast_to((hs == H) & (ts + hs <= T), (H, T, N)))
    np.testing.assert_array_equal(kept.accept, kept.held)
    assert int(kept.replay_steps) == H * int(kept.held.sum())  # held replays run their full H
    assert not np.asarray(run_select(stay, traj, relabel="hold").accept).any()
    assert not np.asarray(run_select(drift, traj).valid).any()  # paper: none
    # a policy that crosses g' and comes back within the success radius only at some middle step
    goal = traj.achieved[0, 0]
    there = jax.tree_util.tree_map(lambda x: x[0, 0], traj.states)
    assert bool(policy_reaches(env, policy, drift, there, goal, H)) and not bool(
        policy_reaches(env, policy, drift, there, goal, H, at_final=True)
    )


def test_stop_labels_the_held_pairs_with_the_zero_action_and_keeps_the_rest(env, policy, run_select):
    """``relabel=stop``: the same verdicts as ``hold``; the held pairs' action becomes 0, the moved ones keep theirs."""
    traj = scripted_trajectory(env, [[0.0, 0.4]], start=(-2.0, -4.8))  # env 0 moves, the others stand still
    drift = constant_policy(policy, [1.0, 0.0])
    held, stopped = run_select(drift, traj, relabel="hold"), run_select(drift, traj, relabel="stop")
    np.testing.assert_array_equal(stopped.accept, held.accept)
    np.testing.assert_array_equal(stopped.held, held.held)
    h, action = np.asarray(held.held), np.asarray(stopped.action)
    assert h.any() and (np.asarray(held.valid) & ~h).any()
    np.testing.assert_array_equal(action[h], 0.0)
    np.testing.assert_array_equal(action[~h], np.asarray(held.action)[~h])
    assert np.abs(np.asarray(held.action)[np.asarray(held.valid) & ~h]).max() > 0


def test_exact_takes_every_verdict_at_h_so_a_policy_that_passes_g_prime_sooner_keeps_the_pair(env, policy, run_select):
    """``relabel=exact``: ``hold``'s candidates; a policy at full speed passes the goals a 0.4 push reached, so the
    first-hit verdict rejects every moved pair, and the exact-h one keeps each where the policy is then off g' (not
    where the room's wall stops it near g'), as each candidate's own replay to exactly h says."""
    traj = scripted_trajectory(env, [[0.4, 0.0]])
    fast = constant_policy(policy, [1.0, 0.0])
    first, exact = run_select(fast, traj, relabel="hold"), run_select(fast, traj, relabel="exact")
    np.testing.assert_array_equal(exact.valid, first.valid)
    np.testing.assert_array_equal(exact.held, first.held)
    moved = np.asarray(first.valid) & ~np.asarray(first.held)
    assert moved.any() and not np.asarray(first.accept)[moved].any()
    starts = jax.tree_util.tree_map(lambda x: x.reshape((T * N,) + x.shape[2:]), traj.states)
    expected = np.asarray(exact.valid) & ~np.asarray(_each_alone(env, policy, fast, starts, exact.goal, True))
    np.testing.assert_array_equal(exact.accept, expected)
    assert expected[moved].sum() > moved.sum() // 2
    assert int(exact.replay_steps) > int(first.replay_steps)  # no replay ends at a passing hit
