"""FetchSlide-v4 under the scripted strike from ``strike_impulse.py``'s starts, two looks the notes cite
(run with the reference's venv, PYTHONPATH=. from the repository root):

    # the pads about the grip site at the first touch, 40 starts
    REF/bin/python experiments/results/2026-11-29/strike-impulse/reference_probes.py pads 40
    # the MuJoCo steps in which the puck slows by more than 6 mm/s (friction alone: 2 mm/s), starts 0 and 10
    REF/bin/python experiments/results/2026-11-29/strike-impulse/reference_probes.py slowings 0 10
"""

from __future__ import annotations

import os
import sys

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import strike_impulse as si  # noqa: E402

from splid_jax.reference.extra import make_reference  # noqa: E402
from splid_jax.reference.mapping import reference_start  # noqa: E402


def episodes(indices, hook):
    """Run the strike from each start in ``indices`` with ``hook(i, k, m, d)`` after every MuJoCo step."""
    sc = si.scripted()
    with np.load(os.path.join(HERE, "raw", "starts100.npz")) as f:
        starts = {k: f[k] for k in f.files}
    env = make_reference("slide")
    u = env.unwrapped
    m, d = u.model, u.data
    for i in indices:
        env.reset(seed=i)
        shift = np.asarray(u.initial_gripper_xpos[:3]) - starts["grip_home"]
        shift[2] = float(u.height_offset) - float(starts["object_rest_z"])
        obs = reference_start(env, starts["object_xy"][i] + shift[:2], starts["goal"][i] + shift)
        hook(i, -1, m, d)
        step = [0]

        def substeps(_action, i=i, step=step):
            for _ in range(u.n_substeps):
                mujoco.mj_step(m, d)
                hook(i, step[0], m, d)
            step[0] += 1

        u._mujoco_step = substeps
        for _ in range(env.spec.max_episode_steps):
            obs, *_ = env.step(np.asarray(sc.slide(obs["observation"], obs["desired_goal"]), np.float64))


def pads(n: int) -> None:
    rows, seen = [], set()

    def hook(i, k, m, d):
        fingers = [m.geom(f"robot0:{s}_gripper_finger_link").id for s in ("r", "l")]
        puck, site = m.geom("object0").id, m.site("robot0:grip").id
        rel = [(d.geom_xpos[g] - d.site_xpos[site])[:2] for g in fingers]
        if k == -1 and i == 0:
            print("reset: r, l pad xy about the grip site", np.round(rel, 4).tolist())
        touching = any(puck in (c.geom1, c.geom2) and {c.geom1, c.geom2} & set(fingers) for c in d.contact[: d.ncon])
        if k >= 0 and touching and i not in seen:
            seen.add(i)
            rows.append(np.concatenate(rel))

    episodes(range(n), hook)
    r = np.array(rows)
    for name, q in (("median", 0.5), ("q10", 0.1), ("q90", 0.9)):
        print(f"first touch, r xy, l xy about the grip site, {name}:", np.round(np.quantile(r, q, axis=0), 4).tolist())


def slowings(indices) -> None:
    last = {}

    def hook(i, k, m, d):
        puck, dof = m.geom("object0").id, int(m.joint("object0:joint").dofadr[0])
        v = float(np.linalg.norm(d.qvel[dof : dof + 2]))
        if k >= 0 and last.get(i, v) - v > 0.006:
            pairs = sorted({(m.geom(c.geom1).name, m.geom(c.geom2).name) for c in d.contact[: d.ncon]
                            if puck in (c.geom1, c.geom2)})  # fmt: skip
            print(f"episode {i} control step {k}: {v - last[i]:+.3f} m/s in one step; the puck's contacts {pairs}")
        last[i] = v

    episodes(indices, hook)


if __name__ == "__main__":
    if sys.argv[1] == "pads":
        pads(int(sys.argv[2]))
    else:
        slowings([int(x) for x in sys.argv[2:]])
