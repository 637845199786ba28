"""A gripper lowered onto the rim of Slide's puck and then driven forward, in our task and in FetchSlide-v4 from
the same start: whether the puck slips out from under the pressed fingers (the reference) or carries the gripper
and is dragged along (a task where learnt policies pin the puck; `open_loop.py`).

    python experiments/reference/slide_on_puck.py [--offset 0.02] [--env-options drive=weld] [--out FILE.json]

The puck starts ``offset`` + 0.04 m ahead of the grip; the gripper rises 0.1 m, moves 0.04 m forward (so the
fingers are ``offset`` behind the puck's centre), is driven down for 6 steps, then forward while pressed down.
Prints and writes, per control step, the grip's height above the puck's centre and both x displacements.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", ".."))

from splid_jax.common.values import parse_overrides  # noqa: E402
from splid_jax.reference.extra import import_reference, make_reference  # noqa: E402
from splid_jax.reference.mapping import reference_shift, reference_start  # noqa: E402

ACTIONS = (
    [(0, 0, 1, 0)] * 2 + [(0.6, 0, 0, 0)] * 2 + [(0, 0, -1, 0)] * 6 + [(0.5, 0, -1, 0)] * 8 + [(0.5, 0, -0.3, 0)] * 8
)


def pressed_puck(offset: float, lateral: float = 0.0) -> tuple[float, float]:
    """The puck's x-y from the grip's home for the press at ``offset`` behind its centre and ``lateral`` to its side
    (``ACTIONS`` move the grip 0.04 m forward before pressing)."""
    return (0.04 + offset, lateral)


def ours(env, puck_from_home, plan) -> np.ndarray:
    """Observation slots 0:6 (grip xyz, puck xyz) per step of ``plan`` (actions) in our task ``env``, the puck put
    at ``puck_from_home`` (x-y) from the grip's home, [T + 1, 6]."""
    import jax
    import jax.numpy as jnp

    lay = env.layout
    s = env.reset(jax.random.PRNGKey(0))
    o = lay.object_q
    xy = jnp.asarray(lay.grip_home[:2]) + jnp.asarray(puck_from_home)
    phys = s.physics.replace(qpos=s.physics.qpos.at[o : o + 2].set(xy))
    s = env._state(phys, s.desired_goal, jnp.int32(0), jnp.bool_(False))
    step = jax.jit(env.step)
    out = [np.asarray(s.obs[:6])]
    for a in plan:
        s = step(s, jnp.asarray(a, jnp.float32))
        out.append(np.asarray(s.obs[:6]))
    return np.array(out, np.float64)


def place_puck(task_env, env, puck_from_home) -> dict:
    """Reset FetchSlide-v4 ``env`` with its puck where our ``task_env`` would have it (``puck_from_home`` from the
    grip's home); its observation."""
    env.reset(seed=0)
    xy = np.asarray(task_env.layout.grip_home[:2]) + np.asarray(puck_from_home)
    return reference_start(env, xy + reference_shift(task_env, env)[:2], np.asarray(env.unwrapped.goal))


def reference(task_env, puck_from_home, plan) -> np.ndarray:
    """``ours`` in FetchSlide-v4."""
    env = make_reference("slide")
    obs = place_puck(task_env, env, puck_from_home)
    out = [obs["observation"][:6]]
    for a in plan:
        obs, *_ = env.step(np.asarray(a, np.float64))
        out.append(obs["observation"][:6])
    env.close()
    return np.array(out, np.float64)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--offset", type=float, default=0.02, help="the fingers' x behind the puck's centre when lowered")
    p.add_argument("--env-options", default="", help="our task's fields, e.g. drive=weld")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    import envs

    import_reference()
    env = envs.make("slide", **parse_overrides(args.env_options))
    puck = pressed_puck(args.offset)
    sims = {"ours": ours(env, puck, ACTIONS), "fetch": reference(env, puck, ACTIONS)}
    result = {"offset": args.offset, "env_options": args.env_options, "actions": ACTIONS}
    for name, x in sims.items():
        result[name] = {
            "grip_above_puck": (x[:, 2] - x[:, 5]).round(4).tolist(),
            "puck_x_moved": (x[:, 3] - x[0, 3]).round(4).tolist(),
            "grip_x_moved": (x[:, 0] - x[0, 0]).round(4).tolist(),
        }
    np.set_printoptions(linewidth=200, precision=3, suppress=True)
    for key in ("grip_above_puck", "puck_x_moved", "grip_x_moved"):
        for name in sims:
            print(f"{key:16s} {name:5s}", np.array(result[name][key]))
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(result, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
