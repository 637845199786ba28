"""Where FetchSlide-v4's puck stands on its table: the angles, in the puck's own frame, of MuJoCo C's puck-table
contact points with the puck turned about its axis and lowered 0.5 mm into the top.

    PYTHONPATH=. python experiments/results/2026-11-29/slide-10000/rest_support.py
"""

from __future__ import annotations

import os
import sys

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", ".."))
sys.path.insert(1, os.path.join(HERE, "..", "..", "..", "reference"))

from press_yaw import turn_puck  # noqa: E402
from slide_on_puck import place_puck  # noqa: E402

import envs  # noqa: E402
from splid_jax.reference.extra import import_reference, make_reference  # noqa: E402


def main() -> int:
    import_reference()
    env = make_reference("slide")
    place_puck(envs.make("slide"), env, (0.15, 0.1))
    m, d = env.unwrapped.model, env.unwrapped.data
    puck = next(g for g in range(m.ngeom) if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER)
    for yaw in (0, 10, 22.5, 45, 90, 200):
        q = turn_puck(m, d, yaw)
        d.qpos[q + 2] -= 0.0005
        mujoco.mj_forward(m, d)
        frame = d.geom_xmat[puck].reshape(3, 3)
        angles = sorted(
            round(float(np.degrees(np.arctan2(*(frame.T @ (c.pos - d.geom_xpos[puck]))[1::-1])) % 360), 1)
            for c in d.contact[: d.ncon]
            if puck in (c.geom1, c.geom2)
        )
        d.qpos[q + 2] += 0.0005
        print(f"yaw {yaw:5.1f}: contact angles in the puck's frame {angles}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
