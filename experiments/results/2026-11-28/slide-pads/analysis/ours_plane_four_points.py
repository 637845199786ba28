"""Ours (MJX, the pads' Slide) with the puck held on the table plane by 4 bottom-rim points at fixed angles in the
puck's frame (corners of MuJoCo C's 16-gon) instead of MJX's 3: the light-press rim probe, our side only.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/ours_plane_four_points.py \
        22.5/135/225/315 diag,+x 0.015,0.02 OUT.json
"""

import json
import os
import sys

import jax
import jax.numpy as jnp
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), *[".."] * 5))
sys.path.insert(0, os.path.dirname(__file__))

import pads_rim_probe as probe  # noqa: E402
from mujoco.mjx._src import math as mjx_math  # noqa: E402
from mujoco.mjx._src.collision_primitive import collider  # noqa: E402
from mujoco.mjx._src.types import GeomType  # noqa: E402

from envs import box_cylinder  # noqa: E402


def four_points(angles_deg):
    angles = np.radians(angles_deg)

    @collider(ncon=4)
    def plane_cylinder(plane, cyl):
        n, axis = plane.mat[:, 2], cyl.mat[:, 2]
        side = -jnp.sign(jnp.dot(n, axis))  # the cap facing the plane
        r, h = cyl.size[0], cyl.size[1]
        local = jnp.stack([r * jnp.cos(angles), r * jnp.sin(angles), side * h * jnp.ones(4)], -1)
        p = cyl.pos + local @ cyl.mat.T
        dist = (p - plane.pos) @ n
        return dist, p - n[None] * dist[:, None] * 0.5, jnp.stack([mjx_math.make_frame(n)] * 4)

    return plane_cylinder


def main(pattern: str, dirs: str, offsets: str, out: str) -> None:
    group = four_points([float(a) for a in pattern.split("/")])
    own = box_cylinder.groups_for
    box_cylinder.groups_for = lambda m: {**own(m), (GeomType.PLANE, GeomType.CYLINDER): group}
    import envs
    from splid_jax.common.values import parse_overrides

    env = envs.make("slide", **parse_overrides(probe.OPTIONS))
    step = jax.jit(env.step)
    rows = []
    for name in dirs.split(","):
        u = np.asarray(probe.DIRS[name])
        for offset in map(float, offsets.split(",")):
            y = probe.ours(env, step, u, offset, probe.actions(u, -0.25, 0.5))
            rows.append({"pattern": pattern, "dir": name, "offset": offset, **probe.measures(y, u)})
            print(rows[-1], flush=True)
    with open(out, "w") as fh:
        json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main(*sys.argv[1:5])
