"""The box-cylinder contact against MuJoCo C's on fixed configurations of a reference finger pad and Slide's puck.

Tolerances: depths 2e-5 m (float32 arithmetic on centimetre geoms), normals 0.01 and points 0.5 mm where MuJoCo
C's convex collider finds the same feature (it meets the disc's edge on a polygon, up to 0.4 mm inside the circle);
where the box's face rests on the cap within ``SNAP`` of parallel, ours pushes along the face's normal, as MuJoCo
C's mostly does (its convex collider returns the cap's or the face's, by a small margin either way): normals within
the tilt, depths per point. Where a box's vertical edge presses the side wall, MuJoCo C's normal is the box's face
normal and its depth 0.2 mm shallower than the exact least penetration, and at other yaws the normal is even
perpendicular to the penetration (its native collider; libccd, its other, finds the penetration): there ours is
checked against the exact minimum over 20,000 sampled directions, and against libccd on random edges pressing the
wall (normals within 4 degrees, depths within 0.3 mm, never deeper).
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
import pytest

from envs.box_cylinder import _separation, box_cylinder

PAD = (0.0135, 0.007, 0.0385)  # a reference finger pad's half sizes
PUCK = (0.025, 0.02)
MARGIN = 0.001


def _mujoco(box_pos, box_euler=(0, 0, 0), cyl_euler=(0, 0, 0), libccd=False, box_axisangle=None):
    """MuJoCo C's contacts (dist, pos, normal) and the geoms' poses, for the pad at ``box_pos`` near the puck; by its
    native convex collider (its default), or by libccd."""
    turn = (f'axisangle="{" ".join(map(str, box_axisangle))}"' if box_axisangle is not None
            else f'euler="{" ".join(map(str, box_euler))}"')  # fmt: skip
    xml = f"""<mujoco><compiler angle="radian"/><option gravity="0 0 0"/><worldbody>
      <body euler="{' '.join(map(str, cyl_euler))}"><freejoint/>
        <geom name="puck" type="cylinder" size="{PUCK[0]} {PUCK[1]}" contype="0" conaffinity="0"/></body>
      <body pos="{' '.join(map(str, box_pos))}" {turn}><freejoint/>
        <geom name="pad" type="box" size="{' '.join(map(str, PAD))}" contype="0" conaffinity="0"/></body>
    </worldbody><contact><pair geom1="pad" geom2="puck" margin="{MARGIN}" condim="4"/></contact></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    if libccd:
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_NATIVECCD)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    c = d.contact[: d.ncon]
    poses = [(d.geom_xpos[g].copy(), d.geom_xmat[g].reshape(3, 3).copy(), m.geom_size[g].copy()) for g in (0, 1)]
    return (np.array([x.dist for x in c]), np.array([x.pos for x in c]).reshape(-1, 3),
            np.array([x.frame[:3] for x in c]).reshape(-1, 3), poses)  # fmt: skip


@functools.cache
def _ours():
    return jax.jit(box_cylinder)


def _contacts(poses):
    (cp, cm, cs), (bp, bm, bs) = poses
    dist, pos, frame = _ours()(*(jnp.asarray(x, jnp.float32) for x in (cp, cm, cs[:2], bp, bm, bs)))
    live = np.asarray(dist) < MARGIN
    return np.asarray(dist)[live], np.asarray(pos)[live], np.asarray(frame)[live, 0]


def _matched(points, others, tol):
    """Whether every point has one of ``others`` within ``tol`` (m)."""
    return all(np.min(np.linalg.norm(others - p, axis=1)) < tol for p in points)


SAME_FEATURE = {  # (box position, box euler): MuJoCo C and ours meet the same features
    "above the top face": ((0.0, 0.0, 0.0565), (0, 0, 0)),
    "pressing the rim": ((-0.02, 0.0, 0.0555), (0, 0, 0)),
    "overhanging the rim": ((-0.03, 0.0, 0.0575), (0, 0, 0)),
    "touching the side": ((0.037, 0.0, 0.0), (0, 0, 0)),
    "corner on the edge": ((0.02, 0.02, 0.055), (0, 0, 0.5)),
}


@pytest.mark.parametrize("name", SAME_FEATURE)
def test_same_contacts_as_mujoco_c(name):
    box_pos, euler = SAME_FEATURE[name]
    c_dist, c_pos, c_normal, poses = _mujoco(box_pos, euler)
    dist, pos, normal = _contacts(poses)
    assert len(c_dist) >= 2 and len(dist) >= len(c_dist) - 1, (c_dist, dist)
    np.testing.assert_allclose(np.sort(dist), np.sort(c_dist)[: len(dist)] if len(dist) < len(c_dist) else
                               np.sort(c_dist), atol=2e-5)  # fmt: skip
    np.testing.assert_allclose(normal, np.broadcast_to(c_normal[0], normal.shape), atol=0.01)
    assert _matched(pos, c_pos, 5e-4) and _matched(c_pos[: len(pos)], pos, 5e-4), (pos, c_pos)


def test_tilted_box_on_the_top_face():
    c_dist, c_pos, c_normal, poses = _mujoco((0.0, 0.0, 0.058), (0.05, 0.03, 0.0))
    dist, pos, normal = _contacts(poses)
    assert len(dist) == len(c_dist) == 4
    order = [int(np.argmin(np.linalg.norm(c_pos - p, axis=1))) for p in pos]
    np.testing.assert_allclose(dist, c_dist[order], atol=2e-5)
    np.testing.assert_allclose(pos, c_pos[order], atol=5e-4)
    assert np.all(normal @ c_normal[0] > np.cos(0.06))


@pytest.mark.parametrize("degrees", (10, 20, 30))
def test_pitched_pad_edge_on_the_top_face_as_mujoco_c(degrees):
    """Slide's pads pitched as the reference hand at stretch (``hand_pitch``) press the cap with an edge: the cap's
    normal and the edge's depth, as MuJoCo C's."""
    t = np.radians(degrees)
    low = PAD[2] * np.cos(t) + PAD[0] * np.sin(t)  # the turned box's lowest edge below its centre
    for x in (0.0, 0.01):
        c_dist, c_pos, c_normal, poses = _mujoco((x, 0.0, PUCK[1] + low - 5e-4), (0, t, 0))
        dist, pos, normal = _contacts(poses)
        assert len(dist) >= 1 and len(c_dist) >= 1
        np.testing.assert_allclose(normal, np.broadcast_to(c_normal[0], normal.shape), atol=0.01)
        np.testing.assert_allclose(dist, c_dist[0], atol=2e-5)
        # on the edge's line; where along it each puts its one point is its own choice
        np.testing.assert_allclose(pos[:, [0, 2]], np.broadcast_to(c_pos[0, [0, 2]], (len(pos), 2)), atol=5e-4)
        assert np.all(np.abs(pos[:, 1]) <= PAD[1]) and np.all(np.abs(c_pos[:, 1]) <= PAD[1])


def test_tilted_puck_under_a_level_box():
    c_dist, c_pos, c_normal, poses = _mujoco((0.0, 0.0, 0.0575), cyl_euler=(0.1, 0, 0))
    dist, pos, normal = _contacts(poses)
    assert np.min(dist) == pytest.approx(np.min(c_dist), abs=2e-5)
    # MuJoCo C's normal is the cap's here, the box face's at other tilts; ours is the face's: within the tilt
    assert normal[0] @ c_normal[0] > np.cos(0.1 + 1e-3)
    np.testing.assert_allclose(normal[0], poses[1][1][:, 2], atol=1e-6)
    # past C's face-face angle, one point midway along the deepest edge, as MuJoCo C
    assert len(dist) == len(c_dist) == 1 and np.linalg.norm(pos[0] - c_pos[0]) < 1e-3


def test_edge_against_the_side_is_the_least_penetration():
    c_dist, c_pos, _, poses = _mujoco((0.036, 0.01, 0.03), (0, 0, 0.7))
    dist, pos, normal = _contacts(poses)
    assert len(dist) == len(c_dist) == 2 and _matched(pos, c_pos, 5e-4)
    (cp, cm, _), (bp, bm, bs) = poses
    dirs = np.random.default_rng(0).normal(size=(20000, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    seps = np.asarray(_separation(jnp.asarray(dirs), jnp.asarray(cm.T @ (bp - cp)), jnp.asarray(cm.T @ bm),
                                  jnp.asarray(bs), PUCK[0], PUCK[1]))  # fmt: skip
    assert np.min(dist) == pytest.approx(seps.max(), abs=1e-4) and np.min(dist) >= seps.max() - 1e-6
    assert normal[0] @ (cm @ dirs[np.argmax(seps)]) > np.cos(0.1)


def test_apart_no_contact():
    c_dist, _, _, poses = _mujoco((0.0, 0.0, 0.06))  # 1.5 mm above the top face, beyond the margin
    dist, _, _ = _contacts(poses)
    assert len(c_dist) == 0 and len(dist) == 0


def test_edges_against_the_side_as_libccd():
    rng = np.random.default_rng(1)
    R2 = lambda a: np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])  # noqa: E731
    for _ in range(8):
        yaw, toward = rng.uniform(0, np.pi / 2), rng.uniform(0, 2 * np.pi)
        u = np.array([np.cos(toward), np.sin(toward)])
        corners = np.array([[sx, sy] for sx in (-1, 1) for sy in (-1, 1)]) * np.array(PAD[:2]) @ R2(yaw).T
        center = u * (PUCK[0] - rng.uniform(0.0005, 0.003)) - corners[np.argmin(corners @ u)]
        c_dist, _, c_normal, poses = _mujoco((*center, rng.uniform(0.0, 0.04)), (0, 0, yaw), libccd=True)
        dist, _, normal = _contacts(poses)
        assert normal[0] @ c_normal[0] > np.cos(np.radians(4.0)), (normal[0], c_normal[0])
        assert np.min(c_dist) - 1e-5 <= np.min(dist) <= np.min(c_dist) + 3e-4


TILTED_UNDER_A_PAD = {  # (pad centre in the puck's frame, tilt in degrees): a pad sunk near the rim of a tilted puck
    "cap, 7 deg": ((-0.0163, -0.0158, 0.0492), 7),
    "edge across the rim, 12 deg": ((-0.0163, -0.0158, 0.0492), 12),
    "edge across the rim, 16 deg": ((-0.0163, -0.0158, 0.0492), 16),
    "edge across the rim, 25 deg": ((-0.0163, -0.0158, 0.0492), 25),
    "nearer the rim, 9 deg": ((-0.0153, -0.0221, 0.0497), 9),
    "nearer the rim, 16 deg": ((-0.0153, -0.0221, 0.0497), 16),
}


@pytest.mark.parametrize("name", TILTED_UNDER_A_PAD)
def test_pad_on_a_tilted_puck_as_mujoco_c(name):
    """Where the pads turned the puck over: past C's face-face angle one point, and where a pad's edge crosses the rim
    the least penetration between the candidates (C's EPA finds it), not the tilted cap's normal."""
    centre, tilt = TILTED_UNDER_A_PAD[name]
    axis = np.array([-0.1, 0.122, 0.0]) / np.hypot(0.1, 0.122)
    c_dist, c_pos, c_normal, poses = _mujoco(centre, box_axisangle=(*axis, np.radians(tilt)))
    dist, pos, normal = _contacts(poses)
    assert len(dist) == len(c_dist) == 1, (dist, c_dist)
    assert dist[0] == pytest.approx(c_dist[0], abs=1e-4)
    assert normal[0] @ c_normal[0] > np.cos(0.12), (normal, c_normal)
    assert np.linalg.norm(pos[0] - c_pos[0]) < 2.5e-3
