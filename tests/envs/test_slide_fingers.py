"""Slide's finger options: the reference's box pads collide with the puck in MJX through the box-cylinder contact,
registered only while MJX builds and steps such a model, and the scripted strike succeeds with them."""

from __future__ import annotations

import jax.numpy as jnp
import mujoco
import numpy as np
import pytest
from mujoco.mjx._src import collision_driver
from mujoco.mjx._src.types import GeomType

import envs
from envs.fetch import models, slide_fingers
from tests.envs.test_box_cylinder import _ours as box_cylinder_program  # its compiled program, shared

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


def test_round_tips_stay_the_default():
    assert envs.make("slide").finger == "box"
    m = models.build("slide")[0]
    names = {m.geom(i).name for i in range(m.ngeom)}
    assert {"tip_0", "tip_3"} <= names and not {"pad_r", "pad_l"} & names


def test_gripper_mass_is_recorded_only_when_set():
    assert "gripper_mass" not in envs.make("slide").settings()  # runs recorded before it still resume
    assert envs.make("slide", gripper_mass=22.0).settings()["gripper_mass"] == 22.0
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


def test_pad_friction_sets_the_pads_pairs_alone_and_needs_the_pads():
    m = envs.make("slide", finger="pads", pad_friction=0.2)
    assert m.settings()["pad_friction"] == 0.2 and "pad_friction" not in envs.make("slide", finger="pads").settings()
    pads = [i for i in range(m.mj_model.npair) if m.mj_model.geom(m.mj_model.pair_geom1[i]).name.startswith("pad_")]
    assert len(pads) == 2 and np.allclose(m.mj_model.pair_friction[pads, :2], 0.2)
    with pytest.raises(ValueError, match="pad_friction"):
        envs.make("slide", pad_friction=0.2)  # the round tips have no pads
    with pytest.raises(ValueError, match="pad_friction"):
        envs.make("push", finger="pads", pad_friction=0.2)  # Push's pads are its finger block, not Slide's pairs


def _capped(top):
    return mujoco.MjModel.from_xml_string(models.mjcf("slide", pad_top_friction=top, **PADS))


def test_pad_top_friction_caps_the_puck_with_pairs_of_its_own():
    assert models.mjcf("slide", **PADS) == models.mjcf("slide", pad_top_friction=None, **PADS)  # off: as before
    plain, m = mujoco.MjModel.from_xml_string(models.mjcf("slide", **PADS)), _capped(0.1)
    # the puck moves as the uncapped one: its mass, inertia, height and side
    for key in ("mass", "inertia", "ipos"):
        np.testing.assert_allclose(getattr(m.body("object"), key), getattr(plain.body("object"), key), atol=1e-12)
    body, cap, whole = m.geom("object"), m.geom("object_top"), plain.geom("object")
    assert body.pos[2] - body.size[1] == pytest.approx(-whole.size[1])
    assert cap.pos[2] + cap.size[1] == pytest.approx(whole.size[1])
    assert body.pos[2] + body.size[1] == pytest.approx(cap.pos[2] - cap.size[1])
    assert body.size[0] == whole.size[0] and cap.size[0] == pytest.approx(whole.size[0] - slide_fingers.CAP_INSET)
    pairs = {(m.geom(m.pair_geom1[i]).name, m.geom(m.pair_geom2[i]).name): i for i in range(m.npair)}
    for pad in ("pad_r", "pad_l"):
        assert m.pair_friction[pairs[pad, "object"], 0] == 1.0 and m.pair_friction[pairs[pad, "object_top"], 0] == 0.1
        np.testing.assert_array_equal(m.pair_margin[pairs[pad, "object_top"]], m.pair_margin[pairs[pad, "object"]])
        np.testing.assert_array_equal(m.pair_solref[pairs[pad, "object_top"]], m.pair_solref[pairs[pad, "object"]])
    table = m.pair_friction[[pairs["table", "object_top"], pairs["table", "object"]]]
    np.testing.assert_array_equal(table[0], table[1])
    assert "object_top" not in {plain.geom(i).name for i in range(plain.ngeom)}


def test_pad_top_friction_is_recorded_when_set_and_needs_slides_pads():
    task = envs.make("slide", finger="pads", pad_top_friction=0.2)
    assert task.settings()["pad_top_friction"] == 0.2 and task.model_options()["pad_top_friction"] == 0.2
    assert "pad_top_friction" not in envs.make("slide", finger="pads").settings()
    refused = [("slide", "box", 0.2), ("push", "pads", 0.2), ("slide", "pads", 0.0), ("slide", "pads", "low")]
    for kind, finger, top in refused:  # the round tips and Push's block have no such pairs; out of (0, 2]
        with pytest.raises(ValueError, match="pad_top_friction"):
            envs.make(kind, finger=finger, pad_top_friction=top)


def _live(m, name, pad_pos):
    """Our box-cylinder contact's depths within the pads' margin of a level pad at ``pad_pos`` (the puck's frame, the
    puck upright at the origin) against the puck's geom ``name``."""
    g, eye = m.geom(name), np.eye(3, dtype=np.float32)
    args = (g.pos, eye, g.size[:2], pad_pos, eye, slide_fingers.PAD_HALF)
    dist = np.asarray(box_cylinder_program()(*(jnp.asarray(x, jnp.float32) for x in args))[0])
    return dist[dist < m.pair_margin[_pair(m, "pad_r", name)]]


def _pair(m, g1, g2):
    return next(i for i in range(m.npair) if (m.geom(m.pair_geom1[i]).name, m.geom(m.pair_geom2[i]).name) == (g1, g2))


def test_a_press_meets_the_cap_alone_and_a_strike_the_side_alone():
    m = _capped(0.2)
    hx, _, hz = slide_fingers.PAD_HALF
    top = m.geom("object_top").pos[2] + m.geom("object_top").size[1]
    for x in (0.0, -0.02):  # pressed 2.5 mm into the top face, over the centre and over the rim
        pad = (x, 0.0, top + hz - 0.0025)
        assert len(_live(m, "object_top", pad)) and not len(_live(m, "object", pad)), x
    # struck: a pad's face 1 mm into the side wall, over the whole height of the puck
    pad = (-(m.geom("object").size[0] + hx - 0.001), 0.0, 0.01)
    assert len(_live(m, "object", pad)) and not len(_live(m, "object_top", pad))
