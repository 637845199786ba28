"""Slide's pads pitched as the reference arm stretches: the tilt's size and direction, the contacts computed on the
turned pads, and the option's reach (Slide's pads alone)."""

from __future__ import annotations

import jax.numpy as jnp
import mujoco
import numpy as np
import pytest
from mujoco import mjx
from mujoco.mjx._src.types import GeomType

import envs
from envs import box_cylinder
from envs.fetch import hand_pitch, models
from envs.fetch.control import ARM_REACH_CENTER
from envs.settings import InvalidConfig

CENTER = np.asarray(ARM_REACH_CENTER["slide"])


def _hand_at(reach: float, heading: float, height: float = 0.42) -> np.ndarray:
    """The pads' centre whose grip lies ``reach`` from the reach centre, at table height, ``heading`` radians off +x."""
    dz = height - CENTER[2]
    flat = np.sqrt(reach**2 - dz**2)
    grip = CENTER + np.array([flat * np.cos(heading), flat * np.sin(heading), dz])
    return grip + np.array([0.0, 0.0, hand_pitch.GRIP_BELOW_HAND])


@pytest.mark.parametrize("heading", [0.0, 0.4])
def test_the_fingertips_swing_out_away_from_the_robot_by_the_reference_tilt(heading):
    for reach, tilt in ((0.78, 0.9), (0.9625, 11.0), (1.0625, 33.8)):
        r = np.asarray(hand_pitch.rotation(jnp.asarray(_hand_at(reach, heading)), 1.0))
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-6)
        down = r @ np.array([0.0, 0.0, -1.0])
        assert np.degrees(np.arccos(-down[2])) == pytest.approx(tilt, abs=0.3)
        radial = np.array([np.cos(heading), np.sin(heading)])
        np.testing.assert_allclose(down[:2], np.sin(np.radians(tilt)) * radial, atol=3e-3)  # out, not sideways
    half = np.asarray(hand_pitch.rotation(jnp.asarray(_hand_at(1.0625, heading)), 0.5)) @ np.array([0.0, 0.0, -1.0])
    assert np.degrees(np.arccos(-half[2])) == pytest.approx(33.8 / 2, abs=0.3)
    np.testing.assert_allclose(hand_pitch.rotation(jnp.asarray(_hand_at(1.0625, heading)), 0.0), np.eye(3), atol=1e-7)


def test_the_pads_lean_the_way_the_reference_fingers_do_at_stretch():
    """FetchSlide-v4 driven out to its arm's reach: its fingers' tips (the grip site) lie out from their centres
    along the radial direction, and our pads turned for that grip lean the same way, by about the same angle."""
    pytest.importorskip("gymnasium_robotics")
    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_shift

    ref = make_reference("slide")
    ref.reset(seed=0)
    for _ in range(10):
        ref.step(np.array([1.0, 0.0, 0.0, 0.0]))
    m, d = ref.unwrapped.model, ref.unwrapped.data
    grip = d.site_xpos[m.site("robot0:grip").id] - reference_shift(envs.make("slide"), ref)
    fingers = [m.geom(f"robot0:{s}_gripper_finger_link").id for s in "rl"]
    tip = d.site_xpos[m.site("robot0:grip").id] - d.geom_xpos[fingers].mean(axis=0)  # centre to tips
    ref.close()
    radial = (grip - CENTER)[:2] / np.linalg.norm((grip - CENTER)[:2])
    theirs = np.degrees(np.arctan2(tip[:2] @ radial, -tip[2]))
    down = np.asarray(hand_pitch.rotation(jnp.asarray(grip + [0.0, 0.0, hand_pitch.GRIP_BELOW_HAND]), 1.0))[:, 2] * -1
    ours = np.degrees(np.arctan2(down[:2] @ radial, -down[2]))
    assert theirs > 5.0  # out, at a reach where the lean is several degrees
    assert ours == pytest.approx(theirs, abs=4.0)


def test_the_puck_meets_the_turned_pads():
    m = models.build("slide", finger="pads", finger_table=1.0, drive="weld", hand_pitch=1.0)[0]
    assert hand_pitch.scale_of(m) == 1.0
    d = mujoco.MjData(m)
    grip = _hand_at(1.0, 0.0) - np.array([0.0, 0.0, hand_pitch.GRIP_BELOW_HAND])
    d.qpos[m.joint("grip_x").qposadr[0] : m.joint("grip_x").qposadr[0] + 3] = grip - m.body("gripper").pos
    obj = m.joint("object").qposadr[0]
    d.qpos[obj : obj + 3] = grip + np.array([0.0, 0.0, -0.023])  # the reference's press: pads 1.55 cm into the top
    mujoco.mj_kinematics(m, d)
    with models.own_contacts(m):
        mx, dx = mjx.put_model(m), mjx.put_data(m, d)
        groups = hand_pitch.wrap(m, box_cylinder.groups_for(m))
    key = (GeomType.CYLINDER, GeomType.BOX)
    pads, puck = [m.geom(n).id for n in hand_pitch.PADS], m.geom("object").id
    geom = jnp.asarray([[puck, p] for p in pads])
    dist, pos, frame = groups[key](mx, dx, key, geom)
    # the same pads turned here about their centre by the reference's tilt at its grip's reach (about 18.5 degrees
    # at 1.0 m), their bottoms toward +x
    centre = d.geom_xpos[pads].mean(axis=0)
    reach = np.linalg.norm(centre - [0.0, 0.0, hand_pitch.GRIP_BELOW_HAND] - CENTER)
    quat, tilt = np.zeros(4), np.radians(np.interp(reach, hand_pitch.REACH, hand_pitch.TILT))
    mujoco.mju_axisAngle2Quat(quat, np.array([0.0, 1.0, 0.0]), -tilt)
    turn = np.zeros(9)
    mujoco.mju_quat2Mat(turn, quat)
    turn = turn.reshape(3, 3)
    want = [box_cylinder.box_cylinder(*(jnp.asarray(x, jnp.float32) for x in (
        d.geom_xpos[puck], d.geom_xmat[puck].reshape(3, 3), m.geom_size[puck, :2],
        centre + turn @ (d.geom_xpos[p] - centre), turn @ d.geom_xmat[p].reshape(3, 3), m.geom_size[p])))
        for p in pads]  # fmt: skip
    np.testing.assert_allclose(dist, np.concatenate([w[0] for w in want]), atol=2e-6)
    np.testing.assert_allclose(pos, np.concatenate([w[1] for w in want]), atol=2e-6)
    np.testing.assert_allclose(frame, np.concatenate([w[2] for w in want]), atol=2e-6)
    upright = box_cylinder.groups_for(m)[key](mx, dx, key, geom)[0]
    assert not np.allclose(dist, upright, atol=1e-4)  # the turn changes the contact
    plane_box = (GeomType.PLANE, GeomType.BOX)
    assert plane_box in groups and plane_box not in box_cylinder.groups_for(m)  # the pads meet the table turned too


def test_only_slides_pads_pitch():
    assert envs.make("slide", hand_pitch=0.5).hand_pitch == 0.5
    for kind, options in (("slide", {"finger": "box"}), ("push", {}), ("slide", {"hand_pitch": 3.0})):
        with pytest.raises(InvalidConfig, match="hand_pitch"):
            envs.make(kind, **{"hand_pitch": 1.0, **options})
    m = models.build("slide", finger="pads", finger_table=1.0)[0]
    groups = box_cylinder.groups_for(m)
    assert hand_pitch.scale_of(m) == 0.0 and hand_pitch.wrap(m, groups) is groups
