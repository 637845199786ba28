"""The physical response of both simulators from each one's home: the grip under a held action, the
object's free slide, and the gripper pushing the object."""

from __future__ import annotations

import functools

import numpy as np

from splid_jax.reference.extra import make_reference
from splid_jax.reference.mapping import reference_start


@functools.cache
def jitted_step(task_env):
    """``jax.jit(task_env.step)``, compiled once per task for the response measurements."""
    import jax

    return jax.jit(task_env.step)


def grip_paths(task_env, task: str, actions) -> tuple[np.ndarray, np.ndarray]:
    """Grip positions [T + 1, 3] of (ours, reference) under the same ``actions`` [T, 4] from each
    one's home (our ``reset(PRNGKey(0))``, the reference's ``reset(seed=0)``)."""
    import jax
    import jax.numpy as jnp

    env = make_reference(task)
    o, _ = env.reset(seed=0)
    ref = [o["observation"][:3]]
    for a in actions:
        o, *_ = env.step(np.asarray(a, np.float64))
        ref.append(o["observation"][:3])
    env.close()
    s = task_env.reset(jax.random.PRNGKey(0))
    step = jitted_step(task_env)
    ours = [np.asarray(s.obs[:3])]
    for a in actions:
        s = step(s, jnp.asarray(a, jnp.float32))
        ours.append(np.asarray(s.obs[:3]))
    return np.array(ours, np.float64), np.array(ref, np.float64)


def step_response(task_env, task: str, action=(1.0, 0.0, 0.0, 0.0), hold: int = 10, release: int = 10) -> dict:
    """The grip's per-step displacement (m) in both simulators under ``action`` held ``hold`` steps then
    zero for ``release`` steps, and under zero action alone from home (drift at rest)."""
    held = np.concatenate([np.tile(np.asarray(action, np.float64), (hold, 1)), np.zeros((release, 4))])
    ours, ref = grip_paths(task_env, task, held)
    ours_rest, ref_rest = grip_paths(task_env, task, np.zeros((hold + release, 4)))
    return {
        "action": [float(x) for x in action],
        "hold": hold,
        "release": release,
        "commanded_per_step": (0.05 * np.asarray(action[:3], np.float64)).tolist(),
        "ours_step": np.diff(ours, axis=0).tolist(),
        "fetch_step": np.diff(ref, axis=0).tolist(),
        "ours_rest_step": np.diff(ours_rest, axis=0).tolist(),
        "fetch_rest_step": np.diff(ref_rest, axis=0).tolist(),
    }


def cube_slide(task_env, task: str, velocity=(0.5, 0.0), steps: int = 15) -> dict:
    """The object's free slide in both simulators: from each one's reset (seed 0, ``PRNGKey(0)``) the
    object is given the x-y ``velocity`` (m/s) and the gripper is held (zero action); per-step
    displacement (m) of the object along x-y, and the distance it travels."""
    import jax
    import jax.numpy as jnp

    v = np.array([*velocity, 0.0, 0.0, 0.0, 0.0])
    env = make_reference(task)
    from gymnasium_robotics.utils import mujoco_utils

    o, _ = env.reset(seed=0)
    u = env.unwrapped
    mujoco_utils.set_joint_qvel(u.model, u.data, "object0:joint", v)
    ref = [o["observation"][3:5]]
    for _ in range(steps):
        o, *_ = env.step(np.zeros(4))
        ref.append(o["observation"][3:5])
    env.close()
    s = task_env.reset(jax.random.PRNGKey(0))
    lay = task_env.layout
    qvel = s.physics.qvel.at[lay.object_v : lay.object_v + 6].set(jnp.asarray(v, s.physics.qvel.dtype))
    s = s.replace(physics=s.physics.replace(qvel=qvel))
    step = jitted_step(task_env)
    ours = [np.asarray(s.obs[3:5])]
    for _ in range(steps):
        s = step(s, jnp.zeros(4))
        ours.append(np.asarray(s.obs[3:5]))
    ours, ref = np.array(ours, np.float64), np.array(ref, np.float64)
    return {
        "velocity": [float(x) for x in velocity],
        "ours_step": np.linalg.norm(np.diff(ours, axis=0), axis=-1).tolist(),
        "fetch_step": np.linalg.norm(np.diff(ref, axis=0), axis=-1).tolist(),
        "ours_travel": float(np.linalg.norm(ours[-1] - ours[0])),
        "fetch_travel": float(np.linalg.norm(ref[-1] - ref[0])),
    }


def loaded_push(task_env, task: str, action=(1.0, 0.0, 0.0, 0.0), gap: float = 0.06, hold: int = 5,
                release: int = 5) -> dict:  # fmt: skip
    """The gripper pushing the object in both simulators: from each one's reset the object is put
    ``gap`` metres ahead of the grip (along the action's x-y direction), ``action`` is held ``hold``
    steps then zero for ``release``; per-step x-y displacement (m) of the grip and of the object."""
    import jax
    import jax.numpy as jnp

    a = np.asarray(action, np.float64)
    ahead = a[:2] / max(float(np.linalg.norm(a[:2])), 1e-9) * gap
    seq = np.concatenate([np.tile(a, (hold, 1)), np.zeros((release, 4))])
    env = make_reference(task)
    o, _ = env.reset(seed=0)
    o = reference_start(env, o["observation"][0:2] + ahead, o["desired_goal"])
    ref = [o["observation"][:5]]
    for x in seq:
        o, *_ = env.step(x)
        ref.append(o["observation"][:5])
    env.close()
    s = task_env.reset(jax.random.PRNGKey(0))
    q = task_env.layout.object_q
    qpos = s.physics.qpos.at[q : q + 2].set(s.obs[0:2] + jnp.asarray(ahead, s.obs.dtype))
    s = task_env.with_goal(s.replace(physics=s.physics.replace(qpos=qpos)), s.desired_goal)
    step = jitted_step(task_env)
    ours = [np.asarray(s.obs[:5])]
    for x in seq:
        s = step(s, jnp.asarray(x, jnp.float32))
        ours.append(np.asarray(s.obs[:5]))
    ours, ref = np.array(ours, np.float64), np.array(ref, np.float64)
    disp = lambda p, sl: np.linalg.norm(np.diff(p[:, sl], axis=0), axis=-1).tolist()  # noqa: E731
    return {"action": a.tolist(), "gap": gap, "hold": hold, "release": release,
            "ours_grip_step": disp(ours, slice(0, 2)), "fetch_grip_step": disp(ref, slice(0, 2)),
            "ours_object_step": disp(ours, slice(3, 5)), "fetch_object_step": disp(ref, slice(3, 5))}  # fmt: skip


RESPONSE_KEYS = ("ours_step", "fetch_step", "ours_rest_step", "fetch_rest_step")
