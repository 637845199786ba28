"""One light-press run of ours (``pads_rim_probe_polygon.py``'s start) traced substep by substep: from the landing,
each pad's contacts with the puck by ``envs/box_cylinder.py`` and by MuJoCo C on the same poses (our model in C,
whose pad-puck pair goes through C's convex collider), depth (mm) and normal (from the puck to the pad), printed;
the contacts and poses to the JSON named last. Stops once the puck is over (tilt > 90 degrees).

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/pad_contacts_trace.py polygon diag 0.02 2.5 \
        /tmp/trace.json
"""

from __future__ import annotations

import dataclasses
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), *[".."] * 5))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import pads_rim_probe as probe  # noqa: E402
import pads_rim_probe_polygon as pp  # noqa: E402


def tilt_deg(q) -> float:
    w, x, y, z = q
    return float(np.degrees(np.arccos(np.clip(1 - 2 * (x * x + y * y), -1, 1))))


def main(support: str, dirn: str, offset: float, yaw: float, out: str) -> None:
    import jax
    import jax.numpy as jnp
    import mujoco

    import envs
    from envs.box_cylinder import box_cylinder

    env = envs.make("slide", **probe.task_options(support))
    one = dataclasses.replace(env, substeps=1)
    m = env.mj_model
    d = mujoco.MjData(m)
    gid = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n)  # noqa: E731
    puck, pads = gid("object"), [gid("pad_r"), gid("pad_l")]
    u = np.asarray(probe.DIRS[dirn])
    acts = probe.actions(u, -0.25, 0.5)
    s = env.reset(jax.random.PRNGKey(0))
    o = env.layout.object_q
    xy = jnp.asarray(env.layout.grip_home[:2]) + (0.04 + offset) * jnp.asarray(u, jnp.float32)
    quat = jnp.asarray(pp.turned(np.asarray(s.physics.qpos[o + 3 : o + 7]), yaw), s.physics.qpos.dtype)
    phys = s.physics.replace(qpos=s.physics.qpos.at[o : o + 2].set(xy).at[o + 3 : o + 7].set(quat))
    control = jax.jit(lambda p, a: env._control(p, env._action(a)))
    substep, ours = jax.jit(one.simulate), jax.jit(box_cylinder)
    rows = []
    for k, a in enumerate(acts):
        ctrl = control(phys, jnp.asarray(a, jnp.float32))
        for j in range(env.substeps):
            d.qpos[:] = np.asarray(phys.qpos, np.float64)
            mujoco.mj_forward(m, d)
            poses = {int(g): [d.geom_xpos[g].tolist(), d.geom_xmat[g].tolist()] for g in [puck, *pads]}
            tilt = round(tilt_deg(d.qpos[o + 3 : o + 7]), 3)
            rec = {"k": k, "j": j, "tilt": tilt, "ours": [], "c": [], "poses": poses}
            for p in pads:
                args = (d.geom_xpos[puck], d.geom_xmat[puck].reshape(3, 3), m.geom_size[puck][:2], d.geom_xpos[p],
                        d.geom_xmat[p].reshape(3, 3), m.geom_size[p])  # fmt: skip
                dist, pos, frame = ours(*(jnp.asarray(x, jnp.float32) for x in args))
                for i in np.flatnonzero(np.asarray(dist) < 0.001):
                    rec["ours"].append([p, float(dist[i]), np.asarray(pos[i]).round(5).tolist(),
                                        np.asarray(frame[i, 0]).round(4).tolist()])  # fmt: skip
            for c in d.contact[: d.ncon]:
                if puck in (c.geom1, c.geom2) and {c.geom1, c.geom2} & set(pads):
                    n = c.frame[:3] * (1.0 if c.geom1 == puck else -1.0)
                    pad = c.geom2 if c.geom1 == puck else c.geom1
                    rec["c"].append([int(pad), float(c.dist), c.pos.round(5).tolist(), n.round(4).tolist()])
            rows.append(rec)
            if k >= 4:
                show = lambda cs: [(r[0], round(r[1] * 1e3, 3), r[3]) for r in cs]  # noqa: E731
                print(k, j, rec["tilt"], "ours", show(rec["ours"]), "\n        C", show(rec["c"]), flush=True)
            phys = substep(phys, ctrl)
        if tilt_deg(np.asarray(phys.qpos[o + 3 : o + 7])) > 90:
            break
    with open(out, "w") as fh:
        json.dump(rows, fh)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), sys.argv[5])
