"""FetchSlide-v4 pressed on its puck (the grip driven over the puck, OFFSET m along x from its centre, then down):
the puck-table and pad-puck contact counts, the puck's height and tilt. On MuJoCo 3.11.0 (the reference's own
interpreter) or 3.17.0 (the package's, with its run-time fix for gymnasium-robotics):

    PYTHONPATH=. PY experiments/results/2026-11-29/slide-pads-default/puck_contacts.py OFFSET
"""

import sys

import mujoco
import numpy as np

from splid_jax.reference.extra import make_reference

env = make_reference("slide")
env.reset(seed=0)
m, d = env.unwrapped.model, env.unwrapped.data
puck, table = m.geom("object0").id, m.geom("table0").id
pads = {m.geom(f"robot0:{side}_gripper_finger_link").id for side in ("r", "l")}
grip_site = m.site("robot0:grip").id


def census(tag: str) -> None:
    touching = [(c.geom1, c.geom2) for c in d.contact[: d.ncon]]
    on_table = sum({a, b} == {puck, table} for a, b in touching)
    on_pads = sum(puck in (a, b) and bool({a, b} & pads) for a, b in touching)
    tilt = np.degrees(np.arccos(abs(d.geom_xmat[puck].reshape(3, 3)[2, 2])))
    print(f"{tag} puck-table {on_table} pad-puck {on_pads} puck z {d.geom_xpos[puck][2]:.4f} tilt {tilt:.3f}")


for _ in range(5):
    env.step(np.zeros(4))
census("rest")
for t in range(40):
    grip, at = d.site_xpos[grip_site], d.geom_xpos[puck]
    action = np.zeros(4)
    action[:2] = np.clip((at[:2] + np.array([float(sys.argv[1]), 0.0]) - grip[:2]) * 20, -1, 1)
    over = np.linalg.norm(at[:2] - grip[:2]) < 0.03
    action[2] = 1.0 if t < 8 else (-1.0 if over or t > 25 else 0.0)
    env.step(action)
    if t in (10, 20, 26, 30, 35, 39):
        census(f"t{t}")
print(mujoco.__version__)
