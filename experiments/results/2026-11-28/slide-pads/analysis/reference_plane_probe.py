"""The reference's light-press rim probe in FetchSlide-v4 as it is (the puck on the table box), or with the box
kept for the robot and a plane at its top for the puck alone (contype bits; the floor plane moved up, with the
table's contact settings): does the reference's early slip come from C's cylinder-box contact?

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/reference_plane_probe.py plane diag 0.02
"""

import json
import os
import sys

import mujoco
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), *[".."] * 5))
sys.path.insert(0, os.path.dirname(__file__))
import pads_rim_probe as probe

from splid_jax.reference import extra

MODE = sys.argv[1]  # box | plane
real = extra.make_reference


def make(name):
    r = real(name)
    if MODE == "plane":
        m, d = r.unwrapped.model, r.unwrapped.data
        mujoco.mj_forward(m, d)

        def name(i):
            return mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[i])) or ""

        table = next(i for i in range(m.ngeom) if name(i).startswith("table"))
        floor = next(i for i in range(m.ngeom) if m.geom_type[i] == mujoco.mjtGeom.mjGEOM_PLANE)
        puck = next(i for i in range(m.ngeom) if name(i).startswith("object"))
        top = d.geom_xpos[table][2] + m.geom_size[table][2]
        assert m.geom_bodyid[floor] == 0
        m.geom_pos[floor][2] = top
        for f in (
            "geom_friction",
            "geom_solref",
            "geom_solimp",
            "geom_margin",
            "geom_gap",
            "geom_condim",
            "geom_solmix",
            "geom_priority",
        ):
            getattr(m, f)[floor] = getattr(m, f)[table]
        m.geom_contype[puck], m.geom_conaffinity[puck] = 2, 3
        m.geom_contype[table], m.geom_conaffinity[table] = 4, 5
        m.geom_contype[floor], m.geom_conaffinity[floor] = 2, 2
        print("floor plane", floor, "at", top, "for the puck alone; table", table, "puck", puck, file=sys.stderr)
    return r


extra.make_reference = make
import envs  # noqa: E402
from splid_jax.common.values import parse_overrides  # noqa: E402

extra.import_reference()
env = envs.make("slide", **parse_overrides(probe.OPTIONS))
rows = []
for name in sys.argv[2].split(","):
    u = np.asarray(probe.DIRS[name])
    acts = probe.actions(u, -0.25, 0.5)
    for off in map(float, sys.argv[3].split(",")):
        x, tilt = probe.reference(env, u, off, acts)
        row = {"dir": name, "offset": off, **probe.measures(x, u), "trace": probe.trace(x, u)}
        rows.append(row)
        print(MODE, name, off, {k: v for k, v in row.items() if k != "trace"}, flush=True)
json.dump(rows, open(f"{MODE}.json", "w"), indent=1)
