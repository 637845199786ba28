"""How far the gripper reaches, on both sides: the reference's arm against our reach ball.

The reference moves its gripper through a 7-joint arm pulled by a mocap weld; the gripper slows as
the arm straightens and stops short of a target beyond the arm's reach. Ours has no arm: its xyz drive
reaches any target in the workspace box, and ``workspace="arm"`` (the default) keeps each target
within the reach this script measures (``envs.fetch.control.within_reach`` and ``ARM_REACH_*``).

Per robot placement (FetchSlide stands the robot 0.355 m further back than Push, PickAndPlace and
Reach, which share one), the gripper is driven for 60 control steps at full action toward 36 far
targets (4 heights, 9 azimuths). The points where it stops are fit by a sphere (least squares), and
its paths there are compared step by step between the sides.

    # the reference (its own environment, see README.md): about 40 s
    experiments/parity/.venv-ref/bin/python experiments/parity/arm_reach.py --side reference \\
        --out experiments/parity/results/arm_reach_reference.json
    # ours, our models and control rule in MuJoCo C: a few seconds
    python experiments/parity/arm_reach.py --side ours --out experiments/parity/results/arm_reach_ours.json
    # the stretch gain: ours' Slide paths against the reference's for a range of gains (about a minute)
    python experiments/parity/arm_reach.py --fit-stretch experiments/parity/results/arm_reach_reference.json
    # side by side, as markdown
    python experiments/parity/arm_reach.py --summary experiments/parity/results/arm_reach_reference.json \\
        experiments/parity/results/arm_reach_ours.json
"""

from __future__ import annotations

import argparse
import datetime
import json
import platform
import sys
from pathlib import Path

import mujoco
import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(1, str(ROOT))  # envs, for our side only

HEIGHTS = (0.42, 0.45, 0.5, 0.6)
AZIMUTHS_DEG = tuple(range(-40, 41, 10))
STEPS = 60
PLACEMENTS = {"slide": "FetchSlide-v4", "push": "FetchPush-v4"}  # our kind: the reference env


def targets(start_xy):
    """Far targets: 1 m from the gripper's start, at each height and azimuth (0 = +x, away from the robot)."""
    out = []
    for z in HEIGHTS:
        for deg in AZIMUTHS_DEG:
            a = np.radians(deg)
            out.append([start_xy[0] + np.cos(a), start_xy[1] + np.sin(a), z])
    return np.array(out)


def fit_sphere(points):
    """Least-squares sphere through ``points`` [n, 3]: ``(center, radius, max |residual|)``."""
    p = np.asarray(points, float)
    a = np.c_[2 * p, np.ones(len(p))]
    sol = np.linalg.lstsq(a, (p**2).sum(1), rcond=None)[0]
    center = sol[:3]
    radius = float(np.sqrt(sol[3] + center @ center))
    return center, radius, float(np.abs(np.linalg.norm(p - center, axis=1) - radius).max())


def run_reference() -> dict:
    import gymnasium_robotics
    import run_reference as rr

    out = {}
    for kind, env_id in PLACEMENTS.items():
        env = rr.make_env(env_id)
        m, d = env.unwrapped.model, env.unwrapped.data
        site = m.site("robot0:grip").id
        q = int(m.joint("object0:joint").qposadr[0])
        paths = []
        env.reset(seed=0)
        start = d.site_xpos[site].copy()
        for tgt in targets(start):
            env.reset(seed=0)
            d.qpos[q : q + 3] = [start[0] + 0.9, 1.45, 0.42]  # the object out of the way
            mujoco.mj_forward(m, d)
            path = []
            for _ in range(STEPS):
                env.step(np.r_[np.clip((tgt - d.site_xpos[site]) / 0.05, -1, 1), 0.0])
                path.append(d.site_xpos[site].copy())
            paths.append(path)
        env.close()
        out[kind] = _placement(start, paths)
    return _result("reference", out, {"gymnasium_robotics": gymnasium_robotics.__version__})


def run_ours(stretch_gain=None) -> dict:
    """Our model and control rule (``control.gripper_target``, as the tasks step) in MuJoCo C, 10 steps of 4 ms each;
    ``stretch_gain`` overrides ``control.ARM_STRETCH_GAIN``."""
    from envs.fetch import control, models

    gain = control.ARM_STRETCH_GAIN if stretch_gain is None else stretch_gain
    out = {}
    for kind in PLACEMENTS:
        m = mujoco.MjModel.from_xml_string(models.mjcf(kind, 0.004, 10, 4))
        lay = models.build(kind, timestep=0.004, iterations=10, ls_iterations=4)[2]
        home = np.asarray(lay.grip_home)
        g, site = lay.grip_q, m.site("grip").id
        d = mujoco.MjData(m)
        mujoco.mj_forward(m, d)
        start = d.site_xpos[site].copy()
        paths = []
        for tgt in targets(start):
            mujoco.mj_resetData(m, d)
            if lay.object_q is not None:
                d.qpos[lay.object_q : lay.object_q + 3] = [start[0] + 0.9, 1.45, 0.42]
            mujoco.mj_forward(m, d)
            path = []
            for _ in range(STEPS):
                a = np.clip((tgt - d.site_xpos[site]) / 0.05, -1, 1)
                d.ctrl[0:3] = control.gripper_target(d.qpos[g : g + 3], a, home, lay.workspace_lo, lay.workspace_hi,
                                                    lay.reach_center, gain)
                for _ in range(10):
                    mujoco.mj_step(m, d)
                path.append(d.site_xpos[site].copy())
            paths.append(path)
        out[kind] = _placement(start, paths)
    return _result("ours", out, {"mujoco": mujoco.__version__, "stretch_gain": gain})


def fit_stretch(reference: dict, gains) -> str:
    """How far ours' Slide paths lie from the reference's for each stretch gain: the pick is the least RMS."""
    ref = np.asarray(reference["placements"]["slide"]["paths"])
    rows = ["| stretch gain (m^0.5 per step) | Slide path distance, RMS (cm) |", "|---:|---:|"]
    for g in gains:
        ours = np.asarray(run_ours(g)["placements"]["slide"]["paths"])
        rms = 100 * np.sqrt((np.linalg.norm(ours - ref, axis=-1) ** 2).mean())
        rows.append(f"| {g:g} | {rms:.2f} |")
    return "\n".join(rows)


def _placement(start, paths) -> dict:
    paths = np.asarray(paths)  # [target, step, xyz]
    stops = paths[:, -1]
    center, radius, resid = fit_sphere(stops)
    table = stops[np.abs(stops[:, 2] - HEIGHTS[0]) < 0.03]  # the lowest row: at table height
    return {
        "grip_start": np.round(start, 4).tolist(),
        "paths": np.round(paths, 4).tolist(),
        "center": center.round(4).tolist(),
        "radius": round(radius, 4),
        "max_residual": resid,
        "max_x_at_table": float(table[:, 0].max()) if len(table) else None,
    }


def _result(side, placements, versions) -> dict:
    return {
        "side": side,
        "date": datetime.date.today().isoformat(),
        "machine": f"{platform.machine()}, {platform.system()}",
        "versions": versions,
        "command": " ".join([Path(sys.executable).name, *sys.argv]),
        "placements": placements,
    }


def summary(results: list[dict]) -> str:
    out = [
        "| side | placement | sphere centre (m) | radius (m) | max fit residual (mm) | furthest x at table height (m) "
        "|",
        "|---|---|---|---|---:|---:|",
    ]
    for r in results:
        for kind, p in r["placements"].items():
            c = ", ".join(f"{x:.3f}" for x in p["center"])
            out.append(f"| {r['side']} | {kind} | ({c}) | {p['radius']:.3f} | {1000 * p['max_residual']:.1f} | "
                       f"{p['max_x_at_table']:.3f} |")
    if len(results) == 2:  # the paths on the way there, step by step, ours against the reference's
        out += ["", "| placement | path distance, RMS over targets and steps (cm) | max (cm) "
                "| at the last step, max (cm) |", "|---|---:|---:|---:|"]
        for kind in results[0]["placements"]:
            a, b = (np.asarray(r["placements"][kind]["paths"]) for r in results)
            dist = np.linalg.norm(a - b, axis=-1)
            out.append(f"| {kind} | {100 * np.sqrt((dist**2).mean()):.2f} | {100 * dist.max():.2f} | "
                       f"{100 * dist[:, -1].max():.2f} |")
    return "\n".join(out)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--side", choices=("reference", "ours"))
    p.add_argument("--out")
    p.add_argument("--summary", nargs="+", metavar="JSON")
    p.add_argument("--fit-stretch", metavar="REFERENCE_JSON",
                   help="ours' Slide paths vs the reference's, stretch gains 0.06 to 0.15 and 1000 (no slowing)")
    args = p.parse_args(argv)
    if args.fit_stretch:
        gains = (1e3, 0.06, 0.08, 0.09, 0.1, 0.11, 0.12, 0.15)
        print(fit_stretch(json.loads(Path(args.fit_stretch).read_text()), gains))
        return 0
    if args.summary:
        print(summary([json.loads(Path(f).read_text()) for f in args.summary]))
        return 0
    if not args.side:
        p.error("--side or --summary is required")
    result = run_reference() if args.side == "reference" else run_ours()
    print(summary([result]))
    if args.out:
        Path(args.out).write_text(json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
