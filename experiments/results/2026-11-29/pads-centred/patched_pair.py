"""A run's Slide policy in our task alone with the pad-puck pair's attributes changed (no task option holds them),
from the evaluator's starts: success, and how often the pads touch the puck (touch segments an episode) and where
they leave it for the last time, as `touches.py` reads the two simulators.

    PYTHONPATH=. python experiments/results/2026-11-29/pads-centred/patched_pair.py RUN_DIR [--pair 'solref=0.02 1']
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "2026-11-28", "slide-pads-contact", "traces"))
sys.path.insert(0, os.path.join(HERE, "..", "strike-impulse"))

import parting  # noqa: E402
import strike_impulse  # noqa: E402
from touches import segments  # noqa: E402


def main(argv=None) -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("run_dir")
    a.add_argument("--pair", action="append", default=[], metavar="ATTR=VALUE")
    a.add_argument("--episodes", type=int, default=100)
    a.add_argument("--seed", type=int, default=0)
    args = a.parse_args(argv)
    strike_impulse.patch_pair(args.pair, None)  # before the task's model is built
    import jax

    from splid_jax.reference.episodes import run_ours
    from splid_jax.reference.mapping import our_starts
    from splid_jax.reference.policy import load_run

    _, env, policy, pstate, _ = load_run(args.run_dir)
    starts = our_starts(env, jax.random.PRNGKey(args.seed), args.episodes)
    ep = run_ours(env, lambda o, g: policy.act(pstate, o, g), starts["state"])
    s, u = parting.per_step(ep.obs, ep.goal), np.asarray(ep.success)
    last = [parting.last_touch(s, i) for i in range(len(u))]
    out = {"run_dir": os.path.basename(os.path.normpath(args.run_dir)), "pair": args.pair,
           "any": float(u.any(1).mean()), "final": float(u[:, -1].mean()),
           "touch_segments_mean": round(float(segments(s).mean()), 2),
           "last_touch_step_median": float(np.median([t["step"] for t in last])),
           "slid_after_last_touch_median": round(float(np.nanmedian([t["slid"] for t in last])), 3),
           "on_share": round(float(s["on"][:, 1:].mean()), 3)}  # fmt: skip
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
