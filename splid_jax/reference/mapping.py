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
    starts = {"state": start, "object_xy": xy, "goal": goal}
    return starts if reference_env is None else shifted(starts, env, reference_env)


def shifted(starts: dict, env, reference_env) -> dict:
    """``our_starts``'s starts, given in our task's coordinates, moved into those of the reset ``reference_env``."""
    shift = reference_shift(env.evaluation_task(), reference_env)
    xy = None if starts["object_xy"] is None else starts["object_xy"] + shift[:2]
    return {**starts, "object_xy": xy, "goal": starts["goal"] + shift}


def save_starts(path: str, starts: dict) -> None:
    """The object x-y and goals of ``starts`` (our task's coordinates) as an npz, for a reference run elsewhere."""
    xy = {} if starts["object_xy"] is None else {"object_xy": starts["object_xy"]}
    np.savez(path, goal=starts["goal"], **xy)


def load_starts(path: str) -> dict:
    """What ``save_starts`` wrote: ``object_xy`` (None for Reach) and ``goal``, our task's coordinates."""
    with np.load(path) as f:
        return {"object_xy": f["object_xy"] if "object_xy" in f else None, "goal": f["goal"]}
