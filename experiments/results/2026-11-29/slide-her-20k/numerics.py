"""A run's Slide policy in our task alone, at the task's numerics or others (the reference's: 2 ms x 20 substeps,
Newton 100 / 50 iterations): success, the grip's share of steps on the puck, and how often the puck leaves it,
from the evaluator's starts.

    PYTHONPATH=. python experiments/results/2026-11-29/slide-her-20k/numerics.py EXPORT \
        [--set timestep=0.002,substeps=20,iterations=100,ls_iterations=50]
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "2026-11-28", "slide-pads-contact", "traces"))
import parting  # noqa: E402


def main() -> int:
    a = argparse.ArgumentParser()
    a.add_argument("run_dir")
    a.add_argument("--set", default="")
    a.add_argument("--episodes", type=int, default=100)
    args = a.parse_args()
    import jax

    import envs
    from splid_jax.reference.episodes import run_ours
    from splid_jax.reference.mapping import our_starts
    from splid_jax.reference.policy import load_run

    _, env, policy, pstate, _ = load_run(args.run_dir)
    if args.set:
        over = {}
        for kv in args.set.split(","):
            k, v = kv.split("=")
            over[k] = type(getattr(env, k))(v)
        env = envs.make("slide", **{f.name: getattr(env, f.name) for f in dataclasses.fields(env) if f.init} | over)
    starts = our_starts(env, jax.random.PRNGKey(0), args.episodes)
    ep = run_ours(env, lambda o, g: policy.act(pstate, o, g), starts["state"])
    s, u = parting.per_step(ep.obs, ep.goal), np.asarray(ep.success)
    on = s["on"][:, 1:]
    left = (on[:, :-1] & ~on[:, 1:]).sum() / max(on[:, :-1].sum(), 1)
    print(json.dumps({"run": os.path.basename(os.path.normpath(args.run_dir)), "set": args.set,
                      "any": float(u.any(1).mean()), "final": float(u[:, -1].mean()),
                      "on_share": round(float(on.mean()), 3), "leaves_per_on_step": round(float(left), 4)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
