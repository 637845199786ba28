"""Box-cylinder contacts for MJX, which has none: up to four contacts per pair, as MJX's collision functions return
them (dist [4], pos [4, 3], frame [4, 3, 3]; an unused contact has dist 1, which no margin reaches).

Why: the reference's Fetch fingers are boxes and FetchSlide's puck a cylinder; MuJoCo C collides them (its general
convex collider, one normal per pair and up to four points on the shapes' touching features), MJX does not. This
module does the same in closed form, so a Slide can strike and press the puck with the reference's finger pads.
MuJoCo C has two such colliders, which disagree here: on the cap this module gives its native collider's (the
default) face contacts, at the side wall the exact penetration as libccd does, where the native one often returns a
box face's normal (``tests/envs/test_box_cylinder.py`` checks both).

How: in the cylinder's frame, the normal is the separating-axis candidate of least penetration among the cap's
axis, the box's three axes, the horizontal directions from the cylinder's axis to the box's corners and to the
points of its edges nearest that axis, the directions from the rim to each corner and those across each edge and
the rim's tangent; the best of each of three groups is refined by a pattern search on the sphere and the best kept,
so that where a box edge crosses a tilted puck's rim the normal is the least penetration, as MuJoCo C's EPA finds
it, not the tilted cap's axis (which levers the puck over). A normal within ``SNAP`` of the
axis selects the cap, within ``SNAP`` of horizontal the side wall, so a box face on a slightly tilted puck (or float
rounding in its tilt) keeps a face contact rather than a point, pushing along the box face's normal. The contact
points then follow the feature of the cylinder that the normal selects: on a cap, the corners of the box's face
that faces it, clipped to the disc along the face's edges, each at its own depth, while the face lies within
``FACE`` of the cap (C's face-face contact), else the deepest alone; on the side wall, the wall's
vertical segment clipped to the box's extent along it (two points); on the rim, the rim point (one).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

NCON = 4
UNUSED = 1.0  # dist of a contact slot that holds no contact
SNAP = 0.1  # rad: a normal this close to the cylinder's axis is the cap's, this close to horizontal the wall's
FACE = 0.0889  # rad: a box face within this of the cap gives face points (MuJoCo C switches between 0.0875 and 0.09)
REFINE_STEPS = 12  # pattern-search steps on the normal (the step halves to 0.25 / 2**12 rad at the least)
_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], np.float64)  # corners
_EDGES = np.array([(i, j) for i in range(8) for j in range(i + 1, 8) if np.abs(_SIGNS[i] - _SIGNS[j]).sum() == 2])
# each face (axis, side) as its four corners in cyclic order
_FACES = np.zeros((3, 2, 4), np.int32)
for _a in range(3):
    _b, _c = (_a + 1) % 3, (_a + 2) % 3
    for _side, _s in enumerate((-1, 1)):
        for _k, (_u, _v) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
            _corner = np.zeros(3)
            _corner[[_a, _b, _c]] = (_s, _u, _v)
            _FACES[_a, _side, _k] = int(np.flatnonzero((_SIGNS == _corner).all(axis=1))[0])


def _unit(v, fallback):
    n = jnp.linalg.norm(v, axis=-1, keepdims=True)
    return jnp.where(n > 1e-12, v / jnp.where(n > 1e-12, n, 1.0), fallback)


def _flat(v):
    """Horizontal unit directions of ``v`` [..., 3] (x axis where ``v`` is vertical)."""
    h = v * jnp.array([1.0, 1.0, 0.0])
    return _unit(h, jnp.array([1.0, 0.0, 0.0]))


def _separation(n, center, axes, size, radius, half):
    """Signed separation along unit normals ``n`` [k, 3] (from the cylinder to the box) of the box (centre, axes as
    columns, half sizes) from the cylinder (radius, half height), in the cylinder's frame."""
    box_low = n @ center - jnp.abs(n @ axes) @ size
    cyl_high = half * jnp.abs(n[:, 2]) + radius * jnp.linalg.norm(n[:, :2], axis=-1)
    return box_low - cyl_high


def _edge_nearest_axis(corners):
    """The point of each box edge [12, 3] whose horizontal distance to the cylinder's axis is least."""
    a, b = corners[_EDGES[:, 0]], corners[_EDGES[:, 1]]
    d = (b - a)[:, :2]
    dd = jnp.sum(d * d, axis=-1)
    t = jnp.clip(-jnp.sum(a[:, :2] * d, axis=-1) / jnp.where(dd > 1e-12, dd, 1.0), 0.0, 1.0)
    return a + t[:, None] * (b - a)


def _edge_rim(center, corners, radius, half):
    """Directions across each box edge and the rim's tangent where the edge passes nearest the axis, on the cap the
    edge's end lies nearer to (12 per rim side): where an edge crosses the rim of a tilted puck the least penetration
    lies near them."""
    a, b = corners[_EDGES[:, 0]], corners[_EDGES[:, 1]]
    p = _edge_nearest_axis(corners)
    u = _flat(p)
    t = jnp.stack([-u[:, 1], u[:, 0], jnp.zeros_like(u[:, 0])], axis=1)
    n = _unit(jnp.cross(b - a, t), u)
    rim = u * radius + jnp.array([0.0, 0.0, 1.0]) * half * jnp.where(p[:, 2:] >= 0, 1.0, -1.0)
    return n * jnp.where(jnp.sum(n * (p - rim), axis=1, keepdims=True) >= 0, 1.0, -1.0)


def _candidates(center, axes, corners, radius, half):
    """Candidate normals in three groups ([k, 3] each; each pointing from the cylinder towards the box): the cap's
    axis and the box's axes; horizontal directions to corners and edges; rim-to-corner and edge-across-rim
    directions."""
    cap = jnp.array([[0.0, 0.0, 1.0]]) * jnp.where(center[2] >= 0, 1.0, -1.0)
    box = axes.T * jnp.where(axes.T @ center >= 0, 1.0, -1.0)[:, None]
    radial = _flat(jnp.concatenate([center[None], corners, _edge_nearest_axis(corners)]))
    rim = jnp.concatenate([_flat(corners)[:, :2] * radius, half * jnp.where(corners[:, 2:] >= 0, 1.0, -1.0)], axis=1)
    to_corner = _unit(corners - rim, radial[1:9])
    return jnp.concatenate([cap, box]), radial, jnp.concatenate([to_corner, _edge_rim(center, corners, radius, half)])


def _refine(n, sep, center, axes, size, radius, half):
    """The best candidate ``n`` (with its separation ``sep``) improved by a pattern search on the sphere: eight
    directions round it, the step halved where none separates more. Where a box edge crosses the rim of a tilted
    puck, the least penetration lies between the candidates (MuJoCo C's EPA finds it there); a normal that follows
    the puck's tilt there instead pushes the rim down along the tilted axis and turns the puck over."""
    ring = np.array([[np.cos(a), np.sin(a)] for a in np.arange(8) * np.pi / 4])

    def body(_, carry):
        n, sep, h = carry
        e = jnp.where(jnp.abs(n[0]) < 0.9, jnp.array([1.0, 0.0, 0.0]), jnp.array([0.0, 1.0, 0.0]))
        a = _unit(jnp.cross(n, e), e)
        b = jnp.cross(n, a)
        dirs = _unit(n + h * (jnp.asarray(ring[:, :1]) * a + jnp.asarray(ring[:, 1:]) * b), n)
        s = _separation(dirs, center, axes, size, radius, half)
        j = jnp.argmax(s)
        better = s[j] > sep
        return jnp.where(better, dirs[j], n), jnp.where(better, s[j], sep), jnp.where(better, h, 0.5 * h)

    n, sep, _ = jax.lax.fori_loop(0, REFINE_STEPS, body, (n, sep, jnp.asarray(0.25, n.dtype)))
    return n, sep


def _clip_to_disc(face, radius):
    """The face's corners [4, 3] (cyclic) moved onto the disc of ``radius`` (in xy) along an edge where outside:
    toward the next corner, else the previous; with whether each lies on the disc."""

    def entry(p, q):  # the first t in [0, 1] where p + t (q - p) meets the circle, from outside
        d = (q - p)[:2]
        a, b, c = jnp.dot(d, d), 2.0 * jnp.dot(p[:2], d), jnp.dot(p[:2], p[:2]) - radius**2
        disc = b * b - 4.0 * a * c
        t = (-b - jnp.sqrt(jnp.maximum(disc, 0.0))) / (2.0 * jnp.where(a > 1e-12, a, 1.0))
        ok = (disc >= 0.0) & (a > 1e-12) & (t >= 0.0) & (t <= 1.0)
        return p + t * (q - p), ok

    nxt, prv = jnp.roll(face, -1, axis=0), jnp.roll(face, 1, axis=0)
    pn, okn = jax.vmap(entry)(face, nxt)
    pp, okp = jax.vmap(entry)(face, prv)
    inside = jnp.sum(face[:, :2] ** 2, axis=-1) <= radius**2
    moved = jnp.where(okn[:, None], pn, pp)
    pts = jnp.where(inside[:, None], face, moved)
    return pts, inside | okn | okp


def _make_frame(n):
    """MJX's ``math.make_frame``: rows normal, tangent, bitangent."""
    from mujoco.mjx._src import math as mjx_math

    return mjx_math.make_frame(n)


def box_cylinder(cyl_pos, cyl_mat, cyl_size, box_pos, box_mat, box_size):
    """(dist [4], pos [4, 3], frame [4, 3, 3]) of a cylinder (geom 1: pos [3], mat [3, 3], size: radius, half
    height) against a box (geom 2: pos, mat, half sizes): normals point from the cylinder to the box, a contact's
    position is midway between the surfaces and its dist negative in penetration, as in MJX and MuJoCo C."""
    radius, half = cyl_size[0], cyl_size[1]
    center = cyl_mat.T @ (box_pos - cyl_pos)
    axes = cyl_mat.T @ box_mat  # the box's axes as columns, in the cylinder's frame
    corners = center + (jnp.asarray(_SIGNS, center.dtype) * box_size) @ axes.T
    # each group's best candidate refined, the best of them kept: the least penetration can sit in a different basin
    # from the best candidate's (a box edge across a tilted puck's rim against the cap's axis)
    seeds = []
    for normals in _candidates(center, axes, corners, radius, half):
        seps = _separation(normals, center, axes, box_size, radius, half)
        seeds.append((normals[jnp.argmax(seps)], jnp.max(seps)))
    ns, ss = jax.vmap(lambda n, s: _refine(n, s, center, axes, box_size, radius, half))(
        jnp.stack([n for n, _ in seeds]), jnp.stack([s for _, s in seeds]))
    n, sep = ns[jnp.argmax(ss)], jnp.max(ss)
    # within SNAP of the axis the cap faces the box, within SNAP of horizontal the side wall: a box face resting on a
    # slightly tilted puck keeps its four points (MuJoCo C's multi-point contact does too)
    is_cap = jnp.abs(n[2]) >= np.cos(SNAP)
    is_side = jnp.abs(n[2]) <= np.sin(SNAP)
    u = _flat(n[None])[0]
    # the box's face that faces the cylinder along n
    along = axes.T @ n
    face_axis = jnp.argmax(jnp.abs(along))
    side = jnp.where(along[face_axis] > 0, 0, 1)  # the face whose outward normal opposes n
    face = corners[jnp.asarray(_FACES)[face_axis, side]]
    # on a cap: the face's corners clipped to the disc, each at its own depth
    cap_sign = jnp.where(n[2] >= 0, 1.0, -1.0)
    on_disc, cap_ok = _clip_to_disc(face, radius)
    cap_dist = cap_sign * on_disc[:, 2] - half
    cap_pos = on_disc - jnp.array([0.0, 0.0, 1.0]) * cap_sign * 0.5 * cap_dist[:, None]
    # on the side wall: its vertical segment (at the normal's horizontal direction u) clipped to the box's z extent
    depth = corners @ n
    deep = depth <= jnp.min(depth) + 2.0 * SNAP * jnp.max(box_size)  # the box's feature facing the wall
    z_lo = jnp.maximum(-half, jnp.min(jnp.where(deep, corners[:, 2], jnp.inf)))
    z_hi = jnp.minimum(half, jnp.max(jnp.where(deep, corners[:, 2], -jnp.inf)))
    wall = jnp.stack([radius * u + jnp.array([0.0, 0.0, 1.0]) * z for z in (z_lo, z_hi)])
    side_pos = jnp.concatenate([wall, wall]) + 0.5 * sep * n
    side_ok = jnp.array([True, False, False, False]) | (jnp.arange(4) == 1) & (z_hi - z_lo > 1e-6)
    # on the rim: the rim point
    rim = radius * u + jnp.array([0.0, 0.0, 1.0]) * half * cap_sign
    rim_pos = jnp.broadcast_to(rim + 0.5 * sep * n, (NCON, 3))
    rim_ok = jnp.arange(4) == 0
    # the face's points only while the face lies within FACE of the cap, as MuJoCo C's face-face contact; beyond, its
    # deepest alone (several points at the tilted cap's normal, each at its own depth, over-stiffen the pad's press
    # and lever the puck over)
    face_n = axes[:, face_axis] * jnp.where(along[face_axis] > 0, 1.0, -1.0)
    flat = jnp.abs(face_n[2]) >= np.cos(FACE)
    # (midway along the deepest edge where two corners tie, as C)
    low = jnp.min(jnp.where(cap_ok, cap_dist, jnp.inf))
    tie = cap_ok & (cap_dist <= low + 1e-5)
    mid = jnp.sum(jnp.where(tie[:, None], cap_pos, 0.0), axis=0) / jnp.maximum(jnp.sum(tie), 1)
    first = jnp.arange(NCON) == 0
    cap_pos = jnp.where(flat, cap_pos, jnp.where(first[:, None], mid, cap_pos))
    cap_dist = jnp.where(flat, cap_dist, jnp.where(first, low, UNUSED))
    cap_ok = jnp.where(flat, cap_ok, first & jnp.any(cap_ok))
    pos = jnp.where(is_cap, cap_pos, jnp.where(is_side, side_pos, rim_pos))
    ok = jnp.where(is_cap, cap_ok, jnp.where(is_side, side_ok, rim_ok))
    dist = jnp.where(is_cap, cap_dist, sep)
    dist = jnp.where(ok, dist, UNUSED)
    # a box face on a cap pushes along the face's normal, as MuJoCo C's face contacts mostly do: a pad pressed on a
    # slightly tilted puck then presses it down, not sideways
    n = jnp.where(is_cap & (jnp.abs(face_n[2]) >= np.cos(SNAP)), face_n, n)
    world_n = cyl_mat @ n
    world_pos = cyl_pos + pos @ cyl_mat.T
    return dist, world_pos, jnp.broadcast_to(_make_frame(world_n), (NCON, 3, 3))


def box_cylinder_group(m, d, key, geom):
    """The collision driver's function for the (cylinder, box) group: every pair's four contacts, pairs in
    order (geom 1 the cylinder, as MJX orders a pair by geom type)."""
    g1, g2 = geom.T
    dist, pos, frame = jax.vmap(box_cylinder)(d.geom_xpos[g1], d.geom_xmat[g1], m.geom_size[g1, :2],
                                              d.geom_xpos[g2], d.geom_xmat[g2], m.geom_size[g2])  # fmt: skip
    return dist.reshape(-1), pos.reshape(-1, 3), frame.reshape(-1, 3, 3)


box_cylinder_group.ncon = NCON


def groups() -> dict:
    """{(CYLINDER, BOX): the driver's function} as ``envs/mjx_patch.py`` puts it in MJX's table."""
    from mujoco.mjx._src.types import GeomType

    return {(GeomType.CYLINDER, GeomType.BOX): box_cylinder_group}


def groups_for(m) -> dict:
    """``groups()`` where model ``m`` (MjModel) has a cylinder-box pair to collide, else {}."""
    import mujoco

    cyl, box = int(mujoco.mjtGeom.mjGEOM_CYLINDER), int(mujoco.mjtGeom.mjGEOM_BOX)
    types = {frozenset((int(m.geom_type[m.pair_geom1[i]]), int(m.geom_type[m.pair_geom2[i]]))) for i in range(m.npair)}
    # geoms that collide by contype and conaffinity would also need it; the Fetch models collide by pairs only
    return groups() if frozenset((cyl, box)) in types else {}
