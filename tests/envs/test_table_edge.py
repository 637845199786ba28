"""Slide's table top ending at the reference table's edges (``table="edged"``): the model's extent and floor, and
the puck-table contacts kept, moved onto the edge or dropped."""

from __future__ import annotations

import jax.numpy as jnp
import mujoco
import numpy as np
import pytest
from mujoco import mjx
from mujoco.mjx._src import collision_driver
from mujoco.mjx._src.types import GeomType

from envs.fetch import models, table_edge

KEY = (GeomType.PLANE, GeomType.CYLINDER)
OPTIONS = dict(finger="pads", finger_table=1.0, drive="weld", hand_pitch=1.0)


def _contacts(x: float, tilt: float = 0.0, z: float = 0.42):
    """MJX's own and the edged puck-table contacts (dist [3], pos [3, 3]) for the puck's centre at ``x`` (y 0.75,
    height ``z``: resting at 0.42), turned ``tilt`` radians about +y."""
    m = models.build("slide", table="edged", **OPTIONS)[0]
    d = mujoco.MjData(m)
    o = m.joint("object").qposadr[0]
    quat = np.zeros(4)
    mujoco.mju_axisAngle2Quat(quat, np.array([0.0, 1.0, 0.0]), tilt)
    d.qpos[o : o + 7] = (x, 0.75, z, *quat)
    mujoco.mj_kinematics(m, d)
    with models.own_contacts(m):
        mx, dx = mjx.put_model(m), mjx.put_data(m, d)
    geom = jnp.asarray([[m.geom("table").id, m.geom("object").id]])
    own = collision_driver._COLLISION_FUNC[KEY](mx, dx, KEY, geom)
    edged = table_edge.wrap(m, {})[KEY](mx, dx, KEY, geom)
    return [np.asarray(x) for x in own[:2]], [np.asarray(x) for x in edged[:2]]


def test_the_edged_table_carries_the_reference_tables_extent_and_the_floor_under_it():
    m = models.build("slide", table="edged", **OPTIONS)[0]
    assert table_edge.extent_of(m) == pytest.approx((0.695, 1.945, 0.30, 1.20))  # FetchSlide-v4's table0
    name = lambda g: m.geom(int(g)).name  # noqa: E731
    pairs = {tuple(sorted((name(m.pair_geom1[i]), name(m.pair_geom2[i])))) for i in range(m.npair)}
    assert ("floor", "object") in pairs and ("object", "table") in pairs
    plain = models.build("slide", **OPTIONS)[0]
    assert table_edge.extent_of(plain) is None and table_edge.wrap(plain, {}) == {}


def test_a_puck_well_on_the_table_keeps_mjxs_own_contacts():
    (dist, pos), (edist, epos) = _contacts(1.5, tilt=0.02)
    np.testing.assert_array_equal(edist, dist)
    np.testing.assert_array_equal(epos, pos)


def test_a_puck_pressed_deep_into_the_table_well_inside_keeps_its_support():
    (dist, pos), (edist, epos) = _contacts(1.5, tilt=0.02, z=0.41)  # 10 mm into the top, as a hard press can drive it
    assert np.all(dist < -table_edge.BELOW_TOP)
    np.testing.assert_array_equal(edist, dist)
    np.testing.assert_array_equal(epos, pos)


def test_a_puck_over_the_edge_is_held_up_to_the_edge_at_its_bottom_faces_depth():
    (dist, pos), (edist, epos) = _contacts(1.93)  # centre 15 mm inside, one rim point 10 mm past the edge
    past = pos[:, 0] > 1.945
    assert past.sum() == 1
    assert epos[past, 0] == pytest.approx(1.945) and edist[past] == pytest.approx(dist[past], abs=1e-6)  # flat
    np.testing.assert_array_equal(epos[~past], pos[~past])
    (dist, pos), (edist, epos) = _contacts(1.93, tilt=0.05)  # dipped forward: the rim past the edge lies deeper
    past = pos[:, 0] > 1.945
    shift = 1.945 - pos[past, 0]
    assert edist[past] == pytest.approx(dist[past] - np.tan(0.05) * shift, abs=2e-5)  # shallower at the edge
    assert edist[past] > dist[past]


def test_a_puck_past_the_edge_loses_the_table():
    (dist, _), (edist, _) = _contacts(1.975)  # the whole bottom face past the edge
    assert np.all(dist < 1e-3) and np.all(edist == table_edge.APART)
    _, (edist, epos) = _contacts(1.96)  # centre past the edge: only the point straight ahead still lies under it
    kept = edist < table_edge.APART
    assert kept.sum() == 1 and epos[kept, 0] == pytest.approx(1.945)


def test_on_the_edged_table_a_puck_past_the_edge_falls_to_the_floor_and_one_inside_stays():
    import jax

    import envs

    env = envs.make("slide", table="edged")
    o, step = env.layout.object_q, jax.jit(env.step)
    start = env.reset(jax.random.PRNGKey(0))
    ends = []
    for x in (1.93, 1.96):  # the centre 15 mm inside the edge (x 1.945), 15 mm past it
        qpos = start.physics.qpos.at[o : o + 2].set(jnp.array([x, 0.75]))
        s = env._state(start.physics.replace(qpos=qpos), start.desired_goal, jnp.int32(0), jnp.bool_(False))
        for _ in range(15):
            s = step(s, jnp.zeros(4))
        ends.append(np.asarray(s.physics.qpos[o : o + 3]))
    np.testing.assert_allclose(ends[0], (1.93, 0.75, env.layout.object_rest_z), atol=2e-3)
    assert ends[1][2] < 0.1  # on the floor, 0.4 m below the top
