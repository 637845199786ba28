"""Where FetchSlide-v4's press goes: at each step a Slide policy's pads press the puck, the mocap weld's pull on the
hand along z against the pads' normal force on the puck and on the table (``puck_share``: the puck's over the pull;
the rest the arm takes through the wrist), and the arm's joint limits then engaged.

    python experiments/reference/press_split.py RUN_OR_EXPORT [--episodes N] --out FILE.json

Our gripper is pulled by the same weld law and presses the puck with the whole pull; the reference's press on the
puck weakens as its arm stretches (``hand_tilt.py``). If its joint limits or the table take the pull there, this shows
it by reach (the grip site's distance from ``envs.fetch.control.ARM_REACH_CENTER``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", ".."))

from hand_tilt import BINS, Hand  # noqa: E402


def split(hand: Hand, table: set[int], weld: int) -> dict:
    """The step's weld pull along z (N, + up on the hand), the pads' normal force on the table (N; on the puck:
    ``Hand.read``'s ``force``), and the arm's joint limits engaged (name: constraint force). ``table``: the table's
    geoms; ``weld``: the mocap weld's equality id."""
    mj, m, d = hand.mj, hand.m, hand.d
    on_table = 0.0
    f6 = np.zeros(6)
    for i, c in enumerate(d.contact[: d.ncon]):
        pair = {c.geom1, c.geom2}
        if pair & hand.pads and pair & table and hand.puck not in pair:
            mj.mj_contactForce(m, d, i, f6)
            on_table += f6[0]
    rows = [r for r in range(d.nefc) if d.efc_type[r] == mj.mjtConstraint.mjCNSTR_EQUALITY and d.efc_id[r] == weld]
    # the weld's rows are body1 (the mocap) minus body2 (the hand) in world axes: the hand feels minus their force
    weld_z = -float(d.efc_force[rows[2]]) if len(rows) >= 3 else 0.0
    limits = {
        mj.mj_id2name(m, mj.mjtObj.mjOBJ_JOINT, d.efc_id[r]): round(float(d.efc_force[r]), 1)
        for r in range(d.nefc)
        if d.efc_type[r] == mj.mjtConstraint.mjCNSTR_LIMIT_JOINT
    }
    return dict(on_table=float(on_table), weld_z=weld_z, limits=limits)


def median(steps: list[dict], key: str) -> float:
    return round(float(np.median([x[key] for x in steps])), 2)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("run")
    p.add_argument("--episodes", type=int, default=30)
    p.add_argument("--out", required=True)
    a = p.parse_args()
    from splid_jax.reference.policy import load_run, policy_act
    from splid_jax.reference.side import loadable

    hand = Hand()
    table = set(np.flatnonzero(hand.m.geom_bodyid == hand.m.body("table0").id).tolist())
    weld = int(np.flatnonzero(hand.m.eq_type == hand.mj.mjtEq.mjEQ_WELD)[0])
    _, _, policy, pstate, _ = load_run(a.run, adapt=loadable)
    act = policy_act(policy, pstate)
    steps = []
    for ep in range(a.episodes):
        obs = hand.reset(ep)
        for _ in range(50):
            obs, *_ = hand.env.step(np.asarray(act(obs["observation"][None], obs["desired_goal"][None]))[0])
            r = hand.read()
            if r["pressed"]:
                f = split(hand, table, weld)
                pull = max(-f["weld_z"], 1e-6)  # the weld pulling the hand down
                steps.append({**r, **f, "on_puck": r["force"], "puck_share": r["force"] / pull})
    reach = np.array([s["reach"] for s in steps])
    rows = []
    for lo, hi in zip(BINS[:-1], BINS[1:], strict=True):
        s = [x for x, r in zip(steps, reach, strict=True) if lo <= r < hi]
        if len(s) < 5:
            continue
        joints = sorted({j for x in s for j in x["limits"]})
        rows.append(dict(reach=[float(lo), float(hi)], n=len(s), tilt=median(s, "tilt"),
                         on_puck=median(s, "on_puck"), on_table=median(s, "on_table"), weld_z=median(s, "weld_z"),
                         puck_share=round(median(s, "puck_share"), 2),
                         limits={j: round(sum(j in x["limits"] for x in s) / len(s), 2) for j in joints}))  # fmt: skip
    with open(a.out, "w") as f:
        json.dump(dict(mujoco=hand.mj.__version__, run=a.run, episodes=a.episodes, by_reach=rows), f, indent=1)
    for row in rows:
        print(row)
    return 0


if __name__ == "__main__":
    sys.exit(main())
