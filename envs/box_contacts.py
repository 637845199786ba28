"""MJX's box-box and plane-box contacts (``mujoco.mjx._src.collision_convex.box_box``, ``plane_convex``) as arithmetic
a Triton kernel holds: one pair's contacts from its geoms' positions, rotations and sizes.

The arithmetic is MJX's: the separating-axis test over the 6 + 6 face normals and 9 edge crosses, the reference and
incident faces, their clipping, the choice of four manifold points, the edge-contact rule; for a plane, the box's
vertices within 1 mm of its deepest and the same choice of four.

Written for what a Triton kernel holds: vectors as (x, y, z) tuples of arrays, no gathers (picks by masks), argmax
and argmin as the first index of the extreme, no concatenation, no constant arrays (vertices and faces from iota),
shapes padded to powers of two; the clipped points keep a (set, edge, end) layout of shape (2, 4, 2) in MJX's order.
Where MJX's choice is a float tie (boxes face to face: two equally deep points, two equally good fourth points) the
rounding of either implementation decides, so the contacts agree as a set, their order or a duplicated point may
differ.
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from envs.fused_solver import at_mask

_FACE = np.array([0, 4, 5, 1, 0, 2, 6, 4, 6, 7, 5, 4, 2, 3, 7, 6, 1, 5, 7, 3, 0, 1, 3, 2]).reshape(6, 4)
_NORMAL = np.array([[0, -1, 0], [0, 0, -1], [1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0]], dtype=np.float32)
NF, NA, BIG = 8, 32, 1e30  # faces padded to 8, separating axes (6 + 6 + 9 = 21) padded to 32


def _v(a):
    return tuple(a[..., i] for i in range(3))


def _vec(x):
    """A vector as (x, y, z): an array [..., 3] split, or a tuple kept."""
    return x if isinstance(x, tuple) else _v(x)


def _rows(m):
    """A 3 x 3 matrix as a tuple of rows: an array [3, 3] split, or a tuple kept."""
    return m if isinstance(m, tuple) else tuple(_v(m[i]) for i in range(3))


def _vec4(xs):
    """Four scalars as a [4] array (no concatenation: a Triton kernel has none)."""
    i4 = jnp.arange(4)
    return sum(jnp.where(i4 == i, x, 0.0) for i, x in enumerate(xs))


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _add(a, b):
    return tuple(x + y for x, y in zip(a, b, strict=True))


def _sub(a, b):
    return tuple(x - y for x, y in zip(a, b, strict=True))


def _scale(a, s):
    return tuple(x * s for x in a)


def _where(c, a, b):
    return tuple(jnp.where(c, x, y) for x, y in zip(a, b, strict=True))


def _normalize(a):
    n = jnp.sqrt(_dot(a, a))
    d = jnp.where(n == 0.0, n + 1e-6, n)
    return tuple(x / d for x in a)


def _matvec(m, v):  # m as rows
    return tuple(_dot(row, v) for row in m)


def _first_index(mask, index):
    """The smallest ``index`` where ``mask`` holds (argmax's and argmin's first occurrence)."""
    return jnp.min(jnp.where(mask, index, 1 << 20))


def _argmin(x, index):
    return _first_index(x == jnp.min(x), index)


def _argmax(x, index):
    return _first_index(x == jnp.max(x), index)


def _pick(a, index, i):
    """a[i] for a vector ``a`` whose components share ``index``'s shape (a Triton kernel has no gather)."""
    return tuple(at_mask(x, index == i) for x in a)


def _corner(index, c: int, dtype):
    """Coordinate c (-1 or 1) of mesh.box's unit vertex ``index``: its bit 2 - c is the sign."""
    return ((index >> (2 - c)) & 1).astype(dtype) * 2 - 1


def _row_of(a, index, i):
    """Row i (index along axis 0) of each component of ``a`` ([n, k] arrays), as [k] arrays."""
    return tuple(jnp.sum(jnp.where(index[:, None] == i, x, 0.0), axis=0) for x in a)


def _roll1(a):
    """jnp.roll(a, 1) of [4] components, by a permutation (out[i] = a[i - 1])."""
    i = jnp.arange(4)
    perm = (i[:, None] - 1) % 4 == i[None, :]
    return tuple(jnp.sum(jnp.where(perm, x[None, :], 0.0), axis=1) for x in a)


def _segment_plane(a, b, p0, n):  # _closest_segment_point_plane, broadcast
    d = _dot(p0, n)
    denom = _dot(n, _sub(b, a))
    t = (d - _dot(n, a)) / jnp.where(denom == 0.0, denom + 1e-6, denom)
    t = jnp.clip(t, 0, 1)
    return _add(a, _scale(_sub(b, a), t))


def _clip_edges(p0, p1, plane_pts, plane_normals):
    """_clip_edge_to_planes for 4 edges (p0, p1: [4] components) against 4 planes: the clipped ends [4] each and
    the edges' mask [4]."""
    e = lambda v: tuple(x[:, None] for x in v)  # noqa: E731  edges along axis 0
    k = lambda v: tuple(x[None, :] for x in v)  # noqa: E731  planes along axis 1
    pp, pn = k(plane_pts), k(plane_normals)
    p0e, p1e = e(p0), e(p1)
    p0_front = _dot(_sub(p0e, pp), pn) > 1e-6
    p1_front = _dot(_sub(p1e, pp), pn) > 1e-6
    cand = _segment_plane(p0e, p1e, pp, pn)
    plane = jnp.arange(4)[None, :]

    def clip_end(q0, q1, front):
        new = _where(front, cand, tuple(jnp.broadcast_to(x, front.shape) for x in q0))
        dists = _dot(_sub(new, q0), _sub(q1, q0))
        best = jnp.min(jnp.where(dists == jnp.max(dists, axis=1, keepdims=True), plane, 1 << 20), axis=1)
        return tuple(jnp.sum(jnp.where(plane == best[:, None], x, 0.0), axis=1) for x in new)

    n0, n1 = clip_end(p0e, p1e, p0_front), clip_end(p1e, p0e, p1_front)
    mask = jnp.max(jnp.where(p0_front & p1_front, 1, 0), axis=1) == 0
    n0, n1 = _where(mask, n0, p0), _where(mask, n1, p1)
    mask = jnp.where(_dot(_sub(p0, p1), _sub(n0, n1)) < 0, False, mask)
    return n0, n1, mask


def _manifold(poly, mask, norm, flat, count: int):
    """_manifold_points over ``count`` points (components of any shape, ``flat`` their index in MJX's order)."""
    zero = 0.0 * poly[0]
    dist_mask = jnp.where(mask, zero, zero - 1e6)
    a_idx = _argmax(dist_mask, flat)
    a = _pick(poly, flat, a_idx)
    ap = _sub(a, poly)
    b_idx = _argmax(_dot(ap, ap) + dist_mask, flat)
    b = _pick(poly, flat, b_idx)
    ab = _cross(norm, _sub(a, b))
    c_idx = _argmax(jnp.abs(_dot(ap, ab)) + dist_mask, flat)
    c = _pick(poly, flat, c_idx)
    ac, bc = _cross(norm, _sub(a, c)), _cross(norm, _sub(b, c))
    bp = _sub(b, poly)
    d_idx = _argmax(jnp.abs(_dot(bp, bc)) + dist_mask + jnp.abs(_dot(ap, ac)) + dist_mask, flat) % count
    return a_idx, b_idx, c_idx, d_idx


def _manifold_contacts(ref, inc, ref_n, inc_n, sep):
    """_create_contact_manifold: ref and inc are [4] components (the faces' vertices)."""
    # clip the incident face's edges against the reference face's side planes
    c0, c1 = _roll1(ref), ref
    c_normals = _cross(_sub(c1, c0), tuple(jnp.broadcast_to(x, (4,)) for x in ref_n))
    s0, s1 = _roll1(inc), inc
    s_normals = _cross(_sub(s1, s0), tuple(jnp.broadcast_to(x, (4,)) for x in inc_n))
    a0, a1, amask = _clip_edges(s0, s1, c0, c_normals)
    # the reference face's edges, projected onto the incident face's plane, against its side planes
    d = _dot(_pick(inc, jnp.arange(4), 0), inc_n)
    denom = _dot(ref_n, inc_n)

    def project(p):
        t = (d - _dot(p, inc_n)) / jnp.where(denom == 0.0, denom + 1e-6, denom)
        return _add(p, _scale(ref_n, t))

    b0, b1, bmask = _clip_edges(project(c0), project(c1), s0, s_normals)
    # the 16 points in (set, edge, end) layout
    s_idx = jnp.arange(2)[:, None, None]
    end = jnp.arange(2)[None, None, :]
    edge = jnp.arange(4)[None, :, None]

    def layout(x0, x1, y0, y1):
        xs = jnp.where(end == 0, x0[None, :, None], x1[None, :, None])
        ys = jnp.where(end == 0, y0[None, :, None], y1[None, :, None])
        return jnp.where(s_idx == 0, xs, ys)

    incident = tuple(layout(*q) for q in zip(a0, a1, b0, b1, strict=True))
    mask = jnp.where(s_idx == 0, amask[None, :, None], bmask[None, :, None]) & (end >= 0)
    flat = s_idx * 8 + edge * 2 + end
    nn = _normalize(ref_n)
    r0 = _pick(ref, jnp.arange(4), 0)
    dist0 = _dot(_sub(incident, r0), nn)
    poly_ref = _sub(incident, _scale(nn, dist0))
    mask = mask & (_dot(_sub(incident, r0), _scale(ref_n, -1.0)) > 1e-6)
    best = _manifold(poly_ref, mask, ref_n, flat, 16)
    pts = [_pick(poly_ref, flat, i) for i in best]
    pmask = [jnp.max(jnp.where((flat == i) & mask, 1, 0)) > 0 for i in best]
    pen = [_dot(_sub(_pick(incident, flat, i), p), _scale(ref_n, -1.0)) for i, p in zip(best, pts, strict=True)]
    dist = [jnp.where(m, -q, 1.0) for m, q in zip(pmask, pen, strict=True)]
    normal = _scale(sep, -1.0)
    return dist, pts, normal


def box_box_soa(pos1, mat1, size1, pos2, mat2, size2):
    """box_box's (dist [4], pos as (x, y, z) [4] arrays, frame rows as tuples of scalars)."""
    m1, m2 = _rows(mat1), _rows(mat2)
    m2t = tuple(tuple(m2[j][i] for j in range(3)) for i in range(3))
    rel = tuple(tuple(_dot(m2t[i], tuple(m1[k][j] for k in range(3))) for j in range(3)) for i in range(3))  # m2^T m1
    pos1, pos2, s1, s2 = (_vec(x) for x in (pos1, pos2, size1, size2))
    t = _matvec(m2t, _sub(pos1, pos2))
    # box 1's vertices and faces in box 2's frame, box 2's in its own
    vi = jnp.arange(8)
    vert = tuple(_corner(vi, c, t[0].dtype) for c in range(3))
    va = _add(t, _matvec(rel, tuple(vert[i] * s1[i] for i in range(3))))
    vb = tuple(vert[i] * s2[i] for i in range(3))
    fi, ki = jnp.arange(NF)[:, None], jnp.arange(4)[None, :]
    face_vi = jnp.zeros((NF, 4), jnp.int32)
    for f in range(6):
        for k in range(4):
            face_vi = jnp.where((fi == f) & (ki == k), int(_FACE[f, k]), face_vi)
    face_unit = tuple(_corner(face_vi, c, t[0].dtype) for c in range(3))  # [8, 4]
    fa = _add(tuple(x[..., None, None] for x in t), _matvec(rel, tuple(face_unit[i] * s1[i] for i in range(3))))
    fb = tuple(face_unit[i] * s2[i] for i in range(3))
    f8 = jnp.arange(NF)
    normal_unit = tuple(sum(jnp.where(f8 == f, float(_NORMAL[f, c]), 0.0) for f in range(6)) for c in range(3))
    na = _matvec(rel, normal_unit)
    nb = normal_unit
    # separating axes: 6 + 6 face normals, then the 9 edge-pair crosses (a tiled, b repeated), padded to 32
    ax_i = jnp.arange(NA)
    ea = tuple(tuple(rel[r][c] for r in range(3)) for c in range(3))  # box 1's axes in box 2's frame
    eb = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    axes = [jnp.zeros((NA,), t[0].dtype) for _ in range(3)]
    degenerate = ax_i >= 21
    for f in range(6):
        for c in range(3):
            axes[c] = jnp.where(ax_i == f, at_mask(na[c], jnp.arange(NF) == f), axes[c])
            axes[c] = jnp.where(ax_i == 6 + f, float(_NORMAL[f, c]), axes[c])
    for q in range(9):
        cr = _cross(ea[q % 3], eb[q // 3])
        deg = _dot(cr, cr) < 1e-6
        cr = _normalize(cr)
        for c in range(3):
            axes[c] = jnp.where(ax_i == 12 + q, cr[c], axes[c])
        degenerate = jnp.where(ax_i == 12 + q, deg, degenerate)
    axes = tuple(axes)
    pa = _dot(tuple(x[:, None] for x in axes), tuple(x[None, :] for x in va))  # [32, 8]
    pb = _dot(tuple(x[:, None] for x in axes), tuple(x[None, :] for x in vb))
    dist1 = jnp.max(pa, axis=1) - jnp.min(pb, axis=1)
    dist2 = jnp.max(pb, axis=1) - jnp.min(pa, axis=1)
    sign = jnp.where(dist1 > dist2, 0.0 * dist1 - 1.0, 0.0 * dist1 + 1.0)
    support = jnp.where(degenerate, 1e6, jnp.minimum(dist1, dist2))
    support = jnp.where(ax_i >= 21, BIG, support)
    best_face_idx = _argmin(jnp.where(ax_i < 12, support, BIG), ax_i)
    best_face_axis = _pick(axes, ax_i, best_face_idx)
    best_idx = _argmin(support, ax_i)
    best_sign = at_mask(sign, ax_i == best_idx)
    best_axis = _pick(axes, ax_i, best_idx)
    is_edge = (best_idx >= 12) & (jnp.abs(_dot(best_face_axis, best_axis)) < 0.99)
    f_i = jnp.arange(NF)
    real = f_i < 6
    da, db = _dot(na, best_axis), _dot(nb, best_axis)
    a_max = _argmax(jnp.where(real, da, -BIG), f_i)
    b_max = _argmax(jnp.where(real, db, -BIG), f_i)
    a_min = _argmin(jnp.where(real, da, BIG), f_i)
    b_min = _argmin(jnp.where(real, db, BIG), f_i)
    pos_sign = best_sign > 0
    ref = _where(pos_sign, _row_of(fa, f_i, a_max), _row_of(fb, f_i, b_max))
    ref_n = _where(pos_sign, _pick(na, f_i, a_max), _pick(nb, f_i, b_max))
    inc = _where(pos_sign, _row_of(fb, f_i, b_min), _row_of(fa, f_i, a_min))
    inc_n = _where(pos_sign, _pick(nb, f_i, b_min), _pick(na, f_i, a_min))
    dist, pts, normal = _manifold_contacts(ref, inc, ref_n, inc_n, _scale(best_axis, -best_sign))
    # edge contacts keep the deepest clipped point alone
    i4 = jnp.arange(4)
    dvec = _vec4(dist)
    pvec = tuple(_vec4([p[c] for p in pts]) for c in range(3))
    idx = _argmin(dvec, i4)
    deep = _pick(pvec, i4, idx)
    dvec = jnp.where(is_edge, jnp.where(i4 == 0, jnp.min(dvec), 1.0), dvec)
    pvec = _where(is_edge, tuple(jnp.broadcast_to(x, (4,)) for x in deep), pvec)
    # back to the world frame
    world = _add(tuple(jnp.broadcast_to(x, (4,)) for x in pos2), _matvec(m2, pvec))
    n = _matvec(m2, normal)
    dvec = jnp.where(jnp.isinf(dvec), jnp.finfo(dvec.dtype).max, dvec)
    return dvec, world, frame_rows(n)


def plane_box_soa(plane_pos, plane_mat, box_pos, box_mat, box_size):
    """plane_box's (dist [4], pos as (x, y, z) [4] arrays, frame rows as tuples of scalars)."""
    pm, bm = _rows(plane_mat), _rows(box_mat)
    plane_pos, box_pos, size = _vec(plane_pos), _vec(box_pos), _vec(box_size)
    bmt = tuple(tuple(bm[j][i] for j in range(3)) for i in range(3))
    normal = (pm[0][2], pm[1][2], pm[2][2])  # the plane's z axis
    local_pos, n = _matvec(bmt, _sub(plane_pos, box_pos)), _matvec(bmt, normal)
    vi = jnp.arange(8)
    vert = tuple(_corner(vi, c, size[0].dtype) * size[c] for c in range(3))
    support = _dot(_sub(tuple(jnp.broadcast_to(x, (8,)) for x in local_pos), vert), n)
    mask = support > jnp.maximum(0.0, jnp.max(support) - 1e-3)  # manifold points within a 1 mm skin
    best = _manifold(vert, mask, n, vi, 8)
    i4 = jnp.arange(4)
    idx = _vec4(best)
    local = tuple(_vec4([_pick(vert, vi, i)[c] for i in best]) for c in range(3))
    depth = _vec4([at_mask(support, vi == i) for i in best])
    earlier = sum(jnp.where((i4 > j) & (idx == best[j]), 1, 0) for j in range(4))  # a point chosen before
    dist = jnp.where(earlier == 0, -depth, 0.0 * depth + 1.0)
    world = _add(tuple(jnp.broadcast_to(x, (4,)) for x in box_pos), _matvec(bm, local))
    world = _sub(world, _scale(tuple(jnp.broadcast_to(x, (4,)) for x in normal), 0.5 * dist))
    return dist, world, frame_rows(normal)


def _as_arrays(soa):
    """(dist [4], pos [4, 3], frame [4, 3, 3]) from a contact function's structure-of-arrays result."""
    dist, world, rows = soa
    frame = jnp.stack([jnp.stack(r) for r in rows])
    return dist, jnp.stack(world, axis=-1), jnp.broadcast_to(frame, (4, 3, 3))


def box_box(pos1, mat1, size1, pos2, mat2, size2):
    """(dist [4], pos [4, 3], frame [4, 3, 3]) as MJX's box_box for two boxes (pos [3], mat [3, 3], half sizes)."""
    return _as_arrays(box_box_soa(pos1, mat1, size1, pos2, mat2, size2))


def plane_box(plane_pos, plane_mat, box_pos, box_mat, box_size):
    """(dist [4], pos [4, 3], frame [4, 3, 3]) as MJX's plane_convex for a plane and a box."""
    return _as_arrays(plane_box_soa(plane_pos, plane_mat, box_pos, box_mat, box_size))


def frame_rows(a):
    """math.make_frame's rows (a, b, c) as tuples of scalars."""
    a = _normalize(a)
    use_y = (-0.5 < a[1]) & (a[1] < 0.5)
    zero = 0.0 * a[0]  # a select of two constants lowers to a boolean in Triton: select against a value
    b = (zero, jnp.where(use_y, zero + 1.0, zero), jnp.where(use_y, zero, zero + 1.0))
    b = _sub(b, _scale(a, _dot(a, b)))
    nonzero = (a[0] != 0) | (a[1] != 0) | (a[2] != 0)
    b = tuple(jnp.where(nonzero, x, 0.0) for x in _normalize(b))
    return a, b, _cross(a, b)
