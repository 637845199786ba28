"""Fetch-style MJX tasks: contract and shapes, sampling ranges, validation, rest without drift,
restore-and-replay bit for bit, NaN flagging, action clipping, and scripted controllers succeeding.

Every physics test steps a task through its one compiled episode program (the ``fetch`` fixture,
conftest.FetchEpisodes), and the runs several tests read (rest, random actions, scripted) run once.
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys

import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs.fetch import control, models, tasks
from splid_jax.common.errors import InvalidConfig

NAMES = ["reach", "push", "slide", "pick_and_place"]
K = 20  # restore point of the replay test


@functools.cache
def _env(name):
    return envs.make(name)


@functools.cache
def _reset(name, n):
    env = _env(name)
    return jax.jit(lambda key: jax.vmap(env.reset)(jax.random.split(key, n)))


@functools.cache
def _episodes(fetch, name, kind):
    """(start, final, trajectory) of a task's standing runs, each run once for every test reading it:
    ``rest`` (zero action), ``random`` (uniform actions) or ``scripted`` (its controller)."""
    zeros = np.zeros((fetch.T, fetch.B, 4))
    if kind == "rest":
        return fetch.run(_env(name), zeros)
    if kind == "random":
        return fetch.run(_env(name), fetch.random_actions(1))
    return fetch.run(_env(name), zeros, w=1.0)


def _at(tree, t):
    return jax.tree_util.tree_map(lambda x: x[t], tree)


# ---- cheap: no physics compiled ------------------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_contract_and_shapes(fetch, name):
    env = _env(name)
    assert (env.goal_size, env.action_size, env.episode_length) == (3, 4, 50)
    assert env.obs_size == (10 if name == "reach" else 25)
    hash(env)  # jitted code closes over tasks: they must stay hashable
    s, n = fetch.reset(env), fetch.B
    chex.assert_shape(s.obs, (n, env.obs_size))
    chex.assert_shape([s.achieved_goal, s.desired_goal], (n, 3))
    chex.assert_shape([s.reward, s.success, s.step, s.invalid], (n,))
    lay = env.layout
    chex.assert_shape(s.physics.qpos, (n, lay.nq))
    chex.assert_shape([s.physics.qvel, s.physics.qacc_warmstart], (n, lay.nv))
    chex.assert_shape(s.physics.ctrl, (n, lay.nu))
    assert not bool(s.invalid.any()) and int(s.step.max()) == 0
    # (that the step keeps every shape and dtype: test_rests_without_drift_under_zero_action)
    # Achieved goal, layout and reward convention.
    np.testing.assert_array_equal(s.achieved_goal, s.obs[:, 0:3] if name == "reach" else s.obs[:, 3:6])
    np.testing.assert_allclose(s.obs[:, 0:3], np.broadcast_to(lay.grip_home, (n, 3)), atol=1e-6)
    np.testing.assert_array_equal(s.reward, env.reward_of(s.achieved_goal, s.desired_goal))
    near = jax.vmap(env.with_goal)(s, s.achieved_goal + jnp.asarray([0.0, 0.0, 0.049]))
    far = jax.vmap(env.with_goal)(s, s.achieved_goal + jnp.asarray([0.0, 0.0, 0.051]))
    assert bool(near.success.all()) and not bool(far.success.any())
    np.testing.assert_array_equal(near.reward, 0.0)
    np.testing.assert_array_equal(far.reward, -1.0)
    jax.tree_util.tree_map(np.testing.assert_array_equal, near.physics, s.physics)


@pytest.mark.parametrize("name", NAMES)
def test_reset_samples_stay_in_their_ranges(name):
    env = _env(name)
    n = 4000
    s = _reset(name, n)(jax.random.PRNGKey(3))
    home = np.asarray(env.layout.grip_home)
    goal = np.asarray(s.desired_goal)
    offset = np.asarray(env.target_offset)
    tr = env.target_range
    assert np.all(np.abs(goal[:, :2] - home[:2] - offset[:2]) <= tr + 1e-6)
    if name == "reach":
        assert np.all(np.abs(goal - home) <= tr + 1e-6)
        return
    obj = np.asarray(s.achieved_goal)
    d = np.linalg.norm(obj[:, :2] - home[:2], axis=-1)
    assert np.all(np.abs(obj[:, :2] - home[:2]) <= env.obj_range + 1e-6)
    assert np.all(d >= tasks.MIN_OBJECT_DISTANCE - 1e-6)
    rest = env.layout.object_rest_z
    np.testing.assert_allclose(obj[:, 2], rest, atol=1e-6)
    lift = goal[:, 2] - rest
    if name == "pick_and_place":
        air = lift > 1e-6
        assert 0.45 < air.mean() < 0.55
        assert np.all(lift >= -1e-6) and np.all(lift <= tasks.GOAL_LIFT_MAX + 1e-6)
    else:
        np.testing.assert_allclose(lift, 0.0, atol=1e-6)
    # Uniform over the allowed region: the spread reaches close to the range on each side.
    assert np.ptp(obj[:, 0]) > 1.8 * env.obj_range and np.ptp(goal[:, 1]) > 1.8 * tr


@pytest.mark.parametrize(
    ("name", "field", "value"),
    [
        ("push", "distance_threshold", 0.0),
        ("push", "obj_range", -0.1),
        ("push", "obj_range", 0.05),  # no room for the 0.1 m minimum distance
        ("push", "table", "mesh"),
        ("slide", "table", "box"),  # MJX collides the cylinder puck with a plane only
        ("pick_and_place", "finger", "capsule"),  # two gripping box fingers
        ("slide", "target_range", -0.3),
        ("pick_and_place", "substeps", 0),
        ("reach", "timestep", 0.0),
        ("push", "iterations", 0),
        ("reach", "max_episode_steps", 0),
        ("push", "cholesky", "lapack"),
        ("slide", "workspace", "sphere"),
        ("push", "drive", "mocap"),
        ("reach", "floor_clearance", -0.01),
        ("slide", "finger_table", 3.0),
        ("push", "finger_table", -1.0),
        ("pick_and_place", "finger_drive", "instant"),
        ("slide", "finger", "capsule"),  # the round tips or the reference's pads
        ("slide", "gripper_mass", -1.0),
    ],
)
def test_bad_overrides_fail_naming_the_field(name, field, value):
    with pytest.raises(InvalidConfig, match=rf"{name}\.{field}"):
        envs.make(name, **{field: value})


def _target_after(env, grip_world, action):
    """World xyz of the gripper target ``env._control`` sets from a gripper at ``grip_world``."""
    lay = env.layout
    phys = env.reset(jax.random.PRNGKey(0)).physics
    home = np.asarray(lay.grip_home)
    phys = phys.replace(qpos=phys.qpos.at[lay.grip_q : lay.grip_q + 3].set(jnp.asarray(grip_world) - home))
    return home + np.asarray(env._control(phys, jnp.asarray(action, jnp.float32)))[:3]


def test_slide_gripper_target_slows_near_the_arm_reach_and_stops_on_it():
    center, radius = np.asarray(control.ARM_REACH_CENTER["slide"]), control.ARM_REACH_RADIUS
    capped = envs.make("slide", arm_drift=0.0)  # the cap alone
    far = _target_after(capped, (1.38, 0.75, 0.42), (1.0, 0.0, -1.0, 0.0))
    assert np.linalg.norm(far - center) <= radius + 1e-6
    assert far[0] < 1.39 < 1.38 + 0.05  # the reference's gripper stops at x 1.39 here
    grip = np.array([1.30, 0.75, 0.42])  # 8 cm inside the reach
    near = _target_after(capped, grip, (1.0, 0.0, 0.0, 0.0))
    n = (grip - center) / np.linalg.norm(grip - center)
    cap = control.ARM_STRETCH_GAIN * np.sqrt(radius - np.linalg.norm(grip - center))
    np.testing.assert_allclose((near - grip) @ n, cap, rtol=1e-4)  # outward step capped, < the asked 5 cm
    inside = _target_after(capped, (1.0, 0.75, 0.45), (1.0, 0.0, -0.4, 0.0))
    np.testing.assert_allclose(inside, (1.05, 0.75, 0.43), atol=1e-6)  # well within reach: unchanged
    free = _target_after(envs.make("slide", workspace="box", arm_drift=0.0), (1.38, 0.75, 0.42), (1.0, 0.0, -1.0, 0.0))
    np.testing.assert_allclose(free, (1.43, 0.75, 0.394), atol=1e-6)  # box floor: the pads pressed on the table


def test_arm_drift_pulls_a_held_grip_back_along_the_floor_only_near_the_reach():
    plain, drifting = envs.make("slide", arm_drift=0.0), envs.make("slide", arm_drift=2.0)
    center = np.asarray(control.ARM_REACH_CENTER["slide"])
    far = np.array([1.30, 0.90, 0.45])  # 1.04 m from the reach centre
    held = [_target_after(e, far, (0.0, 0.0, 0.0, 0.0)) for e in (plain, drifting)]
    np.testing.assert_allclose(held[0], far, atol=1e-6)
    back = 2.0 * np.interp(np.linalg.norm(far - center), control.DRIFT_REACH, control.DRIFT)
    flat = np.append((far - center)[:2], 0.0)
    np.testing.assert_allclose(held[1], far - back * flat / np.linalg.norm(flat), atol=1e-6)
    assert back > 0.015
    out = [_target_after(e, far, (*(flat[:2] / np.linalg.norm(flat)), 0.0, 0.0)) for e in (plain, drifting)]
    np.testing.assert_allclose(*out, atol=1e-7)  # a drive outward: the stretch cap alone slows it
    near = (1.10, 0.75, 0.45)  # 0.85 m: held where it is
    np.testing.assert_allclose(*[_target_after(e, near, (0.0, 0.0, 0.0, 0.0)) for e in (plain, drifting)], atol=1e-7)
    with pytest.raises(InvalidConfig, match="arm_drift"):
        envs.make("slide", arm_drift=1.0, workspace="box")


def test_arm_reach_barely_touches_push_pick_and_reach_goal_regions():
    # their robot stands 0.355 m nearer the table than Slide's: every goal, and the pushing gripper 6 cm
    # behind it, lies over 20 cm inside the reach, where a full 5 cm step outward loses under 10 %
    center, radius = np.asarray(control.ARM_REACH_CENTER_DEFAULT), control.ARM_REACH_RADIUS
    g = np.stack(
        np.meshgrid(np.linspace(1.34 - 0.21, 1.34 + 0.15, 9), np.linspace(0.6, 0.9, 7), np.linspace(0.38, 0.9, 9)), -1
    ).reshape(-1, 3)
    assert (radius - np.linalg.norm(g - center, axis=1)).min() > 0.2
    for axis in range(3):
        steps = g + 0.05 * np.eye(3)[axis]
        np.testing.assert_allclose(control.within_reach(g, steps, center), steps, atol=0.005)


def test_unknown_override_fails_naming_it():
    with pytest.raises(InvalidConfig, match=r"push\.friction"):
        envs.make("push", friction=1.0)
    with pytest.raises(InvalidConfig, match=r"slide\.pad_friction=0\.2: must be unset: the option left the package"):
        envs.make("slide", finger="pads", pad_friction=0.2)  # a run recorded with it says why it cannot load


def test_making_a_fetch_task_prints_nothing():  # MJX's notice on import where its Warp backend is absent
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    made = subprocess.run([sys.executable, "-c", "import envs; envs.make('push')"], cwd=repo, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert made.returncode == 0 and made.stdout == "", made.stdout + made.stderr


# ---- physics: one compiled program per task (conftest.FetchEpisodes) -------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_rests_without_drift_under_zero_action(fetch, name):
    s0, final, traj = _episodes(fetch, name, "rest")
    chex.assert_trees_all_equal_shapes_and_dtypes(final, s0)  # the step keeps every shape and dtype
    assert not bool(traj.invalid.any())
    drift = np.abs(np.asarray(traj.achieved_goal) - np.asarray(s0.achieved_goal)[None])
    assert drift.max() < 2e-3, drift.max()
    np.testing.assert_array_equal(traj.step[-1], fetch.T)
    assert np.abs(np.asarray(traj.obs[-1])[:, -5:]).max() < 1e-3  # velocities settle


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_restore_and_replay_is_bitwise_exact(fetch, name):
    T = fetch.T
    _, _, traj = _episodes(fetch, name, "random")
    acts = fetch.random_actions(1)
    saved = _at(traj, K - 1)  # the state after K steps
    replay = jnp.concatenate([acts[K:], acts[:K]])  # same length: same compiled program
    _, _, again = fetch.run(_env(name), replay, state=saved)
    first, second = _at(traj, slice(K, T)), _at(again, slice(0, T - K))
    jax.tree_util.tree_map(np.testing.assert_array_equal, first, second)
    assert not bool(traj.invalid.any())


@pytest.mark.slow
@pytest.mark.parametrize("name", ["push", "pick_and_place"])
def test_actions_are_clipped_and_observation_is_consistent(fetch, name):
    acts = fetch.random_actions(2) * 5.0
    _, _, clipped = fetch.run(_env(name), jnp.clip(acts, -1.0, 1.0))
    _, _, big = fetch.run(_env(name), acts)
    np.testing.assert_array_equal(clipped.obs, big.obs)
    # The gripper did move: random actions shift it from home.
    obs = np.asarray(big.obs)
    assert np.abs(obs[-1, :, 0:3] - obs[0, :, 0:3]).max() > 0.02
    np.testing.assert_allclose(obs[..., 6:9], obs[..., 3:6] - obs[..., 0:3], atol=1e-6)
    d = np.linalg.norm(np.asarray(big.achieved_goal - big.desired_goal), axis=-1)
    np.testing.assert_array_equal(big.reward, -(d >= 0.05).astype(np.float32))


@pytest.mark.slow
@pytest.mark.parametrize("name", ["reach", "push"])
def test_nan_action_is_flagged(fetch, name):
    acts = np.asarray(fetch.random_actions(3)).copy()
    acts[3, 1, 0] = np.nan
    _, _, traj = fetch.run(_env(name), acts)
    invalid = np.asarray(traj.invalid)
    assert not invalid[:, 0].any()  # the other episode is untouched
    assert not invalid[:3, 1].any() and invalid[3:, 1].all()  # flagged from the bad step on, and stays


@pytest.mark.slow
@pytest.mark.parametrize(("name", "need"), [("reach", 1.0), ("push", 0.75), ("pick_and_place", 0.75), ("slide", 0.75)])
def test_scripted_controllers_succeed_in_most_episodes(fetch, name, need):
    _, _, traj = _episodes(fetch, name, "scripted")
    reached = np.asarray(traj.success).any(axis=0)
    assert reached.mean() >= need, reached
    assert not bool(traj.invalid.any())


@pytest.mark.slow
def test_slide_gripper_driven_away_stops_on_the_arm_reach(fetch):
    acts = np.broadcast_to(np.array([1.0, 0.2, -1.0, 0.0]), (fetch.T, fetch.B, 4))
    _, _, traj = fetch.run(_env("slide"), acts)
    grip = np.asarray(traj.obs)[-1, :, 0:3]
    dist = np.linalg.norm(grip - np.asarray(control.ARM_REACH_CENTER["slide"]), axis=1)
    np.testing.assert_allclose(dist, control.ARM_REACH_RADIUS, atol=0.01)
    assert grip[:, 0].max() < 1.41  # the reference's gripper reaches x 1.39 at table height


@pytest.mark.slow
def test_weld_drive_in_mjx_follows_the_target_like_the_pd_drive(fetch):
    """The reference's weld law (a constraint to a mocap body that ``simulate`` puts at the target) moves
    the gripper along the same path as the PD drive does, to within 3 mm; a restored state replays
    bit for bit under it too (the mocap body follows the saved control)."""
    acts = np.broadcast_to(np.array([1.0, -0.5, 0.5, 0.0], np.float32), (fetch.T, fetch.B, 4))
    weld = envs.make("reach", drive="weld")
    _, _, traj = fetch.run(weld, acts)
    replay = fetch.run(weld, acts, state=_at(traj, 2))[2]  # from the state after step 3: steps 4 on
    jax.tree_util.tree_map(np.testing.assert_array_equal, _at(replay, slice(0, fetch.T - 3)), _at(traj, slice(3, None)))
    pd = np.asarray(fetch.run(_env("reach"), acts)[2].obs)[:6, :, 0:3]
    steps = np.linalg.norm(np.diff(pd, axis=0), axis=-1)
    assert steps.min() > 0.025  # both move 3 to 5 cm per step at full action
    np.testing.assert_allclose(np.asarray(traj.obs)[:6, :, 0:3], pd, atol=0.003)


@pytest.mark.slow
def test_struck_slide_puck_stays_flat_on_the_table(fetch):
    s0, _, traj = _episodes(fetch, "slide", "scripted")
    obs = np.asarray(traj.obs)
    assert np.abs(obs[..., 3:6] - np.asarray(s0.obs)[None, :, 3:6]).max() > 0.1  # the pucks were struck
    assert np.abs(obs[..., 11:13]).max() < 0.05  # roll and pitch: no tipping
    assert np.abs(obs[..., 5] - _env("slide").layout.object_rest_z).max() < 2e-3  # no lift


def test_grasped_starts_put_the_cube_between_the_fingers_and_evaluation_starts_standard():
    env = envs.make("pick_and_place", grasped_starts=1.0)
    lay = env.layout
    state = jax.jit(jax.vmap(env.reset))(jax.random.split(jax.random.PRNGKey(0), 16))  # one compile, not op by op
    obj, grip, fingers = state.obs[:, 3:6], state.obs[:, 0:3], state.obs[:, 9:11]
    np.testing.assert_allclose(obj - grip, np.tile([0.0, 0.0, tasks.GRASP_ABOVE_SITE], (16, 1)), atol=1e-6)
    np.testing.assert_allclose(fingers, models.OBJECT_HALF, atol=1e-6)  # inner faces on the cube's sides
    standard = env.evaluation_task()
    assert standard.grasped_starts == 0.0 and standard.layout == lay
    start = jax.jit(jax.vmap(standard.reset))(jax.random.split(jax.random.PRNGKey(0), 16))
    np.testing.assert_allclose(start.obs[:, 5], lay.object_rest_z, atol=1e-6)  # every cube on the table
    assert np.all(np.linalg.norm(start.obs[:, 3:5] - start.obs[:, 0:2], axis=-1) >= tasks.MIN_OBJECT_DISTANCE - 1e-6)


def test_grasped_starts_mix_by_share_and_need_free_fingers():
    env = envs.make("pick_and_place", grasped_starts=0.5)
    state = jax.jit(jax.vmap(env.reset))(jax.random.split(jax.random.PRNGKey(1), 400))
    held = np.asarray(state.obs[:, 5] > env.layout.object_rest_z + 0.05)
    assert 0.4 < held.mean() < 0.6
    assert envs.make("push").evaluation_task() == envs.make("push")
    with pytest.raises(InvalidConfig, match="grasped_starts"):
        envs.make("push", grasped_starts=0.5)
    with pytest.raises(InvalidConfig, match="grasped_starts"):
        envs.make("pick_and_place", grasped_starts=1.5)


def test_floor_clearance_raises_the_lowest_gripper_target():
    low = np.asarray(models.workspace_box("reach")[0])
    for clearance in (0.0, 0.01):
        env = envs.make("reach", floor_clearance=clearance)
        home = np.asarray(env.layout.grip_home)
        target = _target_after(env, [home[0], home[1], low[2] + 0.002], [0.0, 0.0, -1.0, 0.0])
        assert target[2] == pytest.approx(low[2] + clearance, abs=1e-6)


def _object_moved_away(physics, lay):
    return physics.replace(qpos=physics.qpos.at[..., lay.object_q : lay.object_q + 2].set(jnp.array([1.6, 0.4])))


def _pressed_paths(env, action, steps=6):
    """Grip positions [steps + 1, 3] under ``action`` held from the start (the object moved out of the way)."""
    state = env.reset(jax.random.PRNGKey(0))
    state = state.replace(physics=_object_moved_away(state.physics, env.layout))
    step = jax.jit(env.step)
    path = [np.asarray(state.obs[:3])]
    for _ in range(steps):
        state = step(state, jnp.asarray(action, jnp.float32))
        path.append(np.asarray(state.obs[:3]))
    return np.array(path)


def _pressed_paths_in_the_episode_program(fetch, env, actions, steps=6):
    """``_pressed_paths`` of each of ``actions`` [n, 4] at once, [n, steps + 1, 3], from the task's episode
    program (``fetch``)."""
    n = len(actions)
    state = fetch.reset(env)
    state = state.replace(physics=_object_moved_away(state.physics, env.layout))
    held = np.broadcast_to(np.resize(np.asarray(actions, np.float32), (fetch.B, 4)), (fetch.T, fetch.B, 4))
    after = np.asarray(fetch.run(env, held, state=state)[2].obs)[:steps, :n, :3]
    return np.concatenate([np.asarray(state.obs)[None, :n, :3], after]).swapaxes(0, 1)


@pytest.mark.slow
def test_finger_table_contact_drags_a_gripper_pressed_on_the_table(fetch):
    with_contact = envs.make("push", finger_table=1.0)
    assert envs.make("push") == with_contact  # Push's default: the episode program the tests above compiled
    free, pressed = _pressed_paths_in_the_episode_program(
        fetch, with_contact, [[0.0, 1.0, 0.0, 0.0], [0.0, 1.0, -1.0, 0.0]]
    )
    speed = lambda p: np.linalg.norm(np.diff(p[2:, :2], axis=0), axis=-1).mean()  # noqa: E731
    assert speed(pressed) < 0.7 * speed(free)  # the reference: 16 against 33 mm per step
    table_height = models.TABLE_TOP + models.REFERENCE_FINGER_BELOW_SITE
    assert pressed[:, 2].min() > table_height - 0.005  # the table, not the workspace floor, holds it
    # the library's Cholesky: the same physics to float rounding, in a step that compiles faster
    without = _pressed_paths(envs.make("push", finger_table=0.0, cholesky="library"), [0.0, 1.0, -1.0, 0.0])
    assert speed(without) == pytest.approx(speed(free), rel=0.05)  # no contact: pressing costs nothing
    assert without[-1, 2] < table_height - 0.005
