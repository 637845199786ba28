"""One light-press run (``pads_rim_probe_polygon.py``'s start, az -0.25) traced control step by control step in our
pads' Slide and in FetchSlide-v4: where each pad is relative to the puck (its centre, in the world frame, from the
puck's centre; along u, across, up), the pad-puck contacts (point from the puck's centre, normal from the puck to
the pad, depth), the puck's tilt and its contacts with the table (points from the puck's centre, depths). Ours'
contacts are MJX's on the step's end pose (the model's own box-cylinder and support functions), the reference's
C's of its last substep; ``--substeps``: the reference's every substep in those control steps too (``fetch_substeps``).
Answers why +x at 0.025 holds in ours where the reference slips.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/plusx_trace.py --dir +x --offset 0.025 \
        --support mjx --out experiments/results/2026-11-28/slide-pads/analysis/plusx_trace_0025.json.gz
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, *[".."] * 5)]

import pads_rim_probe as probe  # noqa: E402
import pads_rim_probe_polygon as pp  # noqa: E402


def tilt_deg(q) -> float:
    w, x, y, z = q
    return float(np.degrees(np.arccos(np.clip(1 - 2 * (x * x + y * y), -1, 1))))


def frame_of(u) -> np.ndarray:
    """Rows: along u, across, up (world)."""
    return np.array([[u[0], u[1], 0.0], [-u[1], u[0], 0.0], [0.0, 0.0, 1.0]])


def record(k, tilt, puck_pos, pad_pos, contacts, rot) -> dict:
    """One step's row; ``contacts``: (kind, pad index or -1, dist, world pos, normal puck->other)."""
    rel = lambda p: (rot @ (np.asarray(p) - puck_pos) * 1e3).round(2).tolist()  # noqa: E731  (mm)
    return {"k": k, "tilt": round(tilt, 2), "pads_mm": [rel(p) for p in pad_pos],
            "pad_puck": [[i, round(dd * 1e3, 2), rel(p), (rot @ n).round(3).tolist()]
                         for kind, i, dd, p, n in contacts if kind == "pad"],
            "table": [[round(dd * 1e3, 3), rel(p)] for kind, _, dd, p, _ in contacts if kind == "table"]}  # fmt: skip


def reference_run(env, u, offset, acts, yaw, sub_steps=()):
    import mujoco

    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_shift, reference_start

    r = make_reference("slide")
    r.reset(seed=0)
    m, d = r.unwrapped.model, r.unwrapped.data
    gid = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n)  # noqa: E731
    puck, table = gid("object0"), gid("table0")
    pads = [gid("robot0:r_gripper_finger_link"), gid("robot0:l_gripper_finger_link")]
    xy = np.asarray(env.layout.grip_home[:2]) + (0.04 + offset) * np.asarray(u)
    reference_start(r, xy + reference_shift(env, r)[:2], np.asarray(r.unwrapped.goal))
    j = int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "object0:joint")])
    d.qpos[j + 3 : j + 7] = pp.turned(d.qpos[j + 3 : j + 7], yaw)
    mujoco.mj_forward(m, d)
    rot, rows, subs = frame_of(u), [], []

    def row(k):
        cs = []
        for c in d.contact[: d.ncon]:
            if puck not in (c.geom1, c.geom2):
                continue
            sign = 1.0 if c.geom1 == puck else -1.0
            other = c.geom2 if c.geom1 == puck else c.geom1
            if other in pads:
                cs.append(("pad", pads.index(other), c.dist, c.pos.copy(), c.frame[:3] * sign))
            elif other == table:
                cs.append(("table", -1, c.dist, c.pos.copy(), c.frame[:3] * sign))
        return record(k, tilt_deg(d.qpos[j + 3 : j + 7]), d.geom_xpos[puck].copy(),
                      [d.geom_xpos[p].copy() for p in pads], cs, rot)  # fmt: skip

    def substeps(_action):  # the env's own mj_step(nstep=n), one substep at a time, recorded in the steps asked
        for i in range(r.unwrapped.n_substeps):
            mujoco.mj_step(m, d)
            if len(rows) in sub_steps:
                subs.append({**row(len(rows)), "j": i})

    r.unwrapped._mujoco_step = substeps
    for a in [None, *acts]:
        if a is not None:
            r.step(np.asarray(a, np.float64))
        rows.append(row(len(rows)))
    r.close()
    return rows, subs


def ours_run(env, u, offset, acts, yaw):
    import jax
    import jax.numpy as jnp
    import mujoco
    from mujoco import mjx

    from envs.base import make_data
    from envs.fetch import models

    m = env.mj_model
    gid = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n)  # noqa: E731
    puck, table, pads = gid("object"), gid("table"), [gid("pad_r"), gid("pad_l")]
    lay = env.layout
    s = env.reset(jax.random.PRNGKey(0))
    o = lay.object_q
    xy = jnp.asarray(lay.grip_home[:2]) + (0.04 + offset) * jnp.asarray(u, jnp.float32)
    quat = pp.turned(np.asarray(s.physics.qpos[o + 3 : o + 7]), yaw)
    qpos = s.physics.qpos.at[o : o + 2].set(xy).at[o + 3 : o + 7].set(jnp.asarray(quat, s.physics.qpos.dtype))
    s = env._state(s.physics.replace(qpos=qpos), s.desired_goal, jnp.int32(0), jnp.bool_(False))
    step = jax.jit(env.step)
    with models.own_contacts(m):
        fwd = jax.jit(lambda q: mjx.forward(env.mjx_model, make_data(env.mjx_model).replace(qpos=q)))
        rot, rows = frame_of(u), []
        for k, a in enumerate([None, *acts]):
            if a is not None:
                s = step(s, jnp.asarray(a, jnp.float32))
            dd = fwd(s.physics.qpos)
            c = dd._impl.contact if hasattr(dd, "_impl") else dd.contact
            cs = []
            for i in range(c.dist.shape[0]):
                g1, g2 = (int(v) for v in np.asarray(c.geom[i]))
                dist = float(c.dist[i])
                if puck not in (g1, g2) or dist > 0.001:
                    continue
                sign = 1.0 if g1 == puck else -1.0
                other = g2 if g1 == puck else g1
                n, p = np.asarray(c.frame[i][0], np.float64) * sign, np.asarray(c.pos[i], np.float64)
                if other in pads:
                    cs.append(("pad", pads.index(other), dist, p, n))
                elif other == table:
                    cs.append(("table", -1, dist, p, n))
            rows.append(record(k, tilt_deg(np.asarray(s.physics.qpos[o + 3 : o + 7], np.float64)),
                               np.asarray(dd.geom_xpos[puck], np.float64),
                               [np.asarray(dd.geom_xpos[p], np.float64) for p in pads], cs, rot))  # fmt: skip
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--dir", default="+x")
    p.add_argument("--offset", type=float, default=0.025)
    p.add_argument("--yaw", type=float, default=0.0)
    p.add_argument("--support", default="mjx")
    p.add_argument("--env-options", default="", help="options for our Slide over the probe's (comma-separated k=v)")
    p.add_argument("--substeps", default="5,6,7", help="control steps whose substeps the reference's trace records")
    p.add_argument("--out", required=True)
    args = p.parse_args(argv)
    import envs
    from splid_jax.reference.extra import import_reference

    import_reference()
    overrides = probe.task_options(args.support, args.env_options)
    options = ",".join(f"{k}={v}" for k, v in overrides.items())  # the later key wins
    env = envs.make("slide", **overrides)
    u = np.asarray(probe.DIRS[args.dir])
    acts = probe.actions(u, -0.25, 0.5)
    out = {"env_options": options, "dir": args.dir, "offset": args.offset, "yaw": args.yaw,
           "fetch": None, "fetch_substeps": None,
           "ours": ours_run(env, u, args.offset, acts, args.yaw)}  # fmt: skip
    out["fetch"], out["fetch_substeps"] = reference_run(
        env, u, args.offset, acts, args.yaw, [int(v) for v in args.substeps.split(",") if v]
    )
    for a in out["fetch_substeps"]:
        print(a["k"], a["j"], "| F tilt", a["tilt"], "pads", a["pads_mm"], "pp", a["pad_puck"], "tab", a["table"])
    for a, b in zip(out["fetch"], out["ours"], strict=True):
        print(a["k"], "| F tilt", a["tilt"], "pads", a["pads_mm"], "pp", a["pad_puck"], "tab", a["table"])
        print("   | O tilt", b["tilt"], "pads", b["pads_mm"], "pp", b["pad_puck"], "tab", b["table"], flush=True)
    probe.write_json(args.out, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
