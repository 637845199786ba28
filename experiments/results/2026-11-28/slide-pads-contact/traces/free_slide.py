"""A puck launched on the bare table, the gripper at home behind it and still: how far it slides and how fast it
loses speed, in our Slide (MJX) or in FetchSlide-v4 (the MuJoCo of the interpreter that runs this).

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads-contact/traces/free_slide.py --sim ours \
        --env-options finger=pads,finger_table=1,drive=weld,gripper_mass=22 --out OUT.json
    PYTHONPATH=. REF/bin/python experiments/.../traces/free_slide.py --sim reference --env-options ... --out OUT.json

The puck starts 0.1 m ahead of the grip home (+x) at rest height with a horizontal velocity along +x or the
diagonal (+x +y); 40 control steps of zero action follow. ``decel``: the median of the per-step loss of speed
(m/s^2) over steps faster than 0.1 m/s; ``distance``: where it stopped, from its start.
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np

SPEEDS, STEPS, DT = (0.3, 0.6, 0.9), 40, 0.04
DIRS = {"+x": (1.0, 0.0), "diag": (2**-0.5, 2**-0.5)}
AHEAD = (0.1, 0.0)


def reference_path(env, u, v0) -> np.ndarray:
    import mujoco
    from gymnasium_robotics.utils import mujoco_utils

    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_shift, reference_start

    r = make_reference("slide")
    r.reset(seed=0)
    xy = np.asarray(env.layout.grip_home[:2]) + np.asarray(AHEAD) + reference_shift(env, r)[:2]
    reference_start(r, xy, np.asarray(r.unwrapped.goal))
    m, d = r.unwrapped.model, r.unwrapped.data
    mujoco_utils.set_joint_qvel(m, d, "object0:joint", np.array([v0 * u[0], v0 * u[1], 0, 0, 0, 0]))
    mujoco.mj_forward(m, d)
    out = [d.qpos[m.jnt_qposadr[m.joint("object0:joint").id] :][:3].copy()]
    for _ in range(STEPS):
        obs, *_ = r.step(np.zeros(4))
        out.append(obs["observation"][3:6].copy())
    r.close()
    return np.asarray(out)


def ours_path(env, step, u, v0) -> np.ndarray:
    import jax
    import jax.numpy as jnp

    lay = env.layout
    s = env.reset(jax.random.PRNGKey(0))
    o, v = lay.object_q, lay.object_v
    xy = jnp.asarray(lay.grip_home[:2]) + jnp.asarray(AHEAD, jnp.float32)
    phys = s.physics.replace(qpos=s.physics.qpos.at[o : o + 2].set(xy),
                             qvel=s.physics.qvel.at[v : v + 2].set(jnp.asarray(u, jnp.float32) * v0))  # fmt: skip
    s = env._state(phys, s.desired_goal, jnp.int32(0), jnp.bool_(False))
    out = [np.asarray(s.obs[3:6], np.float64)]
    for _ in range(STEPS):
        s = step(s, jnp.zeros(4, jnp.float32))
        out.append(np.asarray(s.obs[3:6], np.float64))
    return np.asarray(out)


def summary(p: np.ndarray) -> dict:
    speed = np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1) / DT
    fast = (speed[:-1] > 0.1) & (speed[1:] > 0.02)
    return {
        "decel": round(float(np.median((speed[:-1] - speed[1:])[fast] / DT)), 3) if fast.any() else None,
        "distance": round(float(np.linalg.norm(p[-1, :2] - p[0, :2])), 4),
        "first_step_speed": round(float(speed[0]), 3),
        "z_range": [round(float(p[:, 2].min()), 4), round(float(p[:, 2].max()), 4)],
    }


def main(argv=None) -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--sim", choices=("ours", "reference"), required=True)
    a.add_argument("--env-options", default="", help="our Slide's options (its layout places the reference's puck)")
    a.add_argument("--out", required=True)
    args = a.parse_args(argv)
    import jax
    import mujoco

    import envs
    from splid_jax.common.values import parse_overrides

    if args.sim == "reference":
        from splid_jax.reference.extra import import_reference

        import_reference()
    env = envs.make("slide", **parse_overrides(args.env_options))
    step = jax.jit(env.step)
    out = {"sim": args.sim, "mujoco": mujoco.__version__, "env_options": args.env_options, "runs": {}}
    for name, u in DIRS.items():
        for v0 in SPEEDS:
            p = reference_path(env, u, v0) if args.sim == "reference" else ours_path(env, step, u, v0)
            out["runs"][f"{name} {v0}"] = summary(p)
            print(name, v0, out["runs"][f"{name} {v0}"])
    with open(args.out, "w") as fh:
        json.dump(out, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
