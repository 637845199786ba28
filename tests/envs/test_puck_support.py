"""MuJoCo C's puck support (``envs/puck_support.py``, Slide's ``puck_support=polygon``) against MuJoCo C's own
contacts between FetchSlide's puck (a cylinder) and its table (a box), on fixed poses of the puck.

What must agree everywhere: the number of points, that they are corners of the cap's 16-gon, the first of them
(the clipped polygon's first vertex, from which the search starts), each shared corner's depth, and the single
lowest rim point once the puck tilts past ``FACE_TOL``. Which four corners the search keeps is decided by rounding
where quadrilaterals tie in area (a regular 16-gon, or its image under a tilt, has many), in float64 in MuJoCo C
and in float32 here: over 360 flat yaws the four agree at 140 (39 %), at yaw 0 over eight places on the table at 2
(at ``XY`` C keeps the corners at 0, 90, 157.5 and 270 degrees, ours those at 67.5, 157.5, 247.5 and 337.5), on the
12 tilted poses at 10. Both choose among the same quadrilaterals, the same two commonest: as steps on from the first
corner, (0, 4, 8, 12) and (0, 3, 7, 11) (C: 161 and 156 of the 360 yaws, ours 126 and 181). On polygons without
ties the search keeps exactly the corners a plain transcription of C's loops keeps.
"""

from __future__ import annotations

import collections
import functools

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
import pytest

from envs import puck_support
from envs.fetch import models

TABLE_POS, TABLE_HALF = (1.32441906, 0.75018422, 0.2), (0.625, 0.45, 0.2)  # FetchSlide-v4's table0
PUCK = (0.025, 0.02)
XY = (1.1, 0.7)
_RNG = np.random.default_rng(0)
FLAT = [(yaw, 0.0, 0.0, 1e-4, XY) for yaw in np.radians(np.arange(0, 360, 1.0))]
YAW0 = [(0.0, 0.0, 0.0, 1e-4, xy) for xy in zip(_RNG.uniform(1.0, 1.6, 8), _RNG.uniform(0.5, 1.0, 8), strict=True)]
TILTED = [(yaw, tilt, axis, depth, XY) for yaw, tilt, axis, depth in zip(
    _RNG.uniform(0, 2 * np.pi, 12), _RNG.uniform(0.005, 0.085, 12), _RNG.uniform(0, 2 * np.pi, 12),
    _RNG.uniform(5e-4, 2e-3, 12), strict=True)]  # fmt: skip
STEEP = [(1.0, tilt, 2.0, 1e-3, XY) for tilt in (0.095, 0.2, 0.6, 1.2)]
POSES = FLAT + YAW0 + TILTED + STEEP


@functools.cache
def _mujoco():
    """Per pose: the puck's position and orientation, and MuJoCo C's contacts (pos, dist) with the table."""
    xml = f"""<mujoco><worldbody>
      <geom type="box" pos="{' '.join(map(str, TABLE_POS))}" size="{' '.join(map(str, TABLE_HALF))}"/>
      <body><freejoint/><geom type="cylinder" size="{PUCK[0]} {PUCK[1]}"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    out = []
    for yaw, tilt, axis, depth, xy in POSES:
        q, turn, tip = np.zeros(4), [np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)], np.zeros(4)
        mujoco.mju_axisAngle2Quat(tip, [-np.sin(axis), np.cos(axis), 0.0], tilt)
        mujoco.mju_mulQuat(q, tip, turn)
        mat = np.zeros(9)
        mujoco.mju_quat2Mat(mat, q)
        mat = mat.reshape(3, 3)
        low = PUCK[1] * abs(mat[2, 2]) + PUCK[0] * np.hypot(mat[2, 0], mat[2, 1])  # the lowest rim point's height
        d.qpos[:7] = [*xy, 2 * TABLE_HALF[2] - depth + low, *q]
        mujoco.mj_forward(m, d)
        c = d.contact[: d.ncon]
        out.append((d.xpos[1].copy(), mat, np.array([x.pos for x in c]), np.array([x.dist for x in c])))
    return out


@functools.cache
def _ours():
    """Our contacts for every pose (one compiled program): the points in use, their positions and depths."""
    c = _mujoco()
    f = jax.vmap(puck_support.plane_cylinder, in_axes=(None, None, None, 0, 0, None))
    plane = (jnp.array([*TABLE_POS[:2], 2 * TABLE_HALF[2]]), jnp.eye(3), jnp.array([*TABLE_HALF[:2], 0.1]))
    pos, mat = (jnp.asarray(np.array([x[i] for x in c]), jnp.float32) for i in (0, 1))
    dist, at, _ = jax.jit(f)(*plane, pos, mat, jnp.asarray(PUCK))
    dist, at = np.asarray(dist), np.asarray(at)
    return [(at[k][dist[k] < 0.5], dist[k][dist[k] < 0.5]) for k in range(len(POSES))]


def _angles(center, mat, points):
    """Each point's angle round the puck's axis in the puck's frame (degrees in [0, 360))."""
    local = (np.asarray(points) - center) @ mat
    return np.degrees(np.arctan2(local[:, 1], local[:, 0])) % 360


def _pairs(which):
    """(MuJoCo C's angles and depths, ours) per pose of ``which``."""
    c, o = _mujoco(), _ours()
    ks = [POSES.index(p) for p in which]
    return [((_angles(c[k][0], c[k][1], c[k][2]), c[k][3]), (_angles(c[k][0], c[k][1], o[k][0]), o[k][1])) for k in ks]


def _same(a, b):
    return len(a) == len(b) and np.allclose(np.round(a / 22.5) % 16, np.round(b / 22.5) % 16)


def test_four_corners_of_the_16gon_starting_where_mujoco_c_starts():
    for (ca, _), (oa, _) in _pairs(FLAT + YAW0 + TILTED):
        assert len(oa) == len(ca) == 4
        steps = oa / 22.5
        np.testing.assert_allclose(steps, np.round(steps), atol=0.01)  # corners of the cap's 16-gon
    flat = _pairs(FLAT + YAW0)
    assert all(_same(ca[:1], oa[:1]) for (ca, _), (oa, _) in flat)
    for (_, cd), (_, od) in flat:  # flat: every corner as deep as the puck
        np.testing.assert_allclose(od, cd, atol=2e-6)
    tilted = _pairs(TILTED)
    assert sum(_same(ca[:1], oa[:1]) for (ca, _), (oa, _) in tilted) >= 10  # 12 of 12; 95 % of 500 random poses


def test_shared_corners_are_as_deep_and_the_quadrilaterals_are_those_mujoco_c_picks():
    for (ca, cd), (oa, od) in _pairs(TILTED):
        shared = [(i, j) for i in range(4) for j in range(4) if _same(ca[i : i + 1], oa[j : j + 1])]
        assert shared
        for i, j in shared:
            assert od[j] == pytest.approx(cd[i], abs=2e-6)
    flat = _pairs(FLAT)
    agree = sum(_same(ca, oa) for (ca, _), (oa, _) in flat)
    assert 0.25 * len(flat) <= agree < len(flat)  # 140 of 360: rounding decides ties, float32 here, float64 in C

    def shapes(which):  # the corners as steps on from the first, as the list runs (clockwise seen from above)
        return collections.Counter(tuple(sorted(np.round((a[0] - a) / 22.5).astype(int) % 16)) for a in which)

    ours, theirs = shapes([oa for _, (oa, _) in flat]), shapes([ca for (ca, _), _ in flat])
    commonest = {(0, 4, 8, 12), (0, 3, 7, 11)}
    assert {s for s, _ in ours.most_common(2)} == {s for s, _ in theirs.most_common(2)} == commonest
    assert sum(ours[s] for s in theirs) >= 0.98 * len(flat)  # all but a rare one (0, 4, 7, 12) among C's

def test_past_the_face_tolerance_the_lowest_rim_point_alone():
    for (ca, cd), (oa, od) in _pairs(STEEP):
        assert len(ca) == len(oa) == 1
        assert abs((oa[0] - ca[0] + 180) % 360 - 180) < 1.0  # C's on its polygonal support, ours on the circle
        assert od[0] == pytest.approx(cd[0], abs=2e-6)


def test_the_option_reaches_the_model_and_stays_slides():
    m = mujoco.MjModel.from_xml_string(models.mjcf("slide", puck_support="polygon"))
    assert puck_support.support(m) == "polygon"
    assert list(models.own_groups(m).values()) == [puck_support.plane_cylinder_group]
    m = mujoco.MjModel.from_xml_string(models.mjcf("slide"))
    assert puck_support.support(m) == "mjx" and not models.own_groups(m)
    with pytest.raises(ValueError, match="Slide's alone"):
        models.mjcf("push", puck_support="polygon")
    models.build("slide", puck_support="polygon")  # put_model ran with the entry, MJX's own is back
    from mujoco.mjx._src import collision_driver
    from mujoco.mjx._src.types import GeomType

    mjx_own = collision_driver._COLLISION_FUNC[(GeomType.PLANE, GeomType.CYLINDER)]
    assert mjx_own is not puck_support.plane_cylinder_group


def _greedy_quad(poly):
    """C's search as plain loops (the oracle): for each vertex a, advance the fourth corner while the area grows,
    after each advance the third and then the second likewise; a tie does not advance."""
    n = len(poly)

    def area(i, j, k, m):
        return 0.5 * np.linalg.norm(np.cross(poly[i] - poly[k], poly[j] - poly[m]))

    b, c, d = 1, 2, 3
    res, best = (0, 1, 2, 3), area(0, 1, 2, 3)
    for a in range(n):
        while area(a, b, c, (d + 1) % n) > best:
            d = (d + 1) % n
            res, best = (a, b, c, d), area(a, b, c, d)
            while area(a, b, (c + 1) % n, d) > best:
                c = (c + 1) % n
                res, best = (a, b, c, d), area(a, b, c, d)
            while area(a, (b + 1) % n, c, d) > best:
                b = (b + 1) % n
                res, best = (a, b, c, d), area(a, b, c, d)
        if b == a:
            b = (b + 1) % n
            if c == b:
                c = (c + 1) % n
                if d == c:
                    d = (d + 1) % n
    return res


def test_the_search_is_cs_greedy_one_on_polygons_without_ties():
    rng = np.random.default_rng(1)
    polys, counts = np.zeros((40, puck_support.MAXV, 3), np.float32), []
    for k in range(40):  # convex polygons, irregular enough that no two candidate areas tie
        n = int(rng.integers(5, 21))
        angles = np.sort(rng.uniform(0, 2 * np.pi, n))[::-1]
        radii = rng.uniform(0.02, 0.03)
        polys[k, :n] = np.stack([radii * np.cos(angles) * rng.uniform(0.5, 1), radii * np.sin(angles), 0 * angles], 1)
        counts.append(n)
    ours = np.asarray(jax.jit(jax.vmap(puck_support._quad))(jnp.asarray(polys), jnp.asarray(counts, jnp.int32)))
    for k, n in enumerate(counts):
        assert tuple(ours[k]) == _greedy_quad(polys[k, :n].astype(np.float64)), (k, n)
