"""Where FetchSlide-v4's hand tilt under ``pads_rim_probe.py``'s light press comes from: the same actions with the
puck under the pads, with the puck far away (the pads come down on the table), and with the puck far away and no
press (the hand moved in the air). Per control step: the gripper link's rotation from its start (rotation vector,
world frame, degrees) and its tilt (the angle of its rotated vertical), and the weld's orientation error (the link
from its mocap target), and how many contacts the puck has with the table (C's multi-point cylinder-box).

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/hand_tilt_reference.py --out OUT.json
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, *[".."] * 5)]

from pads_rim_probe import DIRS, actions  # noqa: E402

CASES = (("diag", 0.0125, "puck"), ("diag", 0.0175, "puck"), ("+x", 0.02, "puck"), ("diag", 0.0175, "no_puck"),
         ("diag", 0.0175, "air"), ("+x", 0.02, "no_puck"), ("+x", 0.02, "air"))  # fmt: skip


def rotvec_deg(rel: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, rel.reshape(9))
    v = np.zeros(3)
    mujoco.mju_quat2Vel(v, q, 1.0)
    return np.degrees(v)


def run(u, offset: float, case: str, press: float, drag: float) -> dict:
    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_start

    r = make_reference("slide")
    r.reset(seed=0)
    e = r.unwrapped
    m, d = e.model, e.data
    link = m.body("robot0:gripper_link").id
    pair = {m.geom("object0").id, m.geom("table0").id}
    xy = np.asarray(e.initial_gripper_xpos[:2]) + (0.04 + offset) * np.asarray(u)
    if case != "puck":  # the puck 0.2 m across the path, out of reach
        xy = xy + 0.2 * np.array([-u[1], u[0]])
    reference_start(r, xy, np.asarray(e.goal))
    acts = actions(u, 0.0 if case == "air" else press, drag)
    if case == "air":  # come down one step less: the pads stay 5 cm above the table
        acts = [(0, 0, 0, 0) if i == 4 else a for i, a in enumerate(acts)]
    rot0 = d.xmat[link].reshape(3, 3).copy()
    rot, tilt, err, z, support = [], [], [], [], []
    for a in acts:
        r.step(np.asarray(a, np.float64))
        rel = d.xmat[link].reshape(3, 3) @ rot0.T
        rot.append(rotvec_deg(rel).round(2).tolist())
        tilt.append(round(float(np.degrees(np.arccos(min(1.0, rel[2, 2])))), 2))
        mq = np.zeros(9)
        mujoco.mju_quat2Mat(mq, d.mocap_quat[0] / np.linalg.norm(d.mocap_quat[0]))
        err.append(round(float(np.linalg.norm(rotvec_deg(d.xmat[link].reshape(3, 3) @ mq.reshape(3, 3).T))), 2))
        z.append(round(float(e._utils.get_site_xpos(m, d, "robot0:grip")[2]), 4))
        support.append(sum({int(c.geom1), int(c.geom2)} == pair for c in d.contact[: d.ncon]))
    r.close()
    return {"tilt_deg": tilt, "rotvec_deg": rot, "weld_rot_error_deg": err, "grip_z": z, "puck_table_contacts": support,
            "tilt_deg_max_dragging": max(tilt[9:18]), "tilt_deg_max_pressing": max(tilt[6:10])}  # fmt: skip


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--press", type=float, default=-0.25)
    p.add_argument("--drag", type=float, default=0.5)
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    from splid_jax.reference.extra import import_reference

    import_reference()
    rows = []
    for name, offset, case in CASES:
        res = run(np.asarray(DIRS[name]), offset, case, args.press, args.drag)
        rows.append({"dir": name, "offset": offset, "case": case, **res})
        print(name, offset, case, "tilt", res["tilt_deg"], flush=True)
    if args.out:
        with open(args.out, "w") as fh:
            json.dump({"press": args.press, "drag": args.drag, "rows": rows}, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
