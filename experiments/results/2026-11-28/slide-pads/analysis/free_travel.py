"""The gripper's travel per control step in free space (the puck moved out of the way), ours against FetchSlide-v4:
two steps up (the light press's lift), then ``--steps`` sideways steps of a commanded size (action 0.2, 0.6, 1.0,
i.e. 1, 3, 5 cm) along +x and +y. Answers whether the reference's arm lags its target by a fixed fraction per step.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/free_travel.py \
        --out experiments/results/2026-11-28/slide-pads/analysis/free_travel.json
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, *[".."] * 5)]

import pads_rim_probe as probe  # noqa: E402

SIZES = (0.2, 0.6, 1.0)
DIRS = {"+x": (1.0, 0.0), "+y": (0.0, 1.0)}
AWAY = (-0.25, -0.25)  # the puck's place, from the grip home: out of the gripper's way


def sequences(steps: int) -> dict:
    return {f"{d} {s}": [(0, 0, 1, 0)] * 2 + [(s * u[0], s * u[1], 0, 0)] * steps
            for d, u in DIRS.items() for s in SIZES}  # fmt: skip


def reference_path(env, acts) -> list:
    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_shift, reference_start

    r = make_reference("slide")
    r.reset(seed=0)
    xy = np.asarray(env.layout.grip_home[:2]) + np.asarray(AWAY)
    obs = reference_start(r, xy + reference_shift(env, r)[:2], np.asarray(r.unwrapped.goal))
    out = [obs["observation"][:3].copy()]
    for a in acts:
        obs, *_ = r.step(np.asarray(a, np.float64))
        out.append(obs["observation"][:3].copy())
    r.close()
    return out


def ours_path(env, step, acts) -> list:
    import jax
    import jax.numpy as jnp

    lay = env.layout
    s = env.reset(jax.random.PRNGKey(0))
    o = lay.object_q
    xy = jnp.asarray(lay.grip_home[:2]) + jnp.asarray(AWAY, jnp.float32)
    s = env._state(s.physics.replace(qpos=s.physics.qpos.at[o : o + 2].set(xy)), s.desired_goal, jnp.int32(0),
                   jnp.bool_(False))  # fmt: skip
    out = [np.asarray(s.obs[:3], np.float64)]
    for a in acts:
        s = step(s, jnp.asarray(a, jnp.float32))
        out.append(np.asarray(s.obs[:3], np.float64))
    return out


def per_step(path) -> list:
    """Each step's displacement (mm), xyz."""
    p = np.asarray(path)
    return (np.diff(p, axis=0) * 1e3).round(2).tolist()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--steps", type=int, default=4)
    p.add_argument("--env-options", default="", help="options for our Slide over the probe's (comma-separated k=v)")
    p.add_argument("--no-reference", action="store_true", help="ours only")
    p.add_argument("--out", required=True)
    args = p.parse_args(argv)
    import jax

    import envs
    from splid_jax.common.values import parse_overrides
    from splid_jax.reference.extra import import_reference

    overrides = {**parse_overrides(probe.OPTIONS), **parse_overrides(args.env_options)}  # the later key wins
    options = ",".join(f"{k}={v}" for k, v in overrides.items())
    env = envs.make("slide", **overrides)
    step = jax.jit(env.step)
    out = {"env_options": options, "steps": args.steps, "runs": {}}
    if not args.no_reference:
        import_reference()
    for name, acts in sequences(args.steps).items():
        run = {"ours": per_step(ours_path(env, step, acts))}
        if not args.no_reference:
            run["fetch"] = per_step(reference_path(env, acts))
        out["runs"][name] = run
        axis = 0 if name.startswith("+x") else 1
        for side, steps in run.items():
            print(name, side, "lift z", [s[2] for s in steps[:2]], "sideways", [s[axis] for s in steps[2:]], flush=True)
    with open(args.out, "w") as fh:
        json.dump(out, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
