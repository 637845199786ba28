"""The gripper target each control step sets: ``TARGET_STEP`` per unit action from where the gripper is, clipped to
the task's workspace box, then kept within the reference arm's reach. The one rule of the tasks and of the MuJoCo
C replicas in ``experiments/``."""

from __future__ import annotations

import numpy as np

# The reference arm's reach (experiments/parity/arm_reach.py). Its grip site, pulled by the mocap weld
# toward a target out of reach, stops on a sphere around a point near the shoulder (36 stops per robot
# placement fit it to 0.7 mm), and slows as the arm straightens: near the sphere it gains at most about
# ARM_STRETCH_GAIN * sqrt(distance left) outward per control step, as a two-link arm near full
# extension does. FetchSlide stands the robot 0.355 m further back than the other tasks, so only
# Slide's goals (x up to 1.71) lie beyond it: its gripper reaches x 1.39 at table height.
ARM_REACH_RADIUS = 1.126
ARM_REACH_CENTER = {"slide": (0.319, 0.744, 0.781)}
ARM_REACH_CENTER_DEFAULT = (0.674, 0.744, 0.781)
ARM_STRETCH_GAIN = 0.10  # m^0.5 per control step: the target's outward step is capped at this * sqrt(R - r)
# Held still near its reach, the reference arm folds back: with zero action its grip drifts toward the reach centre
# along the floor by these metres per control step at these distances from the centre, none below the first
# (experiments/reference/stretch_speed.py, drives out then held, MuJoCo 3.17.0). Our gripper stays where it is put;
# its target moved back by 1.5 x these (the task field arm_drift) gives the reference's drift, since our weld covers
# about two thirds of a target's step in a control step (stretch_speed.py --fit). A drive outward is left to the
# stretch cap, which was fit on such drives: the drift shrinks with the action's outward share.
DRIFT_REACH = (0.89, 0.925, 0.975, 1.025, 1.075, 1.125)
DRIFT = (0.0, 0.0021, 0.0039, 0.0070, 0.0114, 0.0171)
WORKSPACES = ("arm", "box")
TARGET_STEP = 0.05  # metres of gripper target motion per unit action per control step


def within_reach(grip, target, center, radius=ARM_REACH_RADIUS, stretch_gain=ARM_STRETCH_GAIN, xp=np):
    """The gripper target (world xyz, [..., 3]) the reference arm would follow from ``grip``: its step
    away from ``center`` capped at ``stretch_gain * sqrt(radius - r)`` (r: the grip's distance from
    ``center``), then moved onto the ball of ``radius`` if outside it. ``xp``: numpy or jax.numpy."""
    center = xp.asarray(center)
    off = grip - center
    r = xp.sqrt(xp.sum(off * off, axis=-1, keepdims=True))
    n = off / xp.maximum(r, 1e-9)
    outward = xp.sum((target - grip) * n, axis=-1, keepdims=True)
    cap = stretch_gain * xp.sqrt(xp.maximum(radius - r, 0.0))
    target = target - n * xp.maximum(outward - cap, 0.0)
    off = target - center
    dist = xp.sqrt(xp.sum(off * off, axis=-1, keepdims=True))
    return center + off * xp.minimum(1.0, radius / xp.maximum(dist, 1e-9))


def gripper_target(q, action_xyz, home, lo, hi, reach_center=None, stretch_gain=ARM_STRETCH_GAIN, xp=np, drift=0.0):
    """The xyz drive's next target in the gripper joints' coordinates (grip site = ``home`` + ``q``), as
    each control step sets it: ``TARGET_STEP * action_xyz`` from where the gripper is, clipped to the
    world box [``lo``, ``hi``], then kept within the reference arm's reach around ``reach_center``
    (``within_reach``) unless that is None; ``drift`` > 0 moves it that many times ``DRIFT`` toward the centre in
    x-y, less the action's outward share. The one rule of the tasks and of the C replicas."""
    home = xp.asarray(home)
    target = xp.clip(q + TARGET_STEP * action_xyz, xp.asarray(lo) - home, xp.asarray(hi) - home)
    if reach_center is not None:
        target = within_reach(q + home, target + home, reach_center, stretch_gain=stretch_gain, xp=xp) - home
    if drift and reach_center is not None:
        off = q + home - xp.asarray(reach_center)
        flat = xp.concatenate([off[..., :2], 0.0 * off[..., 2:]], axis=-1)
        u = flat / xp.maximum(xp.sqrt(xp.sum(flat * flat, axis=-1, keepdims=True)), 1e-9)
        lead = xp.clip(xp.sum(action_xyz * u, axis=-1), 0.0, 1.0)  # a drive outward: the cap alone slows it
        r = xp.sqrt(xp.sum(off * off, axis=-1))
        back = drift * (1.0 - lead) * xp.interp(r, xp.asarray(DRIFT_REACH), xp.asarray(DRIFT))
        target = target - u * back[..., None]
    return target
