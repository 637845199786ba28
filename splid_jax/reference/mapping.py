"""Matched starts between the two simulators: our task's sampled start moved into the reference's
coordinates, and the reference put there after its own reset (the observation and action mapping is
in this package's docstring)."""

from __future__ import annotations

import numpy as np


def reference_start(env, object_xy: np.ndarray | None, goal: np.ndarray) -> dict:
    """Put the reference env (already ``reset``) at a start given in its own coordinates: the object's
    x-y (its height, orientation and the gripper stay as its reset left them) and the goal. Returns
    its observation dict."""
    import mujoco

    u = env.unwrapped
    if object_xy is not None:
        from gymnasium_robotics.utils import mujoco_utils

        q = mujoco_utils.get_joint_qpos(u.model, u.data, "object0:joint")
        q[:2] = object_xy
        mujoco_utils.set_joint_qpos(u.model, u.data, "object0:joint", q)
        mujoco_utils.set_joint_qvel(u.model, u.data, "object0:joint", np.zeros(6))
    u.goal = np.asarray(goal, np.float64).copy()
    mujoco.mj_forward(u.model, u.data)
    return u._get_obs()


def reference_shift(env, reference_env) -> np.ndarray:
    """What moves a point of our task ``env`` into the coordinates of the reset ``reference_env``: x-y by the
    difference of the two grip homes; z by that of the object rest heights (tasks with an object: goals sit on
    the table or a lift above it) or of the grip homes (Reach)."""
    u, lay = reference_env.unwrapped, env.layout
    shift = np.asarray(u.initial_gripper_xpos[:3], np.float64) - np.asarray(lay.grip_home)
    if env.has_object:
        shift[2] = float(u.height_offset) - lay.object_rest_z
    return shift


def our_starts(env, key, episodes: int, reference_env=None):
    """Our task's starts (``jax.vmap(env.reset)`` of ``episodes`` keys split from ``key``, as the
    project's evaluation draws them): ``state``, and the object x-y and goal for ``reference_start``.
    Given a reset reference env, these are moved into its coordinates (``reference_shift``)."""
    import jax

    env = env.evaluation_task()  # judged from the standard starts, whatever the run trained from
    start = jax.vmap(env.reset)(jax.random.split(key, episodes))
    goal = np.asarray(start.desired_goal, np.float64)
    xy = np.asarray(start.achieved_goal[:, :2], np.float64) if env.has_object else None
    if reference_env is not None:
        shift = reference_shift(env, reference_env)
        if env.has_object:
            xy = xy + shift[:2]
        goal = goal + shift
    return {"state": start, "object_xy": xy, "goal": goal}
