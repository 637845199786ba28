"""C-like cap contact: the rim's 16-gon clips the pad's face (Sutherland-Hodgman), then the greedy largest-area walk."""
import jax
import jax.numpy as jnp
import numpy as np

SIDES, MAXV = 16, 24


def _area4(a, b, c, d):
    lift = lambda v: jnp.append(v, 0.0)  # noqa: E731
    v = jnp.cross(lift(d - a), lift(b - d)) + jnp.cross(lift(c - b), lift(a - c))
    return 0.5 * jnp.abs(v[2])


def _clip(subject, n, radius):
    """subject [MAXV, 2] with n valid vertices, clipped by the CCW 16-gon of ``radius``."""
    th = 2 * np.pi * np.arange(SIDES) / SIDES
    rim = np.stack([np.cos(th), np.sin(th)], 1)
    for i in range(SIDES):
        e = rim[(i + 1) % SIDES] - rim[i]
        inward = jnp.asarray(np.array([-e[1], e[0]]) / np.linalg.norm(e), subject.dtype)
        v1 = radius * jnp.asarray(rim[i], subject.dtype)
        j = jnp.arange(MAXV)
        p = subject
        q = subject[jnp.where(j + 1 < n, j + 1, 0)]
        sp, sq = (p - v1) @ inward, (q - v1) @ inward
        ip, iq = sp > -1e-15, sq > -1e-15
        denom = sq - sp
        t = -sp / jnp.where(jnp.abs(denom) > 1e-20, denom, 1.0)
        x = p + t[:, None] * (q - p)
        a_ok = (ip ^ iq) & (t >= 0) & (t <= 1)
        b_ok = iq
        live = j < n
        pts = jnp.stack([x, q], 1).reshape(-1, 2)
        ok = (jnp.stack([a_ok, b_ok], 1) & live[:, None]).reshape(-1)
        idx = jnp.where(ok, jnp.cumsum(ok) - 1, 2 * MAXV)
        subject = jnp.zeros((MAXV, 2), subject.dtype).at[idx].set(pts, mode="drop")
        n = jnp.minimum(jnp.sum(ok), MAXV)
    return subject, n


def _walk(p, n):
    """C's greedy walk for a quadrilateral of largest area (indices), over p[:n] in order; n >= 4."""
    nxt = lambda i: jnp.where(i + 1 < n, i + 1, 0)  # noqa: E731
    ar = lambda a, b, c, d: _area4(p[a], p[b], p[c], p[d])  # noqa: E731

    def inner(state, which):
        def cond(s):
            a, b, c, d, m, best = s
            q = [a, b, c, d]
            q[which] = nxt(q[which])
            return ar(*q) > m

        def body(s):
            a, b, c, d, m, best = s
            q = [a, b, c, d]
            q[which] = nxt(q[which])
            return (*q, ar(*q), jnp.stack(q))

        return jax.lax.while_loop(cond, body, state)

    def d_cond(s):
        a, b, c, d, m, best = s
        return ar(a, b, c, nxt(d)) > m

    def d_body(s):
        a, b, c, d, m, best = s
        d = nxt(d)
        s = (a, b, c, d, ar(a, b, c, d), jnp.stack([a, b, c, d]))
        s = inner(s, 2)
        return inner(s, 1)

    def a_cond(s):
        return s[0] < n

    def a_body(s):
        s = jax.lax.while_loop(d_cond, d_body, s)
        a, b, c, d, m, best = s
        bb = b == a
        b = jnp.where(bb, nxt(b), b)
        cc = bb & (c == b)
        c = jnp.where(cc, nxt(c), c)
        dd = cc & (d == c)
        d = jnp.where(dd, nxt(d), d)
        return (a + 1, b, c, d, m, best)

    i = [jnp.int32(k) for k in range(4)]
    s = (*i, ar(*i), jnp.stack(i))
    return jax.lax.while_loop(a_cond, a_body, s)[5]


def cap_points(face, radius):
    """(points [4, 3] on the face's plane, ok [4]) where the 16-gon clips the face [4, 3] (cylinder frame)."""
    sub = jnp.zeros((MAXV, 2), face.dtype).at[:4].set(face[:, :2])
    poly, n = _clip(sub, jnp.int32(4), radius)
    quad = jnp.where(n >= 5, _walk(poly, jnp.maximum(n, 4)), jnp.arange(4))
    xy = poly[quad]
    ok = jnp.where(n >= 5, True, jnp.arange(4) < n)
    # z on the face's plane
    e1, e2 = face[1] - face[0], face[3] - face[0]
    nrm = jnp.cross(e1, e2)
    nz = jnp.where(jnp.abs(nrm[2]) > 1e-12, nrm[2], 1e-12)
    z = face[0, 2] - (nrm[0] * (xy[:, 0] - face[0, 0]) + nrm[1] * (xy[:, 1] - face[0, 1])) / nz
    return jnp.concatenate([xy, z[:, None]], 1), ok
