"""How far a gripper pressed on the table moves per control step, in ``FetchPush-v4`` and in our Push
model with the finger-table contact (MuJoCo C, our control rule ``control.gripper_target``), for each
press depth given: the measurement that chose ``models.FINGER_PRESS``.

    PYTHONPATH=. python experiments/reference/finger_drag.py --press 0.02 0.025 0.03
"""

from __future__ import annotations

import argparse

import mujoco
import numpy as np

from envs.fetch import control, models
from splid_jax.reference.extra import make_reference

ACTIONS = {"a_y = 1": (0, 1, 0), "a_y = 1, a_z = -0.3": (0, 1, -0.3), "a_y = 1, a_z = -1": (0, 1, -1),
           "a_x = 1, a_z = -1": (1, 0, -1)}  # fmt: skip
STEPS = 8
SUBSTEPS = 10  # the tasks' 10 substeps of 4 ms


def reference_path(action) -> np.ndarray:
    env = make_reference("push")
    o, _ = env.reset(seed=0)
    path = [o["observation"][:3]]
    for _ in range(STEPS):
        o, *_ = env.step(np.array([*action, 0.0]))
        path.append(o["observation"][:3])
    env.close()
    return np.array(path)


def our_path(action, friction: float, press: float) -> np.ndarray:
    m = mujoco.MjModel.from_xml_string(models.mjcf("push", timestep=0.004, finger_table=friction))
    d = mujoco.MjData(m)
    lo, hi = models.workspace_box("push", friction, press)
    home = m.body("gripper").pos.copy()  # the grip site when the gripper joints are 0
    g, o = m.joint("grip_x").qposadr[0], m.joint("object").qposadr[0]
    d.qpos[o : o + 3] = [1.6, 0.4, 0.425]  # the cube out of the way
    mujoco.mj_forward(m, d)
    path = [home + d.qpos[g : g + 3]]
    for _ in range(STEPS):
        d.ctrl[0:3] = control.gripper_target(d.qpos[g : g + 3].copy(), np.array(action, float), home, lo, hi,
                                            control.ARM_REACH_CENTER_DEFAULT)  # fmt: skip
        for _ in range(SUBSTEPS):
            mujoco.mj_step(m, d)
        path.append(home + d.qpos[g : g + 3])
    return np.array(path)


def per_step_mm(path: np.ndarray) -> float:
    """Mean x-y displacement per step over steps 3 to 8 (after the start-up), mm."""
    return float(np.linalg.norm(np.diff(path[:, :2], axis=0), axis=-1)[2:].mean() * 1000)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--press", type=float, nargs="+", default=[models.FINGER_PRESS], help="press depths, m")
    p.add_argument("--friction", type=float, default=1.0)
    args = p.parse_args()
    print("| action | FetchPush-v4 | " + " | ".join(f"ours, press {x:g}" for x in args.press) + " |")
    for name, action in ACTIONS.items():
        ours = [per_step_mm(our_path(action, args.friction, press)) for press in args.press]
        print(f"| {name} | {per_step_mm(reference_path(action)):.1f} | " + " | ".join(f"{x:.1f}" for x in ours) + " |")


if __name__ == "__main__":
    main()
