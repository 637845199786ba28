"""A Fetch task's simulator state and what a policy observes of it: the reference's 25 floats (10 for Reach), in
its order, velocities times the control step."""

from __future__ import annotations

import jax
import jax.numpy as jnp
from flax import struct

from envs.fetch.rotations import quat_rotate, quat_to_euler


@struct.dataclass
class Physics:
    """Everything the future depends on; ``step`` rebuilds the simulator from this alone."""

    qpos: jax.Array
    qvel: jax.Array
    ctrl: jax.Array
    time: jax.Array
    qacc_warmstart: jax.Array


def fingers(layout, phys: Physics) -> tuple[jax.Array, jax.Array]:
    """The two finger joints' (positions, velocities); zeros where the fingers are one locked block."""
    if layout.finger_q is None:
        z = jnp.zeros(2, phys.qpos.dtype)
        return z, z
    return phys.qpos[layout.finger_q : layout.finger_q + 2], phys.qvel[layout.finger_v : layout.finger_v + 2]


def observe(layout, dt: float, has_object: bool, phys: Physics) -> tuple[jax.Array, jax.Array]:
    """(observation, achieved goal) in the reference layout; velocities times ``dt``."""
    g = layout.grip_q
    grip = jnp.asarray(layout.grip_home, phys.qpos.dtype) + phys.qpos[g : g + 3]
    grip_vel = phys.qvel[g : g + 3] * dt
    finger_pos, finger_vel = fingers(layout, phys)
    finger_vel = finger_vel * dt
    if not has_object:
        return jnp.concatenate([grip, finger_pos, grip_vel, finger_vel]), grip
    o, v = layout.object_q, layout.object_v
    obj = phys.qpos[o : o + 3]
    quat = phys.qpos[o + 3 : o + 7]
    obj_vel = phys.qvel[v : v + 3] * dt
    obj_rot_vel = quat_rotate(quat, phys.qvel[v + 3 : v + 6]) * dt  # free-joint angular velocity is local
    obs = jnp.concatenate(
        [grip, obj, obj - grip, finger_pos, quat_to_euler(quat), obj_vel - grip_vel, obj_rot_vel, grip_vel, finger_vel]
    )
    return obs, obj
