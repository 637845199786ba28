"""Scripted Fetch controllers on synthetic observations: shapes, bounds, batching and phase choices."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from envs.fetch import scripted

Z = 0.425  # cube centre on the table


def make_obs(grip, obj=(1.3, 0.8, Z), fingers=(0.0, 0.0), obj_vel=(0.0, 0.0, 0.0), grip_vel=(0.0, 0.0, 0.0)):
    grip, obj = np.asarray(grip, float), np.asarray(obj, float)
    o = np.zeros(25, np.float32)
    o[0:3], o[3:6], o[6:9], o[9:11] = grip, obj, obj - grip, fingers
    o[14:17] = np.asarray(obj_vel) - np.asarray(grip_vel)
    o[20:23] = grip_vel
    return o


@pytest.mark.parametrize("name", sorted(scripted.CONTROLLERS))
def test_shape_bounds_numpy_jit_vmap(name):
    fn = scripted.CONTROLLERS[name]
    rng = np.random.default_rng(0)
    obs = rng.uniform(-2, 2, (64, 25)).astype(np.float32)
    obs[:, 3:6] = rng.uniform(0.3, 1.6, (64, 3))
    goal = rng.uniform(0.3, 1.6, (64, 3)).astype(np.float32)
    a_np = np.asarray(fn(obs[0], goal[0]))  # numpy in
    assert a_np.shape == (4,)
    batched = jax.jit(jax.vmap(fn))(jnp.asarray(obs), jnp.asarray(goal))
    broadcast = fn(obs, goal)  # leading batch dims broadcast without vmap
    assert batched.shape == broadcast.shape == (64, 4)
    np.testing.assert_allclose(batched, broadcast, atol=1e-6)
    np.testing.assert_allclose(batched[0], a_np, atol=1e-6)
    assert np.all(np.isfinite(batched)) and np.all(np.abs(batched) <= 1.0)


@pytest.mark.parametrize("name", sorted(scripted.CONTROLLERS))
def test_degenerate_inputs_stay_finite(name):
    obs = make_obs(grip=(1.3, 0.8, Z), obj=(1.3, 0.8, Z))  # gripper inside the object, goal on it
    a = np.asarray(scripted.CONTROLLERS[name](obs, obs[3:6]))
    assert np.all(np.isfinite(a)) and np.all(np.abs(a) <= 1.0)


def test_reach_heads_for_goal_and_saturates():
    a = np.asarray(scripted.reach(make_obs(grip=(1.3, 0.75, 0.5)), np.array([1.3 + 0.01, 0.75, 0.9])))
    np.testing.assert_allclose(a, [0.2, 0.0, 1.0, 0.0], atol=1e-5)


def test_push_rises_before_crossing_over_the_cube():
    # Gripper low, on the goal side of the cube: it must not sweep through it, so it rises first.
    obs = make_obs(grip=(1.36, 0.8, 0.417))
    a = np.asarray(scripted.push(obs, np.array([1.45, 0.8, Z])))
    assert a[2] > 0.5 and np.allclose(a[:2], 0.0, atol=1e-6)


def test_push_descends_when_lined_up_then_pushes_toward_goal():
    goal = np.array([1.45, 0.8, Z])
    above = make_obs(grip=(1.3 - scripted.CONTACT_OFFSET, 0.8, Z + scripted.CLEARANCE))
    a = np.asarray(scripted.push(above, goal))
    assert a[2] < -0.5 and abs(a[0]) < 0.2
    low = make_obs(grip=(1.3 - scripted.CONTACT_OFFSET, 0.8, Z))
    a = np.asarray(scripted.push(low, goal))
    assert a[0] > 0.5 and abs(a[1]) < 1e-3 and abs(a[2]) < 0.2
    assert a[3] == -1.0


def test_push_holds_when_cube_is_on_goal():
    obs = make_obs(grip=(1.24, 0.8, Z))
    np.testing.assert_allclose(np.asarray(scripted.push(obs, obs[3:6]))[:3], 0.0)


def test_pick_and_place_phases():
    goal = np.array([1.2, 0.7, 0.7])
    far = make_obs(grip=(1.2, 0.7, 0.55), fingers=(0.05, 0.05))
    a = np.asarray(scripted.pick_and_place(far, goal))
    assert a[3] == 1.0 and a[0] > 0.5  # open, travel toward the cube
    above_closed = make_obs(grip=(1.3, 0.8, Z + 0.07), fingers=(0.0, 0.0))
    a = np.asarray(scripted.pick_and_place(above_closed, goal))
    assert a[3] == 1.0 and np.allclose(a[:3], 0.0)  # wait there until open
    above_open = make_obs(grip=(1.3, 0.8, Z + 0.07), fingers=(0.05, 0.05))
    a = np.asarray(scripted.pick_and_place(above_open, goal))
    assert a[3] == 1.0 and a[2] < -0.5  # descend
    at_open = make_obs(grip=(1.3, 0.8, Z), fingers=(0.05, 0.05))
    a = np.asarray(scripted.pick_and_place(at_open, goal))
    assert a[3] == -1.0 and np.allclose(a[:3], 0.0)  # close
    holding = make_obs(grip=(1.3, 0.8, Z), fingers=(0.024, 0.024))
    a = np.asarray(scripted.pick_and_place(holding, goal))
    assert a[3] == -1.0 and a[0] < -0.5 and a[2] > 0.5  # carry toward the goal


def _glide(v, decel):
    """Forward model of ``launch_velocity``: per-axis (pyramidal) friction, integrated in closed form."""
    vx, vy = abs(v[0]), abs(v[1])
    big, small = max(vx, vy), min(vx, vy)
    x, y = (big * big + small * small) / (2 * decel), big * small / decel
    d = np.array([x, y]) if vx >= vy else np.array([y, x])
    return d * np.sign(v)


def test_launch_velocity_inverts_the_glide():
    rng = np.random.default_rng(1)
    for _ in range(50):
        disp = rng.uniform(-0.8, 0.8, 2)
        v = np.asarray(scripted.launch_velocity(jnp.asarray(disp, jnp.float32), 0.981))
        np.testing.assert_allclose(_glide(v, 0.981), disp, atol=2e-4)
        assert np.dot(v, disp) > 0


def test_slide_aims_corner_and_holds_while_puck_is_fast_enough():
    goal = np.array([1.6, 0.75, 0.42])
    puck = (1.0, 0.75, 0.42)
    corner = scripted.FINGER_HALF_XY[0]
    # Lined up low behind the puck, in contact: push along +x.
    grip = (1.0 - scripted.PUCK_RADIUS - 0.005 - corner, 0.75 - scripted.FINGER_HALF_XY[1], 0.42)
    a = np.asarray(scripted.slide(make_obs(grip=grip, obj=puck), goal))
    assert a[0] > 0.5 and abs(a[2]) < 0.3
    # Same, but the puck already glides faster than needed: hold still.
    fast = make_obs(grip=grip, obj=puck, obj_vel=(0.05, 0.0, 0.0))
    a = np.asarray(scripted.slide(fast, goal))
    assert abs(a[0]) < 0.1


def test_slide_repush_variant_aims_short_and_trails_a_gliding_puck():
    goal = np.array([1.6, 0.75, 0.42])
    puck = (1.0, 0.75, 0.42)
    corner = scripted.FINGER_HALF_XY
    grip = (1.0 - scripted.PUCK_RADIUS - 0.005 - corner[0], 0.75 - corner[1], 0.42)
    # In contact, with the puck at 0.95 of the flick's launch speed: the flick pushes, a launch aimed
    # 10 % short (speed x 0.949) already has what it needs and holds still.
    v = float(np.linalg.norm(scripted.launch_velocity(jnp.asarray(goal[:2] - puck[:2]), 0.981)))
    moving = make_obs(grip=grip, obj=puck, obj_vel=(0.95 * v * scripted.DT, 0.0, 0.0))
    assert np.asarray(scripted.slide(moving, goal))[0] > 0.5
    assert abs(np.asarray(scripted.slide(moving, goal, aim_short=0.1))[0]) < 0.1
    # 5.5 cm behind a puck gliding at 0.5 m/s: the flick closes in at approach speed, the trailing
    # gripper keeps up (2 cm per step) and closes the gap to trail_gap (2.5 cm more).
    far = (grip[0] - 0.05, grip[1], 0.42)
    gliding = make_obs(grip=far, obj=puck, obj_vel=(0.02, 0.0, 0.0))
    flick = np.asarray(scripted.slide(gliding, goal))[0] * scripted.MAX_STEP
    trail = np.asarray(scripted.slide(gliding, goal, trail_gap=0.03))[0] * scripted.MAX_STEP
    assert flick == pytest.approx(0.2 * scripted.DT, abs=1e-5)
    assert trail == pytest.approx(0.055 - 0.03 + 0.02, abs=1e-5)
