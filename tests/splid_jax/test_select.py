"""SELECT on the point task with a policy whose behaviour is known exactly: it always moves +x."""

import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs.base import State
from splid_jax.explore import Trajectory, explore
from splid_jax.networks import make_policy
from splid_jax.select import num_candidates, policy_reaches, select

T, H = 10, 5


@pytest.fixture(scope="module")
def env():
    return envs.make("point", max_episode_steps=T)


def constant_policy(env, action):
    """An MLP whose output is ``action`` everywhere: zero kernels, output bias = action."""
    policy = make_policy(env.obs_size, env.goal_size, env.action_size, (8,), normalise=False)
    pstate = policy.init(jax.random.PRNGKey(0))
    params = jax.tree_util.tree_map(jnp.zeros_like, pstate.params)
    params["params"]["Dense_1"]["bias"] = jnp.asarray(action, jnp.float32)
    return policy, pstate.replace(params=params)


def scripted_trajectory(env, starts, actions) -> Trajectory:
    """Roll fixed per-env actions [N, 2] for T steps from the given start positions [N, 2]."""
    s0 = jax.vmap(env.reset)(jax.random.split(jax.random.PRNGKey(0), len(starts)))
    s0 = s0.replace(physics=starts, obs=starts, achieved_goal=starts)

    def one(s: State, _):
        nxt = jax.vmap(env.step)(s, actions)
        return nxt, (s, actions, nxt.achieved_goal, nxt.invalid)

    _, (states, acts, ag, inv) = jax.lax.scan(one, s0, None, length=T)
    return Trajectory(
        states, acts, jnp.concatenate([s0.achieved_goal[None], ag]), jnp.concatenate([s0.invalid[None], inv])
    )


def test_rejects_what_the_policy_solves_and_accepts_what_it_cannot(env):
    policy, pstate = constant_policy(env, [1.0, 0.0])  # moves +1 in x each step
    starts = jnp.array([[-4.8, -4.8], [-4.8, -4.8], [-4.8, -4.8]])
    # env 0 explored +x at 0.4 (the policy gets there sooner: reject); env 1 explored +y at 0.4 (the
    # policy cannot: accept); env 2 explored +x at full speed (ties on first hit time: reject).
    actions = jnp.array([[0.4, 0.0], [0.0, 0.4], [1.0, 0.0]])
    traj = scripted_trajectory(env, starts, actions)
    cands = jax.jit(lambda tr, hz: select(env, policy, pstate, tr, H, hz, True))(traj, jnp.int32(H))
    m = num_candidates(T, H, 3)
    chex.assert_shape([cands.obs, cands.goal, cands.action], (m, 2))
    chex.assert_shape([cands.valid, cands.accept], (m,))
    env_of = np.tile(np.arange(3), H * T)  # layout [H, T, N]
    valid, accept = np.asarray(cands.valid), np.asarray(cands.accept)
    assert valid[env_of == 1].sum() > 0 and valid[env_of == 0].sum() > 0 and valid[env_of == 2].sum() > 0
    assert accept[env_of == 0].sum() == 0
    assert accept[env_of == 2].sum() == 0
    np.testing.assert_array_equal(accept[env_of == 1], valid[env_of == 1])
    # accepted pairs carry the explored action and a goal the explored path reached
    np.testing.assert_allclose(np.asarray(cands.action)[accept], np.tile([0.0, 0.4], (accept.sum(), 1)))


def test_pairs_with_no_progress_are_not_candidates(env):
    policy, pstate = constant_policy(env, [1.0, 0.0])
    traj = scripted_trajectory(env, jnp.array([[-4.8, -4.8]]), jnp.array([[0.0, 0.3]]))
    cands = select(env, policy, pstate, traj, H, jnp.int32(H), True)
    # 0.3 per step: only h >= 4 moves the point more than the 1.0 success radius
    hs, ts = np.repeat(np.arange(1, H + 1), T), np.tile(np.arange(T), H)
    assert not np.asarray(cands.valid)[hs < 4].any()
    np.testing.assert_array_equal(np.asarray(cands.valid)[hs >= 4], (ts + hs <= T)[hs >= 4])


def test_horizon_mask_and_no_select_ablation(env):
    policy, pstate = constant_policy(env, [1.0, 0.0])
    traj = scripted_trajectory(env, jnp.array([[-4.8, -4.8]]), jnp.array([[0.6, 0.0]]))
    hs = np.repeat(np.arange(1, H + 1), T)
    short = select(env, policy, pstate, traj, H, jnp.int32(3), True)
    assert not np.asarray(short.valid)[hs > 3].any()
    every = select(env, policy, pstate, traj, H, jnp.int32(H), False)
    np.testing.assert_array_equal(every.accept, every.valid)
    assert (
        int(every.accept.sum()) > 0 and int(select(env, policy, pstate, traj, H, jnp.int32(H), True).accept.sum()) == 0
    )


def test_explore_shapes_and_noise(env):
    policy, pstate = constant_policy(env, [0.0, 0.0])
    traj = explore(env, policy, pstate, jax.random.PRNGKey(0), 4, jnp.float32(1.0))
    chex.assert_shape(traj.actions, (T, 4, 2))
    chex.assert_shape(traj.achieved, (T + 1, 4, 2))
    chex.assert_shape(traj.states.obs, (T, 4, 2))
    assert float(jnp.std(traj.actions)) > 0.3 and float(jnp.max(jnp.abs(traj.actions))) <= 1.0
    quiet = explore(env, policy, pstate, jax.random.PRNGKey(0), 4, jnp.float32(0.0))
    np.testing.assert_array_equal(quiet.actions, 0.0)


def test_work_queue_gives_every_valid_candidate_the_verdict_of_its_own_replay(env):
    """Against ``policy_reaches`` run on each candidate alone, at several lane counts: lanes change
    the speed, never a verdict, and no lane steps past a verdict."""
    policy = make_policy(env.obs_size, env.goal_size, env.action_size, (16,), normalise=False)
    pstate = policy.init(jax.random.PRNGKey(3))
    n = 6
    traj = explore(env, policy, pstate, jax.random.PRNGKey(1), n, jnp.float32(1.0))
    starts = jax.tree_util.tree_map(lambda x: x.reshape((T * n,) + x.shape[2:]), traj.states)
    results = [select(env, policy, pstate, traj, H, jnp.int32(H), True, lanes) for lanes in (0.02, 0.3, 1.0)]
    c = results[0]
    idx = jnp.arange(H * T * n)
    alone = jax.vmap(
        lambda i: policy_reaches(
            env, policy, pstate, jax.tree_util.tree_map(lambda x: x[i % (T * n)], starts), c.goal[i], i // (T * n) + 1
        )
    )(idx)
    expected = np.asarray(c.valid & ~alone)
    assert 0 < expected.sum() < np.asarray(c.valid).sum()  # both verdicts occur
    hs = np.asarray(idx // (T * n) + 1)
    for r in results:
        np.testing.assert_array_equal(r.accept, expected)
        # a rejected candidate stops at its hit, an accepted one runs its full h
        assert int(r.replay_steps) < hs[np.asarray(c.valid)].sum()
        assert int(r.replay_steps) >= hs[expected].sum()
    assert len({int(r.replay_steps) for r in results}) == 1


def test_no_valid_candidate_means_no_replay(env):
    policy, pstate = constant_policy(env, [1.0, 0.0])
    traj = scripted_trajectory(env, jnp.full((2, 2), -4.8), jnp.zeros((2, 2)))  # nothing moves
    cands = select(env, policy, pstate, traj, H, jnp.int32(H), True)
    assert not np.asarray(cands.valid).any() and int(cands.replay_steps) == 0


def test_held_goals_are_kept_where_the_policy_leaves_them_and_judged_at_the_final_step(env):
    """``hold``: a point that stayed put (explored action 0) holds its goal for H steps; a policy that
    drifts +x leaves it (keep the pair), one that stays holds it too (reject). Only h = H is a held
    candidate, and the verdict is the final step's: a policy that passes through g' still fails."""
    traj = scripted_trajectory(env, jnp.array([[-2.0, -4.8]]), jnp.zeros((1, 2)))
    hs, ts = np.repeat(np.arange(1, H + 1), T), np.tile(np.arange(T), H)
    drift, p_drift = constant_policy(env, [1.0, 0.0])
    stay, p_stay = constant_policy(env, [0.0, 0.0])
    kept = select(env, drift, p_drift, traj, H, jnp.int32(H), True, hold=True)
    np.testing.assert_array_equal(kept.held, (hs == H) & (ts + hs <= T))
    np.testing.assert_array_equal(kept.accept, kept.held)
    assert int(kept.replay_steps) == H * int(kept.held.sum())  # held replays run their full H
    assert not np.asarray(select(env, stay, p_stay, traj, H, jnp.int32(H), True, hold=True).accept).any()
    assert not np.asarray(select(env, drift, p_drift, traj, H, jnp.int32(H), True).valid).any()  # paper: none
    # a policy that crosses g' and comes back within the success radius only at some middle step
    goal = traj.achieved[0, 0]
    there = jax.tree_util.tree_map(lambda x: x[0, 0], traj.states)
    assert bool(policy_reaches(env, drift, p_drift, there, goal, H)) and not bool(
        policy_reaches(env, drift, p_drift, there, goal, H, at_final=True)
    )
