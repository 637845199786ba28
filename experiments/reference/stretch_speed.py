"""How fast the gripper moves in free space as the arm stretches, in our Slide and in FetchSlide-v4 from the same
start: the reference's 7-joint arm slows its grip near the reach's edge in every direction, ours (a weld on a free
gripper, the outward step capped by ``envs.fetch.control.within_reach``) only outward.

    python experiments/reference/stretch_speed.py [--env-options K=V,...] --out FILE.json
    python experiments/reference/stretch_speed.py --fit FILE.json --gains 0.06,0.08,0.1 [--drifts 0,1]

Each drive lifts the grip 5 cm clear of the table (the puck is put 0.3 m behind and aside, out of the way), drives it
at full action along +x for ``k`` steps (k in ``OUT_STEPS``: how far out it starts), waits ``SETTLE`` steps, then
drives it at full action in one direction (``DIRECTIONS``: out, sideways, in) for ``DRIVE`` steps, or holds it still
(``hold``). Per step of the last leg: the grip's advance along the direction (m; held: outward along the floor, from
the first still step on) and its distance from the reach centre at the step's start.
``--fit`` replays the recorded drives on our task's model in MuJoCo C (free space: no contact but the weld's) for each
stretch gain and arm drift (``control.gripper_target``'s) and prints how far each leg's advances lie from the
reference's.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", ".."))

from slide_on_puck import ours, reference  # noqa: E402

from envs.fetch.control import ARM_REACH_CENTER  # noqa: E402
from splid_jax.common.values import parse_overrides  # noqa: E402
from splid_jax.reference.extra import import_reference  # noqa: E402

CENTER = np.asarray(ARM_REACH_CENTER["slide"])
OUT_STEPS = (0, 3, 6, 9, 12, 15, 20)
DIRECTIONS = {"out": (1.0, 0.0), "side+": (0.0, 1.0), "side-": (0.0, -1.0), "in": (-1.0, 0.0), "hold": (0.0, 0.0)}
SETTLE, DRIVE = 8, 10
PUCK_AWAY = (-0.3, -0.3)  # the puck's x-y from the grip's home
BINS = (0.75, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15)


def actions(k: int, direction: tuple[float, float]) -> list[tuple[float, ...]]:
    return [(0, 0, 1, 0)] + [(1, 0, 0, 0)] * k + [(0, 0, 0, 0)] * SETTLE + [(*direction, 0, 0)] * DRIVE


def ours_c(env, plan: list, gain: float, drift: float = 0.0) -> np.ndarray:
    """The grip's xyz per step of ``plan`` on our task's own model in MuJoCo C with stretch gain ``gain``, the puck
    put away as ``drives`` puts it, [T + 1, 3]."""
    import mujoco

    from envs.fetch import control

    lay, m = env.layout, env.mj_model
    d = mujoco.MjData(m)
    home, g, o = np.asarray(lay.grip_home), lay.grip_q, lay.object_q
    d.qpos[o : o + 2] = home[:2] + np.asarray(PUCK_AWAY)
    mujoco.mj_forward(m, d)
    lo = (*lay.workspace_lo[:2], lay.workspace_lo[2] + env.floor_clearance)
    out = [home + d.qpos[g : g + 3]]
    for a in plan:
        t = control.gripper_target(d.qpos[g : g + 3], np.asarray(a[:3]), home, lo, lay.workspace_hi,
                                   lay.reach_center, gain, np, drift)  # fmt: skip
        d.ctrl[0:3] = t
        if m.nmocap:
            d.mocap_pos[0] = home + t
        for _ in range(env.substeps):
            mujoco.mj_step(m, d)
        out.append(home + d.qpos[g : g + 3])
    return np.array(out, np.float64)


def fit(env, recorded: dict, gains, drifts=(0.0,)) -> list[dict]:
    """Per stretch gain and drift, the RMS (mm) of ours' advances per step against the reference's, by leg."""
    rows = []
    for gain in gains:
        for drift in drifts:
            err = {"out": [], "side": [], "in": [], "hold": []}
            for dr in recorded["drives"]:
                k, direction = dr["out_steps"], DIRECTIONS[dr["direction"]]
                _, adv = drive_steps(ours_c(env, actions(k, direction), gain, drift), k, direction)
                err[dr["direction"].rstrip("+-")].extend(adv - np.asarray(dr["fetch"]["advance"]))
            rms = {c: round(1000 * float(np.sqrt(np.mean(np.square(e)))), 2) for c, e in err.items() if e}
            rows.append({"gain": gain, "drift": drift, **rms})
            print(rows[-1], flush=True)
    return rows


def drive_steps(grip: np.ndarray, k: int, direction) -> tuple[np.ndarray, np.ndarray]:
    """The last leg's steps: the grip's reach at each step's start and its advance along ``direction`` (held: the
    advance away from the reach centre along the floor, from the first still step)."""
    held = not any(direction)
    g = grip[1 + k if held else 1 + k + SETTLE :]
    if held:
        flat = g[:-1, :2] - CENTER[:2]
        u = flat / np.linalg.norm(flat, axis=1, keepdims=True)
        return np.linalg.norm(g[:-1] - CENTER, axis=1), np.sum(np.diff(g[:, :2], axis=0) * u, axis=1)
    return np.linalg.norm(g[:-1] - CENTER, axis=1), np.diff(g[:, :2], axis=0) @ np.asarray(direction, float)


def summary(drives: list[dict]) -> list[dict]:
    """Per direction class and reach bin, the median advance per step from the leg's third step on (at speed)."""
    rows = []
    for cls in ("out", "side", "in", "hold"):
        for lo, hi in zip(BINS[:-1], BINS[1:], strict=True):
            row = {"direction": cls, "reach": [lo, hi]}
            for sim in ("ours", "fetch"):
                pairs = [list(zip(d[sim]["reach"], d[sim]["advance"], strict=True))[2:]
                         for d in drives if d["direction"].startswith(cls)]  # fmt: skip
                v = [a for leg in pairs for r, a in leg if lo <= r < hi]
                row[sim] = [len(v), round(float(np.median(v)), 4) if v else None]
            if row["ours"][0] >= 3 and row["fetch"][0] >= 3:
                if row["ours"][1]:
                    row["ratio"] = round(row["fetch"][1] / row["ours"][1], 3)
                rows.append(row)
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--env-options", default="", help="our task's fields")
    p.add_argument("--out", default=None)
    p.add_argument("--fit", default=None, help="a recorded run of this probe: fit our stretch gain to its drives")
    p.add_argument("--gains", default="0.1", help="stretch gains to try with --fit, comma-separated")
    p.add_argument("--drifts", default="0", help="arm drifts (x control.DRIFT) to try with --fit, comma-separated")
    args = p.parse_args(argv)
    import envs

    env = envs.make("slide", **parse_overrides(args.env_options))
    if args.fit:
        with open(args.fit) as f:
            recorded = json.load(f)
        fit(env, recorded, [float(g) for g in args.gains.split(",")], [float(x) for x in args.drifts.split(",")])
        return 0
    if not args.out:
        p.error("--out is required without --fit")
    import_reference()
    drives = []
    for k in OUT_STEPS:
        for name, direction in DIRECTIONS.items():
            plan = actions(k, direction)
            row = {"out_steps": k, "direction": name}
            for sim, obs in (("ours", ours(env, PUCK_AWAY, plan)), ("fetch", reference(env, PUCK_AWAY, plan))):
                reach, advance = drive_steps(obs[:, :3], k, direction)
                row[sim] = {"reach": reach.round(4).tolist(), "advance": advance.round(5).tolist()}
            drives.append(row)
            print(k, name, "ours", row["ours"]["advance"][2:6], "fetch", row["fetch"]["advance"][2:6], flush=True)
    result = {"env_options": args.env_options, "summary": summary(drives), "drives": drives}
    for r in result["summary"]:
        print(r)
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
