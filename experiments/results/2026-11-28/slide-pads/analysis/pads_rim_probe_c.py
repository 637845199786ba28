"""``pads_rim_probe.py``'s light press in MuJoCo C on our pads' Slide model (its MJCF, reset and control step, as
``experiments/parity/slide_c.py`` runs them): C's own box-cylinder and cylinder-plane contacts and solver with our
gripper and drive. Beside the MJX and FetchSlide-v4 rows of ``pads_rim_probe.py``, it tells whether the rim's
difference lies in MJX's contacts or in the model (gripper and drive) both of ours share.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/pads_rim_probe_c.py --dirs +x,diag \
        --offsets 0.015,0.02 [--timestep 0.002 --substeps 20] [--gripper-mass 12.5] [--table box] [--out OUT.json]

``--table box``: the table's top as the reference's box (C's cylinder-box contact, as FetchSlide-v4's puck stands)
instead of our plane.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, *[".."] * 5)]

from pads_rim_probe import DIRS, actions, measures, trace  # noqa: E402

OPTIONS = {"finger": "pads", "finger_table": 1.0, "drive": "weld", "gripper_mass": 22.0}


def box_table(xml: str) -> str:
    """Our Slide MJCF with the table's plane top replaced by the reference's table box (same pairs)."""
    from envs.fetch import models

    (tx, ty, tz), (hx, hy, hz), _ = models._SCENES["slide"]
    head = r'<geom name="table" type="plane" pos="[^"]*" size="[^"]*"'
    out, n = re.subn(head, f'<geom name="table" type="box" pos="{models._fmt(tx, ty, tz)}" '
                           f'size="{models._fmt(hx, hy, hz)}"', xml)  # fmt: skip
    if n != 1:
        raise ValueError("no plane table top in the MJCF")
    return out


def c_start(m: mujoco.MjModel, o: int, u, offset: float) -> tuple:
    """MuJoCo C's data with the puck at rest 0.04 + ``offset`` m from the grip home along ``u``; with the grip home
    and the workspace's bounds: ``(data, home, lo, hi)``."""
    from envs.fetch import models

    home = np.asarray(models._SCENES["slide"][2])
    lo, hi = models.workspace_box("slide", OPTIONS["finger_table"])
    d = mujoco.MjData(m)
    xy = home[:2] + (0.04 + offset) * np.asarray(u)
    d.qpos[o : o + 7] = [*xy, models.rest_height(m, o), 1, 0, 0, 0]
    mujoco.mj_forward(m, d)
    return d, home, lo, hi


def c_observation(m: mujoco.MjModel, d: mujoco.MjData, site: int, o: int) -> np.ndarray:
    """Observation slots 0:6 and 11:13 (grip, puck, puck Euler x and y) of MuJoCo C's state, the rest 0."""
    mujoco.mj_kinematics(m, d)
    obs = np.zeros(25)
    obs[0:3], obs[3:6] = d.site_xpos[site], d.qpos[o : o + 3]
    w, x, y, z = d.qpos[o + 3 : o + 7]
    obs[11] = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    obs[12] = np.arcsin(np.clip(2 * (w * y - z * x), -1, 1))
    return obs


def run_c(u, offset: float, acts: list, timestep: float | None, substeps: int | None, mass: float,
          table: str = "plane") -> np.ndarray:  # fmt: skip
    """Observation slots 0:6 and 11:13 (grip, puck, puck Euler x and y) per control step, [T + 1, 25]."""
    from envs.fetch import control, models
    from envs.fetch.tasks import Slide

    task = Slide(**{**OPTIONS, "gripper_mass": mass})
    opts = task.model_options()
    if timestep:
        opts["timestep"] = timestep
    xml = models.mjcf("slide", **opts)
    m = mujoco.MjModel.from_xml_string(box_table(xml) if table == "box" else xml)
    dt = task.timestep * task.substeps
    n_sub = substeps or task.substeps
    g, o = int(m.joint("grip_x").qposadr[0]), int(m.joint("object").qposadr[0])
    site = m.site("grip").id
    d, home, lo, hi = c_start(m, o, u, offset)
    out = []
    for t in range(len(acts) + 1):
        out.append(c_observation(m, d, site, o))
        if t == len(acts):
            break
        d.ctrl[0:3] = control.gripper_target(d.qpos[g : g + 3], np.asarray(acts[t][:3], float), home, lo, hi,
                                             control.ARM_REACH_CENTER["slide"])  # fmt: skip
        d.mocap_pos[0] = home + d.ctrl[0:3]
        for _ in range(n_sub if substeps else round(dt / m.opt.timestep)):
            mujoco.mj_step(m, d)
    return np.array(out)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--press", type=float, default=-0.25)
    p.add_argument("--drag", type=float, default=0.5)
    p.add_argument("--dirs", default="+x,diag")
    p.add_argument("--offsets", default="0.015,0.02,0.025")
    p.add_argument("--timestep", type=float, default=None, help="default: the task's")
    p.add_argument("--substeps", type=int, default=None, help="default: the task's control step over the timestep")
    p.add_argument("--gripper-mass", type=float, default=OPTIONS["gripper_mass"])
    p.add_argument("--table", choices=("plane", "box"), default="plane")
    p.add_argument("--trace", action="store_true")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    rows = []
    for name in args.dirs.split(","):
        u = np.asarray(DIRS[name])
        acts = actions(u, args.press, args.drag)
        for offset in (float(v) for v in args.offsets.split(",")):
            x = run_c(u, offset, acts, args.timestep, args.substeps, args.gripper_mass, args.table)
            row = {"dir": name, "offset": offset, "c_ours_model": measures(x, u)}
            if args.trace:
                row["c_ours_model"]["trace"] = trace(x, u)
            rows.append(row)
            print(name, offset, json.dumps(row["c_ours_model"]), flush=True)
    if args.out:
        head = {"options": {**OPTIONS, "gripper_mass": args.gripper_mass}, "timestep": args.timestep,
                "substeps": args.substeps, "table": args.table}  # fmt: skip
        with open(args.out, "w") as fh:
            json.dump({**head, "rows": rows}, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
