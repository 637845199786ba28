"""How far and how straight a push moves the cube, in ``FetchPush-v4`` and in our Push model (MuJoCo C, our
control rule ``control.gripper_target``), for each closed-finger shape given: the measurement that chose
Push's ``finger="pads"``. From each one's home the cube is put ``GAP`` ahead of the grip along a direction
(8 of them), shifted sideways by an offset, and pushed ``HOLD`` steps at two speeds, then left ``RELEASE``
steps; per shape and speed, the mean over the cases of the cube's travel against the reference's, of the
distance between the two simulators' end points, and of the cube's turn about z (rad).

    PYTHONPATH=. python experiments/reference/push_contact.py --finger box pads
"""

from __future__ import annotations

import argparse

import mujoco
import numpy as np

from envs.fetch import control, models
from envs.fetch.rotations import quat_to_euler
from splid_jax.reference.extra import make_reference
from splid_jax.reference.mapping import reference_start

GAP = 0.05
HOLD, RELEASE = 3, 8
SUBSTEPS = 10  # the tasks' 10 substeps of 4 ms
CASES = [(np.pi / 4 * k, side, speed) for k in range(8) for side in (-0.015, 0.0, 0.015) for speed in (1.0, 0.5)]


def _start(home_xy, angle, side):
    ahead, across = np.array([np.cos(angle), np.sin(angle)]), np.array([-np.sin(angle), np.cos(angle)])
    return home_xy + GAP * ahead + side * across, ahead


def _yaw(quat) -> float:
    return float(quat_to_euler(np.asarray(quat))[2])


def reference_pushes() -> np.ndarray:
    """[cases, 3]: the cube's x-y displacement and turn about z."""
    env = make_reference("push")
    from gymnasium_robotics.utils import mujoco_utils

    out = []
    for angle, side, speed in CASES:
        o, _ = env.reset(seed=0)
        xy, ahead = _start(o["observation"][:2], angle, side)
        o = reference_start(env, xy, o["desired_goal"])
        first = o["observation"][3:5].copy()
        for t in range(HOLD + RELEASE):
            a = speed * ahead if t < HOLD else np.zeros(2)
            o, *_ = env.step(np.array([*a, 0.0, 0.0]))
        u = env.unwrapped
        q = mujoco_utils.get_joint_qpos(u.model, u.data, "object0:joint")
        out.append([*(o["observation"][3:5] - first), _yaw(q[3:7])])
    env.close()
    return np.array(out)


def our_pushes(finger: str) -> np.ndarray:
    m = mujoco.MjModel.from_xml_string(models.mjcf("push", timestep=0.004, finger=finger, finger_table=1.0))
    d = mujoco.MjData(m)
    lo, hi = models.workspace_box("push", 1.0)
    home = m.body("gripper").pos.copy()  # the grip site when the gripper joints are 0
    g, o = m.joint("grip_x").qposadr[0], m.joint("object").qposadr[0]
    rest = models.rest_height(m, o)
    out = []
    for angle, side, speed in CASES:
        mujoco.mj_resetData(m, d)
        xy, ahead = _start(home[:2], angle, side)
        d.qpos[o : o + 7] = [*xy, rest, 1.0, 0.0, 0.0, 0.0]
        mujoco.mj_forward(m, d)
        for t in range(HOLD + RELEASE):
            a = speed * ahead if t < HOLD else np.zeros(2)
            d.ctrl[0:3] = control.gripper_target(d.qpos[g : g + 3].copy(), np.array([*a, 0.0]), home, lo, hi,
                                                control.ARM_REACH_CENTER_DEFAULT)  # fmt: skip
            for _ in range(SUBSTEPS):
                mujoco.mj_step(m, d)
        out.append([*(d.qpos[o : o + 2] - xy), _yaw(d.qpos[o + 3 : o + 7])])
    return np.array(out)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--finger", nargs="+", default=list(models.fingers_for("push")), choices=models.fingers_for("push"))
    args = p.parse_args()
    ref = reference_pushes()
    speed = np.array([c[2] for c in CASES])
    travel = lambda r: np.linalg.norm(r[:, :2], axis=1)  # noqa: E731
    print(f"{len(CASES)} pushes; FetchPush-v4: travel {travel(ref).mean():.4f} m")
    for finger in args.finger:
        ours = our_pushes(finger)
        for v in sorted(set(speed), reverse=True):
            k = speed == v
            apart = np.linalg.norm(ours[k, :2] - ref[k, :2], axis=1)
            print(f"finger={finger} speed {v}: travel {(travel(ours)[k] - travel(ref)[k]).mean():+.4f} m against "
                  f"the reference's, end points {apart.mean():.4f} m apart, |turn| {np.abs(ours[k, 2]).mean():.3f} "
                  f"({np.abs(ref[k, 2]).mean():.3f})")  # fmt: skip


if __name__ == "__main__":
    main()
