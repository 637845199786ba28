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
from splid_jax.select import num_candidates, select

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


def test_replay_budget_decides_a_random_subset_of_valid_candidates(env):
    policy, pstate = constant_policy(env, [1.0, 0.0])
    starts = jnp.full((3, 2), -4.8)
    traj = scripted_trajectory(env, starts, jnp.array([[0.4, 0.0], [0.0, 0.4], [0.3, 0.3]]))
    full = select(env, policy, pstate, traj, H, jnp.int32(H), True)
    valid_per_h = np.asarray(full.valid).reshape(H, -1).sum(axis=1)
    # a budget with room for every valid candidate decides exactly what the full replay decides
    roomy = select(env, policy, pstate, traj, H, jnp.int32(H), True, jax.random.PRNGKey(1), 0.9)
    assert valid_per_h.max() <= round(0.9 * T * 3)
    np.testing.assert_array_equal(roomy.accept, full.accept)
    assert int(roomy.dropped) == 0
    # a tight budget replays 3 slots per h: the rest of the valid candidates are dropped, never stored
    tight = select(env, policy, pstate, traj, H, jnp.int32(H), True, jax.random.PRNGKey(1), 0.1)
    decided = np.minimum(valid_per_h, 3).sum()
    assert int(tight.dropped) == valid_per_h.sum() - decided
    accept = np.asarray(tight.accept)
    assert not (accept & ~np.asarray(full.accept)).any()  # a stored pair is one the full replay accepts
    assert 0 < accept.sum() <= decided
