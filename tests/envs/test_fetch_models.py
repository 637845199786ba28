"""The Fetch tasks' MuJoCo models, stepped by MuJoCo's C simulator (no MJX program compiled): contact pairs,
tables and fingers, the gripper's drives, and the Euler angles of the observation."""

from __future__ import annotations

import jax.numpy as jnp
import mujoco
import numpy as np
import pytest

import envs
from envs.fetch import models, rotations, scripted


def test_euler_angles_match_the_rotation():
    a, b, c = 0.3, -0.5, 1.1
    half = lambda axis, t: jnp.concatenate([jnp.cos(t / 2)[None], jnp.sin(t / 2) * jnp.asarray(axis)])  # noqa: E731

    def mul(p, q):
        w1, v1, w2, v2 = p[0], p[1:], q[0], q[1:]
        return jnp.concatenate([(w1 * w2 - v1 @ v2)[None], w1 * v2 + w2 * v1 + jnp.cross(v1, v2)])

    q = mul(mul(half([1.0, 0, 0], a), half([0, 1.0, 0], b)), half([0, 0, 1.0], c))  # R = Rx Ry Rz
    np.testing.assert_allclose(rotations.quat_to_euler(q), [a, b, c], atol=1e-5)


def _pairs(m: mujoco.MjModel) -> set[tuple[str, str]]:
    name = lambda i: m.geom(int(i)).name  # noqa: E731
    return {tuple(sorted((name(a), name(b)))) for a, b in zip(m.pair_geom1, m.pair_geom2, strict=True)}


def test_model_has_only_listed_contact_pairs():
    for kind in models.KINDS:
        m = models.build(kind)[0]
        assert not m.geom_contype.any() and not m.geom_conaffinity.any()
        assert m.npair == {"reach": 0, "push": 2, "slide": 5, "pick_and_place": 3}[kind]


@pytest.mark.parametrize("kind", ["push", "pick_and_place"])
def test_table_top_is_a_plane_by_default_and_the_box_table_adds_the_floor(kind):
    plane, box = models.build(kind)[0], models.build(kind, table="box")[0]
    assert plane.geom("table").type[0] == mujoco.mjtGeom.mjGEOM_PLANE and plane.geom("table").pos[2] == models.TABLE_TOP
    assert box.geom("table").type[0] == mujoco.mjtGeom.mjGEOM_BOX
    assert _pairs(box) - _pairs(plane) == {("floor", "object")}
    # the object rests at the same height on either table
    assert abs(models.build(kind)[2].object_rest_z - models.build(kind, table="box")[2].object_rest_z) < 1e-3


def test_push_capsule_finger_replaces_the_box_in_the_same_pair():
    box, capsule = models.build("push")[0], models.build("push", finger="capsule")[0]
    assert box.geom("fingers").type[0] == mujoco.mjtGeom.mjGEOM_BOX
    assert capsule.geom("fingers").type[0] == mujoco.mjtGeom.mjGEOM_CAPSULE
    assert _pairs(capsule) == _pairs(box) and ("fingers", "object") in _pairs(box)
    # same centre and half-height (radius + half-length), so the fingertips reach as low as the block's
    np.testing.assert_allclose(capsule.geom("fingers").pos, box.geom("fingers").pos)
    np.testing.assert_allclose(capsule.geom("fingers").size[0] + capsule.geom("fingers").size[1], 0.03)


def _cube_moved_by_a_resting_gripper(finger: str, ahead: float) -> float:
    """How far the cube moves in 0.2 s when put ``ahead`` m in front of the grip (x), the gripper held still."""
    m, _, layout = models.build("push", finger=finger)
    d = mujoco.MjData(m)
    o, rest = layout.object_q, layout.object_rest_z
    start = m.body("gripper").pos[:2] + [ahead, 0.0]
    d.qpos[o : o + 3] = [*start, rest]
    for _ in range(50):
        mujoco.mj_step(m, d)
    return float(np.linalg.norm(d.qpos[o : o + 2] - start))


def test_push_pads_finger_is_the_reference_pads_extent_and_meets_the_cube_first():
    m = models.build("push", finger="pads")[0]
    np.testing.assert_allclose(m.geom("fingers").size[:2], models.PADS_HALF_XY)
    assert envs.make("push").finger == "pads"
    # the cube 1 mm clear of the smaller box's face but inside the pads' face (and its contact margin)
    ahead = models.OBJECT_HALF + 0.011
    assert _cube_moved_by_a_resting_gripper("box", ahead) < 1e-4
    assert _cube_moved_by_a_resting_gripper("pads", ahead) > 1e-3


def test_slide_puck_is_a_cylinder_on_a_plane_struck_at_the_controller_corner():
    m = models.build("slide")[0]
    puck, table = m.geom("object"), m.geom("table")
    assert puck.type[0] == mujoco.mjtGeom.mjGEOM_CYLINDER
    np.testing.assert_allclose(puck.size[:2], [0.025, 0.02])
    assert table.type[0] == mujoco.mjtGeom.mjGEOM_PLANE and table.pos[2] == models.TABLE_TOP
    pairs = _pairs(m)
    assert ("floor", "object") not in pairs and ("object", "table") in pairs
    # The controller aims the fingers' corner at the puck: the round tips sit there.
    tips = [m.geom(f"tip_{i}") for i in range(4)]
    corners = sorted((abs(float(t.pos[0])), abs(float(t.pos[1]))) for t in tips)
    assert corners == [tuple(scripted.FINGER_HALF_XY)] * 4


def _grip_speed_after_jump(xml, ms=8.0, jump=0.045):
    """Grip x speed ``ms`` after the drive's target jumps ``jump`` ahead of a gripper at rest (MuJoCo C)."""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    g = m.joint("grip_x").qposadr[0]
    d.ctrl[0:3] = d.qpos[g : g + 3] + [jump, 0.0, 0.0]
    for _ in range(int(round(ms / 1000 / m.opt.timestep))):
        mujoco.mj_step(m, d)
    return float(d.qvel[g])


def test_drive_options_set_how_fast_the_gripper_follows_and_reject_nonpositive_values():
    default = models.mjcf("slide", 0.004, 10, 4)
    assert models.mjcf("slide", 0.004, 10, 4, gripper_mass=13.0, drive_omega=50.0, drive_damping_ratio=1.0) == default
    base = _grip_speed_after_jump(default)
    assert _grip_speed_after_jump(models.mjcf("slide", 0.004, 10, 4, drive_omega=70.0)) > 1.2 * base
    assert _grip_speed_after_jump(models.mjcf("slide", 0.004, 10, 4, drive_damping_ratio=1.5)) < 0.9 * base
    # gains scale with the mass (the drawn fingers' few grams aside), so a heavier gripper follows alike
    np.testing.assert_allclose(
        _grip_speed_after_jump(models.mjcf("slide", 0.004, 10, 4, gripper_mass=20.0)), base, rtol=1e-3
    )
    # the same damping as the actuators' explicit velocity feedback lets the gripper start faster
    assert _grip_speed_after_jump(models.mjcf("slide", 0.004, 10, 4, drive_damping="actuator")) > 1.1 * base
    for field, bad in (
        ("gripper_mass", 0.0),
        ("drive_omega", 0.0),
        ("drive_damping_ratio", 0.0),
        ("drive_damping", "tendon"),
        ("drive", "spring"),
    ):
        with pytest.raises(ValueError, match=field):
            models.mjcf("slide", **{field: bad})


def _grip_height_driven_down(xml: str, target_z: float) -> float:
    """The grip site's height after 0.5 s of its drive pulling it down towards ``target_z`` (MuJoCo C)."""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    g = m.joint("grip_x").qposadr[0]
    mujoco.mj_forward(m, d)
    d.ctrl[0:3] = [d.qpos[g], d.qpos[g + 1], target_z - m.body("gripper").pos[2]]  # joint coordinates
    for _ in range(int(round(0.5 / m.opt.timestep))):
        mujoco.mj_step(m, d)
    return float(d.site("grip").xpos[2])


def test_slide_fingers_with_a_table_contact_stop_on_the_table_at_the_reference_fingertips_depth():
    floor = models.workspace_box("slide", 1.0)[0][2]  # the press below the fingertips-on-the-table height
    stopped = _grip_height_driven_down(models.mjcf("slide", 0.002, 10, 4, finger_table=1.0), floor)
    assert abs(stopped - (models.TABLE_TOP + models.REFERENCE_FINGER_BELOW_SITE)) < 0.003, stopped
    # without the contact nothing meets the table: the gripper goes where its drive sends it
    glides = _grip_height_driven_down(models.mjcf("slide", 0.002, 10, 4), floor)
    assert glides < stopped - 0.015, glides


def test_weld_drive_pulls_the_gripper_onto_its_mocap_target():
    m = mujoco.MjModel.from_xml_string(models.mjcf("slide", 0.002, 10, 4, drive="weld"))
    d = mujoco.MjData(m)
    g = m.joint("grip_x").qposadr[0]
    d.ctrl[0:3] = [0.05, -0.03, 0.02]  # the PD drive's input: ignored by this drive
    for _ in range(50):
        mujoco.mj_step(m, d)
    np.testing.assert_allclose(d.qpos[g : g + 3], 0.0, atol=1e-3)
    d.mocap_pos[0] = np.asarray(models._SCENES["slide"][2]) + [0.05, -0.03, 0.02]
    for _ in range(250):  # 0.5 s: ten time constants of the constraint
        mujoco.mj_step(m, d)
    np.testing.assert_allclose(d.qpos[g : g + 3], [0.05, -0.03, 0.02], atol=1e-3)


@pytest.mark.parametrize("drive, fastest", [("reference", 1.0), ("fast", None)])
def test_pick_and_place_fingers_close_as_slowly_as_the_references(drive, fastest):
    """The reference's finger joints carry an armature of 100 and a damping of 1000: they take about 0.1 s to
    close and never move at 1 m/s; the fast drive's shut within one control step at several m/s."""
    m = mujoco.MjModel.from_xml_string(models.mjcf("pick_and_place", 0.004, 4, 4, finger_drive=drive))
    d = mujoco.MjData(m)
    q, v = m.joint("finger_l").qposadr[0], m.joint("finger_l").dofadr[0]
    d.qpos[[q, q + 1]] = 0.05  # open
    d.ctrl[3:5] = 0.0  # close
    speeds, path = [], []
    for _ in range(75):  # 0.3 s
        mujoco.mj_step(m, d)
        speeds.append(abs(d.qvel[v]))
        path.append(d.qpos[q])
    first_step = path[9]  # after one 40 ms control step
    if fastest is None:
        assert first_step < 0.005 and max(speeds) > 3.0
    else:
        assert first_step > 0.03 and max(speeds) < fastest
        assert path[-1] < 0.005  # yet it does close
