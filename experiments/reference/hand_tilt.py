"""FetchSlide-v4's hand leans out with its arm as it stretches, the fingertips away from the robot; our gripper stays
upright.

    python experiments/reference/hand_tilt.py [--run RUN --episodes N] --out FILE.json

Part one drives the reference gripper at table height and above, in five directions at three speeds, and tabulates
the hand's tilt (the angle of its initially vertical axis from the vertical) against the grip site's distance from
the arm's reach centre (``envs.fetch.control.ARM_REACH_CENTER``), with the tilt's share along the radial direction.
Part two (``--run``) plays a Slide policy there, steered as its evaluations were, and counts per step whether the
pads press the puck (a pad-puck contact with the grip above the puck's centre), the tilt, reach and the pads' normal
force on the puck then, and the escapes (pressed, then the grip below the puck's top at the next step).
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", ".."))

from envs.fetch.control import ARM_REACH_CENTER  # noqa: E402
from splid_jax.reference.extra import make_reference  # noqa: E402

CENTER = np.asarray(ARM_REACH_CENTER["slide"])
BINS = np.round(np.arange(0.775, 1.176, 0.025), 3)


class Hand:
    """The reference Slide env with what this probe reads of it."""

    def __init__(self):
        import mujoco

        self.mj = mujoco
        self.env = make_reference("slide")
        u = self.env.unwrapped
        self.m, self.d = u.model, u.data
        ids = lambda kind, name: mujoco.mj_name2id(self.m, kind, name)  # noqa: E731
        self.hand = ids(mujoco.mjtObj.mjOBJ_BODY, "robot0:gripper_link")
        self.grip = ids(mujoco.mjtObj.mjOBJ_SITE, "robot0:grip")
        self.puck = ids(mujoco.mjtObj.mjOBJ_GEOM, "object0")
        fingers = [ids(mujoco.mjtObj.mjOBJ_BODY, f"robot0:{s}_gripper_finger_link") for s in "rl"]
        self.pads = {g for g in range(self.m.ngeom) if self.m.geom_bodyid[g] in fingers}

    def reset(self, seed: int):
        obs, _ = self.env.reset(seed=seed)
        start = self.d.xmat[self.hand].reshape(3, 3)
        self.axis = int(np.argmax(np.abs(start[2])))  # the hand's axis that starts vertical
        self.sign = np.sign(start[2, self.axis])
        return obs

    def read(self) -> dict:
        axis = self.d.xmat[self.hand].reshape(3, 3)[:, self.axis] * self.sign
        grip = self.d.site_xpos[self.grip].copy()
        off = grip - CENTER
        radial = off[:2] / np.linalg.norm(off[:2])
        pairs = [i for i, c in enumerate(self.d.contact[: self.d.ncon]) if {c.geom1, c.geom2} & self.pads
                 and self.puck in {c.geom1, c.geom2}]  # fmt: skip
        contacts, force, f6 = len(pairs), 0.0, np.zeros(6)
        for i in pairs:
            self.mj.mj_contactForce(self.m, self.d, i, f6)
            force += f6[0]
        puck = self.d.xpos[self.m.geom_bodyid[self.puck]]
        return dict(
            reach=float(np.linalg.norm(off)),
            tilt=float(np.degrees(np.arccos(min(1.0, abs(axis[2]))))),
            along=float(axis[:2] @ radial),  # < 0: the hand's top leans toward the robot, its fingertips out
            pressed=bool(contacts and grip[2] - puck[2] > 0.01),
            force=float(force),  # the pads' normal force on the puck (N)
            below=bool(grip[2] - puck[2] < 0.01),
        )


def stretch(hand: Hand) -> list[dict]:
    rows = []
    for direction in ((1, 0), (1, 0.5), (1, -0.5), (0.5, 1), (0.5, -1)):
        for speed in (1.0, 0.6, 0.3):
            for lift in (-1.0, 0.0, 0.5):
                hand.reset(0)
                for t in range(45):
                    a = (0, 0, lift, 0) if t < 4 else (speed * direction[0], speed * direction[1], 0, 0)
                    hand.env.step(np.asarray(a, dtype=np.float64))
                    rows.append(hand.read())
    return rows


def by_reach(rows: list[dict], select=None) -> list[dict]:
    reach = np.array([r["reach"] for r in rows])
    tilt = np.array([r["tilt"] for r in rows])
    along = np.array([r["along"] for r in rows])
    force = np.array([r["force"] for r in rows])
    keep = np.ones(len(rows), bool) if select is None else np.asarray(select)
    out = []
    for lo, hi in zip(BINS[:-1], BINS[1:], strict=True):
        s = keep & (reach >= lo) & (reach < hi)
        if s.sum() >= 5:
            q10, q50, q90 = np.percentile(tilt[s], [10, 50, 90])
            out.append(
                dict(
                    reach=[float(lo), float(hi)],
                    n=int(s.sum()),
                    tilt_q10_q50_q90=[round(float(q), 1) for q in (q10, q50, q90)],
                    along=round(float(np.median(along[s])), 3),
                    force_q50=round(float(np.median(force[s])), 1),
                )
            )
    return out


def policy_steps(hand: Hand, run: str, episodes: int) -> dict:
    from splid_jax.reference.policy import load_run, policy_act
    from splid_jax.reference.side import loadable

    _, _, policy, pstate, step = load_run(run, adapt=loadable)
    act = policy_act(policy, pstate)
    eps, finals = [], []
    for ep in range(episodes):
        obs = hand.reset(ep)
        rows = []
        for _ in range(50):
            obs, _, _, _, info = hand.env.step(np.asarray(act(obs["observation"][None], obs["desired_goal"][None]))[0])
            rows.append(hand.read())
        finals.append(float(info["is_success"]))
        eps.append(rows)
    flat = [r for rows in eps for r in rows]
    pressed = np.array([r["pressed"] for r in flat])
    escape = np.array(
        [a["pressed"] and b["below"] for rows in eps for a, b in zip(rows, rows[1:] + [{"below": False}], strict=True)]
    )
    tilt = np.array([r["tilt"] for r in flat])
    bands = []
    for lo, hi in ((0, 2), (2, 5), (5, 10), (10, 20), (20, 90)):
        s = pressed & (tilt >= lo) & (tilt < hi)
        bands.append(dict(tilt=[lo, hi], pressed=int(s.sum()), escapes=int((escape & s).sum())))
    return dict(
        run=run,
        step=int(step),
        episodes=episodes,
        final=float(np.mean(finals)),
        pressed_share=float(pressed.mean()),
        escapes=int(escape.sum()),
        escape_tilt_q50=float(np.median(tilt[escape])) if escape.any() else None,
        pressed_by_reach=by_reach(flat, pressed),
        escapes_by_tilt=bands,
    )


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--run", default=None, help="a Slide run or export whose policy to play there")
    p.add_argument("--episodes", type=int, default=100)
    p.add_argument("--out", required=True)
    a = p.parse_args()
    hand = Hand()
    result = dict(mujoco=hand.mj.__version__, stretch=by_reach(stretch(hand)))
    if a.run:
        result["policy"] = policy_steps(hand, a.run, a.episodes)
    with open(a.out, "w") as f:
        json.dump(result, f, indent=1)
    for row in result["stretch"]:
        print(row)
    if a.run:
        print({k: v for k, v in result["policy"].items() if k != "pressed_by_reach"})
    return 0


if __name__ == "__main__":
    sys.exit(main())
