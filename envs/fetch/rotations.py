"""The object's orientation as the reference observes it: Euler angles of a quaternion, and vectors rotated by
one (a free joint's angular velocity is in the body's frame)."""

from __future__ import annotations

import jax
import jax.numpy as jnp


def quat_to_euler(q: jax.Array) -> jax.Array:
    """Euler angles (a, b, c) with R = Rx(a) Ry(b) Rz(c), from a (w, x, y, z) quaternion."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    r00 = 1 - 2 * (y * y + z * z)
    r01 = 2 * (x * y - w * z)
    r02 = 2 * (x * z + w * y)
    r10 = 2 * (x * y + w * z)
    r11 = 1 - 2 * (x * x + z * z)
    r12 = 2 * (y * z - w * x)
    r22 = 1 - 2 * (x * x + y * y)
    cy = jnp.sqrt(r22 * r22 + r12 * r12)
    regular = cy > 1e-6
    a = jnp.where(regular, -jnp.arctan2(r12, r22), 0.0)
    b = -jnp.arctan2(-r02, cy)
    c = jnp.where(regular, -jnp.arctan2(r01, r00), -jnp.arctan2(-r10, r11))
    return jnp.stack([a, b, c])


def quat_rotate(q: jax.Array, v: jax.Array) -> jax.Array:
    """Rotate vector ``v`` by unit quaternion ``q`` (w, x, y, z)."""
    w, u = q[0], q[1:]
    return v + 2.0 * jnp.cross(u, jnp.cross(u, v) + w * v)
