"""A run's Slide policy in our task alone with the pad-puck friction changed (no task option holds it: it is
``slide_fingers.PAD_PUCK_CONTACT``'s, replaced here before the task is built), from the evaluator's starts: success,
and how the pads keep the puck (``parting.holding``). Asks whether our pads holding the puck less firmly, as the
reference's do, loses the final step as the reference does.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads-contact/traces/slippery_pads.py RUN_DIR \
        --friction 0.1 [--episodes 100 --seed 0]
"""

from __future__ import annotations

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import parting  # noqa: E402


def main(argv=None) -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("run_dir")
    a.add_argument("--friction", default=None, help="the pads' sliding friction on the puck (default: the task's, 1)")
    a.add_argument("--episodes", type=int, default=100)
    a.add_argument("--seed", type=int, default=0)
    args = a.parse_args(argv)
    from envs.fetch import slide_fingers

    if args.friction is not None:
        mu = float(args.friction)
        slide_fingers.PAD_PUCK_CONTACT = slide_fingers.PAD_PUCK_CONTACT.replace(
            'friction="1 1 ', f'friction="{mu} {mu} '
        )
        assert f'friction="{mu} {mu} ' in slide_fingers.PAD_PUCK_CONTACT
    import jax

    from splid_jax.reference.episodes import run_ours
    from splid_jax.reference.mapping import our_starts
    from splid_jax.reference.policy import load_run

    _, env, policy, pstate, _ = load_run(args.run_dir)
    starts = our_starts(env, jax.random.PRNGKey(args.seed), args.episodes)
    ep = run_ours(env, lambda o, g: policy.act(pstate, o, g), starts["state"])
    s, u = parting.per_step(ep.obs, ep.goal), ep.success
    out = {"run_dir": args.run_dir, "friction": args.friction or "1 (the task's)", "any": float(u.any(1).mean()),
           "final": float(u[:, -1].mean()), "lost": int((u.any(1) & ~u[:, -1]).sum()),
           "on_share": round(float(s["on"][:, 1:].mean()), 3), **parting.holding(s, u)}  # fmt: skip
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
