"""How long Push's gripper stays on the cube's top face when it presses down there, in FetchPush-v4 and in our Push
model (MuJoCo C, our control rule): the gripper is lifted, the cube put under it so that the grip lies ``across`` m
from the cube's centre along a heading, then the gripper is driven straight down (action z ``-press``) for ``STEPS``
control steps. Per case: the steps it stays on the top (the grip 3 to 5.5 cm above the cube's centre and within
5 cm of it across) before it first leaves, and how far the cube moved.

    python experiments/results/2026-11-30/push-on-top/press_probe.py --press 0.3 [--drive weld --gripper-mass 12.5]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable
from typing import NamedTuple

import mujoco
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))
sys.path.insert(0, os.path.dirname(__file__))

from on_top import grip_on_top  # noqa: E402

from envs.fetch import control, models  # noqa: E402
from splid_jax.reference.extra import make_reference  # noqa: E402

STEPS, LIFT, SUBSTEPS = 15, 2, 10
HEADINGS = np.arange(8) * np.pi / 4
ACROSS = (0.02, 0.03, 0.035, 0.04, 0.045)


class OurPush(NamedTuple):
    """Our Push model in MuJoCo C, driven by our control rule."""

    m: mujoco.MjModel
    d: mujoco.MjData
    home: np.ndarray  # the grip site when the gripper joints are 0
    grip_q: int  # qpos address of the gripper's x slide
    object_q: int  # qpos address of the cube's free joint
    rest: float  # the cube's centre height at rest
    step: Callable[[np.ndarray], None]  # one control step at action xyz


def our_push(drive: str = "pd", gripper_mass: float | None = None) -> OurPush:
    xml = models.mjcf("push", timestep=0.004, finger="pads", finger_table=1.0, drive=drive, gripper_mass=gripper_mass)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    lo, hi = models.workspace_box("push", 1.0)
    home = m.body("gripper").pos.copy()
    g, o = m.joint("grip_x").qposadr[0], m.joint("object").qposadr[0]
    mujoco.mj_forward(m, d)

    def step(a):
        d.ctrl[0:3] = control.gripper_target(d.qpos[g : g + 3].copy(), np.asarray(a), home, lo, hi,
                                            control.ARM_REACH_CENTER_DEFAULT)  # fmt: skip
        if drive == "weld":  # the constraint pulls the gripper to the mocap body, put at the target
            d.mocap_pos[0] = home + d.ctrl[0:3]
        for _ in range(SUBSTEPS):
            mujoco.mj_step(m, d)

    return OurPush(m, d, home, g, o, models.rest_height(m, o), step)


def stay(trace) -> int:
    n = 0
    for grip, cube in trace:
        if not grip_on_top(grip, cube):
            break
        n += 1
    return n


def reference_case(env, heading, across, press):
    from gymnasium_robotics.utils import mujoco_utils

    env.reset(seed=0)
    u = env.unwrapped
    for _ in range(LIFT):
        o, *_ = env.step(np.array([0.0, 0.0, 0.6, 0.0]))
    grip = o["observation"][:3]
    q = mujoco_utils.get_joint_qpos(u.model, u.data, "object0:joint").copy()
    q[:2] = grip[:2] - across * np.array([np.cos(heading), np.sin(heading)])
    q[3:7] = [1, 0, 0, 0]
    mujoco_utils.set_joint_qpos(u.model, u.data, "object0:joint", q)
    mujoco_utils.set_joint_qvel(u.model, u.data, "object0:joint", np.zeros(6))
    mujoco.mj_forward(u.model, u.data)
    start, trace = q[:2].copy(), []
    for _ in range(STEPS):
        o, *_ = env.step(np.array([0.0, 0.0, -press, 0.0]))
        trace.append((o["observation"][:3].copy(), o["observation"][3:6].copy()))
    return stay(trace), float(np.linalg.norm(trace[-1][1][:2] - start))


def our_case(heading, across, press, drive="pd", gripper_mass=None):
    p = our_push(drive, gripper_mass)
    m, d, g, o = p.m, p.d, p.grip_q, p.object_q
    d.qpos[o : o + 7] = [p.home[0] + 0.3, p.home[1] + 0.3, p.rest, 1, 0, 0, 0]
    for _ in range(LIFT):
        p.step([0.0, 0.0, 0.6])
    grip = p.home + d.qpos[g : g + 3]
    xy = grip[:2] - across * np.array([np.cos(heading), np.sin(heading)])
    d.qpos[o : o + 7] = [*xy, p.rest, 1, 0, 0, 0]
    d.qvel[m.joint("object").dofadr[0] : m.joint("object").dofadr[0] + 6] = 0
    mujoco.mj_forward(m, d)
    trace = []
    for _ in range(STEPS):
        p.step([0.0, 0.0, -press])
        trace.append((p.home + d.qpos[g : g + 3], d.qpos[o : o + 3].copy()))
    return stay(trace), float(np.linalg.norm(trace[-1][1][:2] - xy))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--press", type=float, nargs="+", default=[0.3, 1.0])
    p.add_argument("--drive", default="pd", choices=models.DRIVES, help="our side's drive")
    p.add_argument("--gripper-mass", type=float, default=None, help="our side's gripper mass (kg; default the task's)")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    env = make_reference("push")
    rows = {}
    for press in args.press:
        for across in ACROSS:
            ref = [reference_case(env, h, across, press) for h in HEADINGS]
            ours = [our_case(h, across, press, args.drive, args.gripper_mass) for h in HEADINGS]
            rows[f"{press},{across}"] = {"reference": ref, "ours": ours}
            print(f"press {press} across {across}: stays ref {[s for s, _ in ref]} ours {[s for s, _ in ours]}; "
                  f"cube moved ref {np.mean([c for _, c in ref]):.3f} ours {np.mean([c for _, c in ours]):.3f}")
    if args.out:
        with open(args.out, "w") as f:
            json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
