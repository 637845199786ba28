"""How stiffly FetchSlide-v4's hand holds its pitch: the turn a torque, or a push up at the grip site (a pressed
puck's reaction), adds to its tilt at each reach. Our pads pitch kinematically (``envs/fetch/hand_pitch.py``): held
at the tilt the reach sets, whatever the load.

    python experiments/reference/hand_compliance.py --out FILE.json

Per reach (the grip driven out ``k`` steps at full action 5 cm above the table, the puck put away, then held still
for ``SETTLE`` steps), the hand is loaded for ``HOLD`` steps with zero action: a torque about the horizontal axis
across the radial direction (``TORQUES``, N m), or an upward force at the grip site (``PUSHES``, N). Reported: the
hand's pitch (degrees, the initially vertical axis's lean along the radial direction) when the load starts, and what
the load adds to the pitch after ``HOLD`` steps against the same steps unloaded (held still, the stretched arm folds
back and its hand rights itself: ``relaxed``); for the torques, the stiffness (N m per radian) from the two signs.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", ".."))

from slide_on_puck import place_puck  # noqa: E402

from envs.fetch.control import ARM_REACH_CENTER  # noqa: E402
from splid_jax.reference.extra import import_reference, make_reference  # noqa: E402

CENTER = np.asarray(ARM_REACH_CENTER["slide"])
OUT_STEPS = (0, 4, 8, 10, 12, 14)
SETTLE, HOLD = 8, 6
TORQUES = (-20.0, -5.0, 5.0, 20.0)
PUSHES = (200.0, 1000.0, 3000.0)
PUCK_AWAY = (-0.3, -0.3)


class Arm:
    def __init__(self, task_env):
        import mujoco

        self.mj, self.task_env = mujoco, task_env
        self.env = make_reference("slide")
        u = self.env.unwrapped
        self.m, self.d = u.model, u.data
        self.hand = mujoco.mj_name2id(self.m, mujoco.mjtObj.mjOBJ_BODY, "robot0:gripper_link")
        self.grip = mujoco.mj_name2id(self.m, mujoco.mjtObj.mjOBJ_SITE, "robot0:grip")

    def start(self, k: int):
        place_puck(self.task_env, self.env, PUCK_AWAY)
        start = self.d.xmat[self.hand].reshape(3, 3)
        self.axis = int(np.argmax(np.abs(start[2])))
        self.sign = np.sign(start[2, self.axis])
        for a in [(0, 0, 1, 0)] + [(1, 0, 0, 0)] * k + [(0, 0, 0, 0)] * SETTLE:
            self.env.step(np.asarray(a, np.float64))

    def pitch(self) -> tuple[float, float, np.ndarray]:
        """(reach, pitch in degrees, the radial unit vector)."""
        v = self.d.xmat[self.hand].reshape(3, 3)[:, self.axis] * self.sign
        off = self.d.site_xpos[self.grip] - CENTER
        radial = off[:2] / np.linalg.norm(off[:2])
        return float(np.linalg.norm(off)), float(np.degrees(np.arctan2(v[:2] @ radial, v[2]))), radial

    def load(self, torque: float = 0.0, push: float = 0.0) -> float:
        """The pitch after ``HOLD`` still steps under the load (applied at the hand's centre of mass)."""
        _, _, radial = self.pitch()
        across = np.array([-radial[1], radial[0], 0.0])  # z x radial: turning about it leans the top outward
        f = np.array([0.0, 0.0, push])
        arm = self.d.site_xpos[self.grip] - self.d.xipos[self.hand]
        self.d.xfrc_applied[self.hand] = np.concatenate([f, torque * across + np.cross(arm, f)])
        for _ in range(HOLD):
            self.env.step(np.zeros(4))
        self.d.xfrc_applied[self.hand] = 0.0
        return self.pitch()[1]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", required=True)
    args = p.parse_args(argv)
    import envs

    import_reference()
    arm = Arm(envs.make("slide"))
    rows = []
    for k in OUT_STEPS:
        arm.start(k)
        reach, start, _ = arm.pitch()
        still = arm.load()
        row = {"out_steps": k, "reach": round(reach, 4), "pitch": round(start, 2), "relaxed": round(still - start, 2),
               "torque": {}, "push": {}}  # fmt: skip
        for t in TORQUES:
            arm.start(k)
            row["torque"][t] = round(arm.load(torque=t) - still, 3)
        for f in PUSHES:
            arm.start(k)
            row["push"][f] = round(arm.load(push=f) - still, 3)
        d = row["torque"][TORQUES[-1]] - row["torque"][TORQUES[0]]
        row["stiffness_nm_per_rad"] = round((TORQUES[-1] - TORQUES[0]) / np.radians(d), 1) if d else None
        rows.append(row)
        print(row, flush=True)
    with open(args.out, "w") as f:
        json.dump({"rows": rows}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
