"""A run's Slide policy in our task alone, with the pad-puck contact at the puck's side wall pushing along the pad's
face normal (as MuJoCo C's native collider often does) instead of the exact least-penetration direction
(``envs/box_cylinder.py``, as libccd), or with task fields set anew (``--set``, the reference's numerics say):
success and the share of steps with the grip on the puck, from the evaluator's starts.

    PYTHONPATH=. python experiments/results/2026-11-29/slide-pads-default/side_normal.py RUN_DIR [--face-normal]
        [--set timestep=0.002,substeps=20,iterations=100,ls_iterations=50]
"""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "2026-11-28", "slide-pads-contact", "traces"))

import parting  # noqa: E402

CAP_RULE = "    n = jnp.where(is_cap & (jnp.abs(face_n[2]) >= np.cos(SNAP)), face_n, n)\n"


def face_normal_at_the_wall() -> None:
    import envs.box_cylinder as bc

    source = inspect.getsource(bc.box_cylinder)
    assert CAP_RULE in source, "box_cylinder changed: update this script"
    exec(source.replace(CAP_RULE, CAP_RULE + "    n = jnp.where(is_side, face_n, n)\n"), bc.__dict__)


def main(argv=None) -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("run_dir")
    a.add_argument("--face-normal", action="store_true")
    a.add_argument("--set", default="", help="KEY=VALUE[,KEY=VALUE...]: task fields set anew")
    a.add_argument("--episodes", type=int, default=100)
    args = a.parse_args(argv)
    if args.face_normal:
        face_normal_at_the_wall()
    import jax

    import envs
    from splid_jax.reference.episodes import run_ours
    from splid_jax.reference.mapping import our_starts
    from splid_jax.reference.policy import load_run

    _, env, policy, pstate, _ = load_run(args.run_dir)
    if args.set:
        over = {k: type(getattr(env, k))(v) for k, _, v in (kv.partition("=") for kv in args.set.split(","))}
        fields = {f.name: getattr(env, f.name) for f in dataclasses.fields(env) if f.init}
        env = envs.make(env.kind, **fields | over)
    starts = our_starts(env, jax.random.PRNGKey(0), args.episodes)
    ep = run_ours(env, lambda o, g: policy.act(pstate, o, g), starts["state"])
    s, u = parting.per_step(ep.obs, ep.goal), np.asarray(ep.success)
    on = s["on"][:, 1:]
    left = (on[:, :-1] & ~on[:, 1:]).sum() / max(on[:, :-1].sum(), 1)
    out = {"run_dir": os.path.basename(os.path.normpath(args.run_dir)), "face_normal": args.face_normal,
           "set": args.set, "any": float(u.any(1).mean()), "final": float(u[:, -1].mean()),
           "on_share": round(float(on.mean()), 3), "leaves_per_on_step": round(float(left), 4)}  # fmt: skip
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
