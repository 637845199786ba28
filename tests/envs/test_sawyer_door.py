"""SawyerDoor: the contract, exact restore-and-replay, and a scripted controller that opens the door to
the goal and back, from one compiled episode program (8 envs, 50 steps) shared by every test."""


import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs.sawyer_door import GOAL_MAX, HINGE_MAX, WORKSPACE, scripted
from splid_jax.common.errors import InvalidConfig

N = 8


@pytest.fixture(scope="module")
def env():
    return envs.make("sawyer_door")


@pytest.fixture(scope="module")
def episodes(env, episode_program, fresh_starts):
    start = fresh_starts(env, N)
    noise = jax.random.uniform(jax.random.PRNGKey(1), (env.episode_length, N, 3), minval=-1.0, maxval=1.0)
    run = episode_program(env, scripted)
    return start, noise, run(start, noise, False), run(start, noise, True)


def test_contract_shapes_and_goal_ranges(env, episodes, fresh_starts):
    start, _, (states, actions), _ = episodes
    assert (env.obs_size, env.goal_size, env.action_size, env.episode_length) == (4, 1, 3, 50)
    assert states.obs.shape == (50, N, 4) and states.obs.dtype == jnp.float32
    assert states.achieved_goal.shape == (50, N, 1) and states.success.dtype == jnp.bool_
    np.testing.assert_array_equal(states.step[-1], 50)
    # the state is the hand's XYZ and the door angle; the goal is the angle
    np.testing.assert_array_equal(states.obs[..., 3:], states.achieved_goal)
    np.testing.assert_array_equal(states.obs[..., :3], states.physics.qpos[..., 1:4])
    np.testing.assert_array_equal(start.obs[:, 3], 0.0)  # every episode starts with the door closed
    assert 0.0 <= float(jnp.min(start.desired_goal)) and float(jnp.max(start.desired_goal)) <= GOAL_MAX
    same = fresh_starts(env, N)  # traced anew: a draw outside the key would differ
    np.testing.assert_array_equal(same.obs, start.obs)  # a key fixes the start and the goal
    np.testing.assert_array_equal(same.desired_goal, start.desired_goal)
    assert not bool(jnp.any(states.invalid))


def test_random_actions_move_the_hand_within_its_box_and_success_is_the_angle_error(env, episodes):
    _, _, (states, _), _ = episodes
    hand = states.obs[..., :3]
    moved = jnp.linalg.norm(hand[-1] - hand[0], axis=-1)
    assert float(jnp.min(moved)) > 0.01
    lo, hi = (np.asarray(b) for b in WORKSPACE)
    assert np.all(np.asarray(hand) > lo - 0.02) and np.all(np.asarray(hand) < hi + 0.02)  # targets stay in the box
    angle = states.achieved_goal[..., 0]
    assert float(jnp.min(angle)) > -0.02 and float(jnp.max(angle)) < HINGE_MAX + 0.02  # the hinge's limits hold
    err = jnp.abs(states.achieved_goal - states.desired_goal)[..., 0]
    np.testing.assert_array_equal(states.success, err <= 0.06)
    np.testing.assert_array_equal(states.reward, states.success.astype(jnp.float32) - 1.0)


def test_a_saved_state_replays_bit_for_bit(env, episodes, episode_program):
    _, _, _, (states, actions) = episodes  # the scripted run: the hand in the hook, the door moving
    k = 15
    saved = jax.tree_util.tree_map(lambda x: x[k - 1], states)  # the state after k steps
    rest = jnp.concatenate([actions[k:], jnp.zeros((k, N, 3))])  # padded to the program's length
    replay, _ = episode_program(env, scripted)(saved, rest, False)
    assert float(jnp.max(jnp.abs(states.physics.qvel[k:, :, 0]))) > 0.1  # the door swings after the save
    np.testing.assert_array_equal(replay.obs[: 50 - k], states.obs[k:])
    np.testing.assert_array_equal(replay.physics.qvel[: 50 - k], states.physics.qvel[k:])
    np.testing.assert_array_equal(replay.physics.qacc_warmstart[: 50 - k], states.physics.qacc_warmstart[k:])


def test_the_scripted_controller_opens_the_door_to_the_goal_and_holds_it(env, episodes):
    start, _, _, (states, actions) = episodes
    assert float(jnp.max(start.desired_goal)) > 0.5  # some goals need the door well open
    assert bool(jnp.all(states.success[-1]))
    final = jnp.abs(states.achieved_goal[-1] - states.desired_goal[-1])
    assert float(jnp.max(final)) < 0.03  # half the threshold
    assert bool(jnp.all(states.success[-10:]))  # held, not swung through
    assert float(jnp.max(jnp.abs(actions))) <= 1.0


def test_the_scripted_controller_pulls_the_door_back(env, episodes, episode_program):
    _, noise, _, (states, _) = episodes
    opened = jax.tree_util.tree_map(lambda x: x[-1], states)
    back = GOAL_MAX - opened.desired_goal  # wide open doors go nearly shut, nearly shut ones wide open
    retargeted = jax.vmap(env.with_goal)(opened, back)
    closing, _ = episode_program(env, scripted)(retargeted, noise, True)
    assert bool(jnp.any(back[:, 0] < opened.achieved_goal[:, 0] - 0.3))  # some doors must swing well back
    assert bool(jnp.all(closing.success[-1]))


@pytest.mark.parametrize(
    "field, value",
    [
        ("max_episode_steps", 1),
        ("success_threshold", 0.0),
        ("action_scale", 0.5),
        ("door_damping", 0.0),
        ("timestep", 0.05),
        ("frame_skip", 0),
        ("iterations", 0),
    ],
)
def test_bad_fields_fail_naming_them(field, value):
    with pytest.raises(InvalidConfig, match=rf"sawyer_door\.{field}"):
        envs.make("sawyer_door", **{field: value})
