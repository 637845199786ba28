"""``reference/push_contact.py``'s scripted pushes (48 cases: 8 headings, 3 offsets, 2 speeds) in FetchPush-v4 and in
our Push model under a drive and gripper mass: whether the weld at the reference arm's mass, which presses on the
cube's top as the reference does (``press_probe.py``), still pushes as it.

    python experiments/results/2026-11-30/push-on-top/push_travel.py [--drive weld --gripper-mass 12.5]
"""

from __future__ import annotations

import argparse
import os
import sys

import mujoco
import numpy as np

ROOT = os.path.join(os.path.dirname(__file__), "..", "..", "..", "..")
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "experiments", "reference"))
sys.path.insert(0, os.path.dirname(__file__))

import push_contact as pc  # noqa: E402
from press_probe import our_push  # noqa: E402

from envs.fetch import models  # noqa: E402


def our_pushes(drive: str, gripper_mass: float | None) -> np.ndarray:
    p = our_push(drive, gripper_mass)
    m, d, o = p.m, p.d, p.object_q
    out = []
    for angle, side, speed in pc.CASES:
        mujoco.mj_resetData(m, d)
        xy, ahead = pc._start(p.home[:2], angle, side)
        d.qpos[o : o + 7] = [*xy, p.rest, 1.0, 0.0, 0.0, 0.0]
        mujoco.mj_forward(m, d)
        for t in range(pc.HOLD + pc.RELEASE):
            a = speed * ahead if t < pc.HOLD else np.zeros(2)
            p.step(np.array([*a, 0.0]))
        out.append([*(d.qpos[o : o + 2] - xy), pc._yaw(d.qpos[o + 3 : o + 7])])
    return np.array(out)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--drive", default="pd", choices=models.DRIVES)
    p.add_argument("--gripper-mass", type=float, default=None)
    args = p.parse_args(argv)
    ref, ours = pc.reference_pushes(), our_pushes(args.drive, args.gripper_mass)
    speed = np.array([c[2] for c in pc.CASES])
    travel = lambda r: np.linalg.norm(r[:, :2], axis=1)  # noqa: E731
    print(f"drive={args.drive} gripper_mass={args.gripper_mass}: FetchPush-v4 travel {travel(ref).mean():.4f} m")
    for v in sorted(set(speed), reverse=True):
        k = speed == v
        apart = np.linalg.norm(ours[k, :2] - ref[k, :2], axis=1)
        turn, ref_turn = np.abs(ours[k, 2]).mean(), np.abs(ref[k, 2]).mean()
        print(f"  speed {v}: travel {(travel(ours)[k] - travel(ref)[k]).mean():+.4f} m against the reference's, end "
              f"points {apart.mean():.4f} m apart, |turn| {turn:.3f} ({ref_turn:.3f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
