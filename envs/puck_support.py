"""MuJoCo C's support of a cylinder standing on a box face, for MJX's plane-cylinder pair: up to four contacts per
pair, as MJX's collision functions return them (dist [4], pos [4, 3], frame [4, 3, 3]; an unused one has dist 1).

Why: FetchSlide's puck (a cylinder) stands on its table (a box), which MuJoCo C collides with its general convex
collider and multi-contact; MJX's plane-cylinder contact holds the puck by three points 120 degrees apart instead.
C's points are corners of a 16-gon round the rim, which of them changes irregularly as the puck turns and tilts,
and that is what makes the reference's puck tilt out from under a light press early (experiments/NOTES.md, "Slide's
press and strike"). This module makes the same choice in JAX, on the plane's rectangle as the box's top face.

How (as MuJoCo's multi-contact does for a cap within ``FACE_TOL`` of a box face): the cap facing the table is a
16-gon (vertex k at k x 22.5 degrees in the cylinder's frame, counter-clockwise seen from outside the cylinder for
the bottom cap), which clips the face's rectangle (Sutherland-Hodgman, one edge of the 16-gon at a time, each cut
along the cap's normal); the clipped vertices the cap does not reach are dropped; of more than four, four are kept
by a greedy hill-climb on a quadrilateral's area that starts at the list's first vertex. Each point's depth is
the height over the face of the corner above it, the point midway. Past ``FACE_TOL`` (or where no vertex
reaches the face) the lowest point of the rim alone touches, as C's single contact does; a cylinder lying on its
side touches by the lowest points of both rims. On a regular 16-gon many quadrilaterals tie in area, so rounding
decides between them: in float32 it decides otherwise than C's float64 at some poses
(``tests/envs/test_puck_support.py`` states how often).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

NCON = 4
UNUSED = 1.0  # dist of a contact slot that holds no contact
SIDES = 16  # the cap's polygon
FACE_TOL = 0.0889  # rad: a cap tilted less than this from the face touches it face to face (C's tolerance)
MAXV = 24  # room for the clipped polygon: the rectangle's 4 corners and one vertex more per clipping edge
STEPS = 72  # area evaluations of the hill-climb: 52 at most on a 16-gon, fewer on a clipped one
INSIDE_TOL = 1e-10  # a point this far outside a clipping plane still counts as inside
T_TOL = 3e-7  # an intersection this far outside its segment still counts
SUPPORTS = ("mjx", "polygon")  # MJX's plane-cylinder contact, or this module's
_ANGLES = np.arange(SIDES) * 2.0 * np.pi / SIDES
TEXT = "puck_support"  # the MJCF custom text that asks for this module's contact


def mjcf(support: str) -> str:
    """The MJCF ``<custom>`` element that marks a model whose puck stands on C's polygon ('' for MJX's contact)."""
    if support not in SUPPORTS:
        raise ValueError(f"puck_support must be one of {SUPPORTS}, got {support!r}")
    return f'\n  <custom><text name="{TEXT}" data="{support}"/></custom>' if support == "polygon" else ""


def _cap(mat, size, sgn):
    """The cap's 16-gon [16, 3] about the cylinder's centre, as C lists it: ``sgn`` -1 the bottom cap (outward
    normal -axis), +1 the top."""
    center = mat[:, 2] * (sgn * size[1])
    col0, col1 = mat[:, 0] * size[0], mat[:, 1] * (size[0] * sgn)
    cos, sin = jnp.asarray(np.cos(_ANGLES), mat.dtype), jnp.asarray(np.sin(_ANGLES), mat.dtype)
    return col0[None] * cos[:, None] - col1[None] * sin[:, None] + center


def _compact(points, keep):
    """The points [k, 3] with ``keep`` first, in order, in MAXV rows; and how many."""
    csum = jnp.cumsum(keep.astype(jnp.int32))
    src = jnp.sum(csum[None, :] <= jnp.arange(MAXV)[:, None], axis=1)  # the j-th kept point's row
    return points[jnp.minimum(src, points.shape[0] - 1)], jnp.minimum(csum[-1], MAXV)


def _clip(face, n, poly, count):
    """Sutherland-Hodgman: polygon ``poly`` (its first ``count`` rows) clipped by the planes through each edge of
    the convex ``face`` [16, 3] along its normal ``n``, in C's order and with its tolerances."""
    pn = jnp.cross(jnp.roll(face, -1, axis=0) - face, (face + n) - face)
    pd = jnp.sum(pn * face, axis=-1)
    rows = jnp.arange(MAXV)

    def cut_by(carry, plane):
        poly, count = carry
        a, pn_e, pd_e = plane
        q = poly[(rows + 1) % jnp.maximum(count, 1)]
        valid = rows < count
        in1 = (poly - a) @ pn_e > -INSIDE_TOL
        in2 = (q - a) @ pn_e > -INSIDE_TOL
        den = (q - poly) @ pn_e
        flat = jnp.abs(den) < INSIDE_TOL
        t = (pd_e - poly @ pn_e) / jnp.where(flat, 1.0, den)
        cut = ~flat & (t > -T_TOL) & (t < 1.0 + T_TOL)
        x = poly + jnp.clip(t, 0.0, 1.0)[:, None] * (q - poly)
        keep = jnp.stack([valid & (in1 != in2) & cut, valid & in2], axis=1).reshape(-1)
        return _compact(jnp.stack([x, q], axis=1).reshape(-1, 3), keep), None

    (poly, count), _ = jax.lax.scan(cut_by, (poly, count), (face, pn, pd))
    return poly, count


def _area(p):
    """Area of the quadrilateral p [4, 3]: half the cross product of its diagonals."""
    return 0.5 * jnp.linalg.norm(jnp.cross(p[0] - p[2], p[1] - p[3]))


def _quad(poly, count):
    """Indices [4] of the quadrilateral C's greedy search keeps in the polygon's first ``count`` (> 4) rows: from
    the first four vertices, for each vertex a in turn, advance the fourth corner while the area grows and after
    each advance the third and then the second likewise; a tie does not advance."""
    n = jnp.maximum(count, 1)
    idx0 = jnp.arange(4)

    def step(s, _):
        a, b, c, d, m, res, phase, done = s
        cand = jnp.stack([a, (b + (phase == 2)) % n, (c + (phase == 1)) % n, (d + (phase == 0)) % n])
        m_next = _area(poly[cand])
        better = (m_next > m) & ~done
        b, c, d = (jnp.where(better, cand[i], v) for i, v in ((1, b), (2, c), (3, d)))
        res, m = jnp.where(better, cand, res), jnp.where(better, m_next, m)
        # phases: 0 the fourth corner, 1 the third, 2 the second; a failed fourth ends vertex a's turn
        end = ~better & (phase == 0) & ~done
        phase = jnp.where(better, jnp.maximum(phase, 1), jnp.where(phase == 1, 2, 0))
        bump_b = end & (b == a)
        b = jnp.where(bump_b, (b + 1) % n, b)
        bump_c = bump_b & (c == b)
        c = jnp.where(bump_c, (c + 1) % n, c)
        d = jnp.where(bump_c & (d == c), (d + 1) % n, d)
        a = a + end
        return (a, b, c, d, m, res, phase, done | (a >= n)), None

    zero = jnp.zeros((), jnp.int32)
    init = (zero, zero + 1, zero + 2, zero + 3, _area(poly[idx0]), idx0, zero, jnp.zeros((), bool))
    out, _ = jax.lax.scan(step, init, None, length=STEPS)
    return out[5]


def _lowest(mat, size, sgn, n):
    """The lowest point of the rim of the cap ``sgn`` along ``-n`` (a plane's normal), about the centre."""
    axis = mat[:, 2]
    down = -n - axis * jnp.dot(-n, axis)
    norm = jnp.linalg.norm(down)
    down = jnp.where(norm > 1e-9, down / jnp.where(norm > 1e-9, norm, 1.0), mat[:, 0])
    return axis * (sgn * size[1]) + down * size[0]


def plane_cylinder(plane_pos, plane_mat, plane_size, cyl_pos, cyl_mat, cyl_size):
    """(dist [4], pos [4, 3], frame [4, 3, 3]) of a cylinder (radius, half height) standing on the rectangle
    (half sizes ``plane_size[:2]``) of a plane: normals along the plane's, dist negative in penetration."""
    n = plane_mat[:, 2]
    axis_n = jnp.dot(cyl_mat[:, 2], n)
    sgn = jnp.where(axis_n > 0, -1.0, 1.0)  # the cap whose outward normal faces the plane
    face = _cap(cyl_mat, cyl_size, sgn)
    cap_n = cyl_mat[:, 2] * sgn
    rect = jnp.array([[-1.0, 1.0], [1.0, 1.0], [1.0, -1.0], [-1.0, -1.0]]) * plane_size[:2]
    corners = plane_pos - cyl_pos + rect @ plane_mat[:, :2].T
    poly = jnp.zeros((MAXV, 3), cyl_pos.dtype).at[:4].set(corners)
    poly, count = _clip(face, cap_n, poly, jnp.int32(4))
    depth = (poly - face[0]) @ cap_n  # <= 0: the cap reaches the face there
    poly, count = _compact(poly, (jnp.arange(MAXV) < count) & (depth <= 0.0))
    rows = jnp.where(count > 4, _quad(poly, count), jnp.arange(4))
    on_face = poly[rows]
    on_cap = on_face - ((on_face - face[0]) @ cap_n)[:, None] * cap_n  # the corner on the cap's plane
    dist = (on_cap - on_face) @ n
    pos = on_cap - 0.5 * dist[:, None] * n
    ok = jnp.arange(4) < count
    # past the face tolerance, or where no corner reaches the face: the rim's lowest point (two on the side)
    low = jnp.stack([_lowest(cyl_mat, cyl_size, sgn, n), _lowest(cyl_mat, cyl_size, -sgn, n)])
    low_dist = (low + cyl_pos - plane_pos) @ n
    low_pos = jnp.concatenate([low - 0.5 * low_dist[:, None] * n, jnp.zeros((2, 3), low.dtype)])
    side = jnp.abs(axis_n) < np.sin(FACE_TOL)
    low_ok = jnp.array([True, False, False, False]) | (side & (jnp.arange(4) == 1))
    face_to_face = (jnp.abs(axis_n) > np.cos(FACE_TOL)) & (count > 0)
    dist = jnp.where(face_to_face, dist, jnp.concatenate([low_dist, jnp.ones(2, low.dtype)]))
    pos = jnp.where(face_to_face, pos, low_pos)
    dist = jnp.where(jnp.where(face_to_face, ok, low_ok), dist, UNUSED)
    from mujoco.mjx._src import math as mjx_math

    return dist, cyl_pos + pos, jnp.broadcast_to(mjx_math.make_frame(n), (NCON, 3, 3))


def plane_cylinder_group(m, d, key, geom):
    """The collision driver's function for the (plane, cylinder) group: every pair's four contacts, pairs in
    order (geom 1 the plane, as MJX orders a pair by geom type)."""
    g1, g2 = geom.T
    dist, pos, frame = jax.vmap(plane_cylinder)(d.geom_xpos[g1], d.geom_xmat[g1], m.geom_size[g1],
                                                d.geom_xpos[g2], d.geom_xmat[g2], m.geom_size[g2, :2])  # fmt: skip
    return dist.reshape(-1), pos.reshape(-1, 3), frame.reshape(-1, 3, 3)


plane_cylinder_group.ncon = NCON


def support(m) -> str:
    """The puck support model ``m`` (MjModel) asks for: its custom text ``puck_support``, else MJX's."""
    import mujoco

    i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_TEXT, TEXT)
    if i < 0:
        return "mjx"
    adr, size = int(m.text_adr[i]), int(m.text_size[i])
    return bytes(m.text_data[adr : adr + size]).split(b"\0")[0].decode()


def groups_for(m) -> dict:
    """{(PLANE, CYLINDER): the driver's function} where model ``m`` asks for this support, else {}."""
    if support(m) != "polygon":
        return {}
    from mujoco.mjx._src.types import GeomType

    return {(GeomType.PLANE, GeomType.CYLINDER): plane_cylinder_group}
