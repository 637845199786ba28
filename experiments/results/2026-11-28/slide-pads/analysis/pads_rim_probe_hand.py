"""``pads_rim_probe_c.py``'s light press in MuJoCo C on our pads' Slide model with a hand that turns: the rigid
gripper replaced by ``experiments/parity/slide_hand.py``'s chain (slides x, y, z; hinges about y and x) fitted to
the reference arm's operational-space inertia and joint damping at the grip site, held to the mocap target by a
6-row weld with the reference's solref / solimp. Does a hand that tilts under the press, as the reference's does,
let the puck escape off the pads' axes where the reference's does?

The mocap target each control step, as the reference's ``mocap_set_action`` sets it (``--target reference``): the
hand body's position plus 0.05 a (through the task's workspace clip) and its orientation plus the fixed
(1, 0, 1, 0) (here, the hand's rest orientation times sqrt 2), normalised, so the weld pulls a tilted hand back only
part of the way each step; ``--target fixed``: the slide joints' position plus 0.05 a, orientation upright (as
``slide_hand.py``'s strike); ``--target replay``: the position as ``reference``, the orientation each step the one
FetchSlide-v4's gripper link reached after the same step of the same probe (``hand_tilt_reference.py``, its rotation
from its start), so our hand turns as the reference's does whatever turns it; ``--target static``: the position as
``reference``, the orientation held at ``--static-rotvec`` from the start.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/pads_rim_probe_hand.py \\
        --fit experiments/parity/results/hand_opspace_reference.json --damping-scales 0,1 --targets reference,fixed \\
        --dirs +x,diag --offsets 0.0125,0.015,0.0175,0.02,0.0225,0.025,0.0275 --trace --out OUT.json \\
        [--timestep 0.002] [--targets static --static-rotvec 0,2.3,0]
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, *[".."] * 5)
sys.path[:0] = [HERE, ROOT, os.path.join(ROOT, "experiments", "parity")]

from pads_rim_probe import DIRS, actions, measures, trace, write_json  # noqa: E402
from pads_rim_probe_c import OPTIONS, c_observation, c_start  # noqa: E402

TARGETS = ("reference", "fixed", "replay", "static")


def hand_xml(params: dict, damping_scale: float, timestep: float | None) -> tuple[str, float, int]:
    """The pads' Slide MJCF with the fitted hand; its timestep and substeps per 0.04 s control step."""
    from slide_hand import hand_mjcf

    from envs.fetch.tasks import Slide

    task = Slide(**OPTIONS)
    ts = timestep or task.timestep
    return hand_mjcf(params, ts, damping_scale, task.model_options()), ts, round(task.timestep * task.substeps / ts)


def tilt_deg(xmat: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(xmat.reshape(3, 3)[2, 2], -1.0, 1.0))))


def quat_of(rotvec_deg) -> np.ndarray:
    v = np.radians(np.asarray(rotvec_deg, float))
    q = np.array([1.0, 0.0, 0.0, 0.0])
    angle = float(np.linalg.norm(v))
    if angle > 0:
        mujoco.mju_axisAngle2Quat(q, v / angle, angle)
    return q


def run_hand(xml: str, substeps: int, u, offset: float, acts: list, target: str,
             replay: list | None = None) -> tuple[np.ndarray, list]:  # fmt: skip
    """Observation slots 0:6 and 11:13 per control step [T + 1, 25], and the hand's tilt (degrees) per step.
    ``replay`` (``target="replay"``): the orientation target after each step, rotation vectors in degrees."""
    from envs.fetch import control

    m = mujoco.MjModel.from_xml_string(xml)
    o, site, hand = int(m.joint("object").qposadr[0]), m.site("grip").id, m.body("hand").id
    g = int(m.joint("grip_x").qposadr[0])
    d, home, lo, hi = c_start(m, o, u, offset)
    out, tilts = [], []
    for t in range(len(acts) + 1):
        out.append(c_observation(m, d, site, o))
        tilts.append(tilt_deg(d.xmat[hand]))
        if t == len(acts):
            break
        q = d.qpos[g : g + 3] if target == "fixed" else d.xpos[hand] - home
        d.mocap_pos[0] = home + control.gripper_target(q, np.asarray(acts[t][:3], float), home, lo, hi,
                                                       control.ARM_REACH_CENTER["slide"])  # fmt: skip
        if target == "reference":
            quat = d.xquat[hand] + np.array([np.sqrt(2.0), 0.0, 0.0, 0.0])
            d.mocap_quat[0] = quat / np.linalg.norm(quat)
        elif target in ("replay", "static"):
            d.mocap_quat[0] = quat_of(replay[t])
        for _ in range(substeps):
            mujoco.mj_step(m, d)
        if not np.isfinite(d.qpos).all():
            raise FloatingPointError(f"unstable at step {t}")
    return np.array(out), tilts


def hand_measures(tilts: list) -> dict:
    """The hand's largest tilt pressed (after steps 7 to 10), and dragged pressed (after steps 10 to 18: the
    window of ``pads_rim_probe.py``'s reference pad tilt)."""
    return {"hand_tilt_deg_max_pressing": round(max(tilts[7:11]), 2),
            "hand_tilt_deg_max_dragging": round(max(tilts[10:19]), 2)}  # fmt: skip


def main(argv=None) -> int:
    from slide_hand import fit, fit_error

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--fit", required=True, help="slide_hand.py --measure's JSON")
    p.add_argument("--damping-scales", default="0,1")
    p.add_argument("--targets", default="reference,fixed")
    p.add_argument("--press", type=float, default=-0.25)
    p.add_argument("--drag", type=float, default=0.5)
    p.add_argument("--dirs", default="+x,diag")
    p.add_argument("--offsets", default="0.015,0.02,0.025")
    p.add_argument("--timestep", type=float, default=None, help="default: the task's")
    p.add_argument("--static-rotvec", default="0,2.3,0", help="--targets static: degrees, world x, y, z")
    p.add_argument("--trace", action="store_true")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    scales = [float(v) for v in args.damping_scales.split(",")]
    targets = args.targets.split(",")
    if any(s < 0 for s in scales):
        p.error(f"--damping-scales must be >= 0, got {args.damping_scales}")
    if any(t not in TARGETS for t in targets):
        p.error(f"--targets: each one of {TARGETS}, got {args.targets}")
    with open(args.fit) as fh:
        measured = json.load(fh)
    params = fit(measured)
    print(f"fitted blocks: largest relative error {fit_error(measured, params):.2e}", flush=True)
    rows = []
    for scale in scales:
        xml, ts, substeps = hand_xml(params, scale, args.timestep)
        for target in targets:
            for name in args.dirs.split(","):
                u = np.asarray(DIRS[name])
                acts = actions(u, args.press, args.drag)
                for offset in (float(v) for v in args.offsets.split(",")):
                    replay = [[float(v) for v in args.static_rotvec.split(",")]] * len(acts)
                    if target == "replay":
                        from hand_tilt_reference import run as reference_run

                        replay = reference_run(u, offset, "puck", args.press, args.drag)["rotvec_deg"]
                    x, tilts = run_hand(xml, substeps, u, offset, acts, target, replay)
                    res = {**measures(x, u), **hand_measures(tilts)}
                    if args.trace:
                        res["trace"] = {**trace(x, u), "hand_tilt_deg": np.round(tilts[4:20], 2).tolist()}
                    rows.append({"damping_scale": scale, "target": target, "dir": name, "offset": offset,
                                 "c_hand": res})  # fmt: skip
                    brief = {k: v for k, v in res.items() if k != "trace"}
                    print(f"x{scale:g} {target} {name} {offset}", json.dumps(brief), flush=True)
    if args.out:
        head = {"options": OPTIONS, "fit": args.fit, "hand": params, "timestep": args.timestep,
                "static_rotvec_deg": args.static_rotvec,
                "press": args.press, "drag": args.drag}  # fmt: skip
        write_json(args.out, {**head, "rows": rows}, separators=(",", ":"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
