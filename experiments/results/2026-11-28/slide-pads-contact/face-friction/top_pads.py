"""A run's Slide policy in our task alone with task fields changed (``--env-options``, e.g. the pads' friction on the
puck's top face, ``pad_top_friction``), from the evaluator's starts: success, and how the pads keep the puck
(``parting.holding``), as ``../traces/slippery_pads.py`` did for the friction on every face.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads-contact/face-friction/top_pads.py RUN_DIR \
        --env-options pad_top_friction=0.2 [--episodes 100 --seed 0]
"""

from __future__ import annotations

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "traces"))

import parting  # noqa: E402


def main(argv=None) -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("run_dir")
    a.add_argument("--env-options", default="", help="our task's fields changed from the run's")
    a.add_argument("--episodes", type=int, default=100)
    a.add_argument("--seed", type=int, default=0)
    args = a.parse_args(argv)
    import jax

    from splid_jax.reference.episodes import run_ours
    from splid_jax.reference.mapping import our_starts
    from splid_jax.reference.policy import load_run

    _, env, policy, pstate, _ = load_run(args.run_dir, env_options=args.env_options)
    starts = our_starts(env, jax.random.PRNGKey(args.seed), args.episodes)
    ep = run_ours(env, lambda o, g: policy.act(pstate, o, g), starts["state"])
    s, u = parting.per_step(ep.obs, ep.goal), ep.success
    out = {"run_dir": os.path.basename(os.path.normpath(args.run_dir)), "env_options": args.env_options,
           "any": float(u.any(1).mean()), "final": float(u[:, -1].mean()), "lost": int((u.any(1) & ~u[:, -1]).sum()),
           "on_share": round(float(s["on"][:, 1:].mean()), 3), **parting.holding(s, u)}  # fmt: skip
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
