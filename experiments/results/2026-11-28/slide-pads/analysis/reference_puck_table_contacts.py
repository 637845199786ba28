"""MuJoCo C's contact points between FetchSlide-v4's puck (a cylinder) and its table (a box), the puck flat and
pressed 0.1 mm into the table, as its yaw turns: the angle of each point round the rim in the puck's frame.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/reference_puck_table_contacts.py OUT.json
"""

import json
import os
import sys

import mujoco
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), *[".."] * 5))

from splid_jax.reference.extra import import_reference, make_reference  # noqa: E402


def main(out: str) -> None:
    import_reference()
    r = make_reference("slide")
    r.reset(seed=0)
    m, d = r.unwrapped.model, r.unwrapped.data

    def body(i):
        return mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[i])) or ""

    table = next(i for i in range(m.ngeom) if body(i).startswith("table"))
    puck = next(i for i in range(m.ngeom) if body(i).startswith("object"))
    j = m.jnt_qposadr[m.body_jntadr[m.geom_bodyid[puck]]]
    mujoco.mj_forward(m, d)
    z0, rows = d.qpos[j + 2], []
    for deg in np.arange(0, 90.01, 2.5):
        yaw = np.radians(deg)
        d.qpos[j + 2] = z0 - 1e-4
        d.qpos[j + 3 : j + 7] = [np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)]
        d.qvel[:] = 0
        mujoco.mj_forward(m, d)
        pairs = [d.contact[k] for k in range(d.ncon) if {d.contact[k].geom1, d.contact[k].geom2} == {table, puck}]
        rel = [c.pos[:2] - d.geom_xpos[puck][:2] for c in pairs]
        angles = sorted(round(float((np.degrees(np.arctan2(v[1], v[0])) - deg) % 360), 1) for v in rel)
        radius = [round(float(np.hypot(*v)), 4) for v in rel]
        rows.append({"yaw_deg": float(deg), "n": len(pairs), "angles_in_puck_frame": angles, "radius": radius})
        print(deg, len(pairs), angles)
    with open(out, "w") as fh:
        json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main(sys.argv[1])
