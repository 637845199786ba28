"""Reacher: the contract, exact restore-and-replay, and a scripted controller that reaches, from
one compiled episode program (8 envs, 50 steps) shared by every test."""


import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs.reacher import fingertip, scripted
from splid_jax.common.errors import InvalidConfig

N = 8


@pytest.fixture(scope="module")
def env():
    return envs.make("reacher")


@pytest.fixture(scope="module")
def episodes(env, episode_program, fresh_starts):
    start = fresh_starts(env, N)
    noise = jax.random.uniform(jax.random.PRNGKey(1), (env.episode_length, N, 2), minval=-1.0, maxval=1.0)
    run = episode_program(env, scripted)
    return start, noise, run(start, noise, False), run(start, noise, True)


def test_contract_shapes_and_goal_ranges(env, episodes, fresh_starts):
    start, _, (states, actions), _ = episodes
    assert (env.obs_size, env.goal_size, env.action_size, env.episode_length) == (11, 2, 2, 50)
    assert states.obs.shape == (50, N, 11) and states.obs.dtype == jnp.float32
    assert states.achieved_goal.shape == (50, N, 2) and states.success.dtype == jnp.bool_
    np.testing.assert_array_equal(states.step[-1], 50)
    # the goal is the fingertip's XY, the last three entries of the state its XYZ
    np.testing.assert_array_equal(states.obs[..., -3:-1], states.achieved_goal)
    np.testing.assert_allclose(states.obs[..., -3:], fingertip(states.obs[..., 4:6]), atol=1e-6)
    assert float(jnp.max(jnp.linalg.norm(start.desired_goal, axis=-1))) <= 0.2
    same = fresh_starts(env, N)  # traced anew: a draw outside the key would differ
    np.testing.assert_array_equal(same.obs, start.obs)  # a key fixes the start and the goal
    assert not bool(jnp.any(states.invalid))


def test_random_actions_move_the_arm_and_the_goal_test_uses_the_squared_distance(env, episodes):
    _, _, (states, _), _ = episodes
    moved = jnp.linalg.norm(states.achieved_goal[-1] - states.achieved_goal[0], axis=-1)
    assert float(jnp.min(moved)) > 0.01
    d2 = jnp.sum((states.achieved_goal - states.desired_goal) ** 2, axis=-1)
    np.testing.assert_array_equal(states.success, d2 <= 0.05)
    np.testing.assert_array_equal(states.reward, states.success.astype(jnp.float32) - 1.0)


def test_a_saved_state_replays_bit_for_bit(env, episodes, episode_program):
    start, noise, (states, _), _ = episodes
    k = 10
    saved = jax.tree_util.tree_map(lambda x: x[k - 1], states)  # the state after k steps
    rest = jnp.concatenate([noise[k:], jnp.zeros((k, N, 2))])  # padded to the program's length
    replay, _ = episode_program(env, scripted)(saved, rest, False)
    np.testing.assert_array_equal(replay.obs[: 50 - k], states.obs[k:])
    np.testing.assert_array_equal(replay.physics.qvel[: 50 - k], states.physics.qvel[k:])


def test_the_scripted_controller_reaches_and_stays(env, episodes):
    _, _, _, (states, actions) = episodes
    assert bool(jnp.all(states.success[-1]))
    final = jnp.linalg.norm(states.achieved_goal[-1] - states.desired_goal[-1], axis=-1)
    assert float(jnp.max(final)) < 0.01  # within 1 cm, far inside the seed's lenient threshold
    assert float(jnp.max(jnp.abs(actions))) <= 1.0


@pytest.mark.parametrize(
    "field, value", [("max_episode_steps", 1), ("success_threshold", 0.0), ("timestep", 0.1), ("frame_skip", 0)]
)
def test_bad_fields_fail_naming_them(field, value):
    with pytest.raises(InvalidConfig, match=rf"reacher\.{field}"):
        envs.make("reacher", **{field: value})
