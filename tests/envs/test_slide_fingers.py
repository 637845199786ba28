"""Slide's finger options: the reference's box pads collide with the puck in MJX through the box-cylinder contact,
registered only while MJX builds and steps such a model, and the scripted strike succeeds with them."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from mujoco.mjx._src import collision_driver
from mujoco.mjx._src.types import GeomType

import envs
from envs.fetch import models, slide_fingers

# the Slide whose press matches the reference's (experiments/reference/results/slide-pads.md)
PADS = {"finger": "pads", "finger_table": 1.0, "drive": "weld", "gripper_mass": 22.0}


def test_pads_are_the_reference_pads_with_its_contact():
    m = models.build("slide", finger="pads", finger_table=1.0)[0]
    for name, center in zip(("pad_r", "pad_l"), slide_fingers.PAD_CENTERS, strict=True):
        g = m.geom(name)
        assert g.type[0] == mujoco.mjtGeom.mjGEOM_BOX
        np.testing.assert_allclose(g.size, slide_fingers.PAD_HALF)
        np.testing.assert_allclose(g.pos, center)
    puck = m.geom("object").id
    pairs = [i for i in range(m.npair) if puck in (m.pair_geom1[i], m.pair_geom2[i])
             and m.geom_type[m.pair_geom1[i] + m.pair_geom2[i] - puck] == mujoco.mjtGeom.mjGEOM_BOX]  # fmt: skip
    assert len(pairs) == 2
    for i in pairs:
        assert m.pair_dim[i] == 4 and m.pair_margin[i] == pytest.approx(0.001)
        np.testing.assert_allclose(m.pair_solref[i], (0.015, 1.0))
        np.testing.assert_allclose(m.pair_friction[i], (1, 1, 0.05, 0.01, 0.01))
    # the pads touch the table (finger_table) through MJX's own plane-box contact
    table = m.geom("table").id
    assert sum(table in (m.pair_geom1[i], m.pair_geom2[i]) for i in range(m.npair)) == 3


def test_the_box_cylinder_entry_lives_only_while_mjx_uses_it():
    models.build("slide", finger="pads", finger_table=1.0)  # put_model ran with the entry
    assert (GeomType.CYLINDER, GeomType.BOX) not in collision_driver._COLLISION_FUNC
    with pytest.raises(NotImplementedError):  # stock MJX has no such pair
        from mujoco import mjx

        mjx.put_model(models.build("slide", finger="pads", finger_table=1.0)[0])


def test_the_reference_pads_are_slides_default():
    task = envs.make("slide")
    assert (task.finger, task.finger_table, task.drive, task.gripper_mass) == ("pads", 1.0, "weld", 22.0)
    assert task.hand_pitch == 1.0 and task.settings()["hand_pitch"] == 1.0  # the reference hand's tilt, recorded
    names = {task.mj_model.geom(i).name for i in range(task.mj_model.ngeom)}
    assert {"pad_r", "pad_l"} <= names and not {"tip_0", "tip_3"} & names
    former = dict(finger="box", finger_table=0.0, drive="pd", gripper_mass=0.0, hand_pitch=0.0)
    m = envs.make("slide", **former).mj_model  # the former task
    assert {"tip_0", "tip_3"} <= {m.geom(i).name for i in range(m.ngeom)}


def test_gripper_mass_is_recorded_only_when_set():
    assert "gripper_mass" not in envs.make("push").settings()  # runs recorded before it still resume
    assert envs.make("slide").settings()["gripper_mass"] == 22.0
    assert models.build("slide", gripper_mass=22.0)[0].body("gripper").mass[0] == pytest.approx(22.0, abs=0.01)


@pytest.mark.slow
def test_scripted_strike_succeeds_with_the_reference_pads(fetch):
    env = envs.make("slide", **PADS)
    s0, _, traj = fetch.run(env, np.zeros((fetch.T, fetch.B, 4)), w=1.0)
    assert not bool(traj.invalid.any())
    reached = np.asarray(traj.success).any(axis=0)
    assert reached.mean() >= 0.75, reached  # 0.906 of 64 episodes (the reference: 0.965), see the results file
    obs = np.asarray(traj.obs)
    assert np.abs(obs[..., 3:5] - np.asarray(s0.obs)[None, :, 3:5]).max() > 0.1  # the pucks were struck
