"""The reference side of ``python -m splid_jax.evaluate RUN --reference`` alone, under the MuJoCo this interpreter
has. FetchSlide-v4's box-cylinder contact differs between MuJoCo releases (its scripted strike: 0.965 / 0.880 on
3.11.0, the last release Gymnasium-Robotics 1.4.2 runs on unpatched, 0.295 / 0.295 on 3.17.0), so the reference can
be run in an environment of its own while our task stays on the project's release:

    python3 -m venv REF && REF/bin/pip install mujoco==3.11.0 mujoco-mjx==3.11.0 gymnasium-robotics==1.4.2 \
        jax flax optax orbax-checkpoint chex brax && REF/bin/pip install --no-deps -e .
    REF/bin/python experiments/reference/reference_side.py RUN --episodes 300 [--seed 0] --out FILE.json

The policy is loaded as the evaluator loads it (steered at subgoals where the run's eval_subgoal_reach says); our
task is built for that (its pads allowed on any release: nothing of ours is stepped) and the episodes, seeds
``seed`` onwards, are the reference's own, as the evaluator's ``fetch`` numbers are."""

from __future__ import annotations

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", ".."))

import mujoco  # noqa: E402

import envs.fetch.tasks as tasks  # noqa: E402
from splid_jax.reference.episodes import run_reference  # noqa: E402
from splid_jax.reference.extra import import_reference  # noqa: E402
from splid_jax.reference.policy import load_run, policy_act  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--episodes", type=int, default=300)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    import_reference()
    tasks.kernels_checked = lambda: True  # only the policy's steering reads our task here
    cfg, _env, policy, pstate, step = load_run(args.run_dir)
    ref = run_reference(cfg.env, policy_act(policy, pstate), args.episodes, args.seed).summary()
    out = {"run_dir": args.run_dir, "task": cfg.env, "step": int(step), "seed": args.seed,
           "mujoco": mujoco.__version__, "fetch": ref}  # fmt: skip
    with open(args.out, "w") as fh:
        json.dump(out, fh, indent=1)
    print(f"{args.run_dir} (iteration {step}) on MuJoCo {mujoco.__version__}: any {ref['success_any']:.3f} "
          f"final {ref['success_final']:.3f}, median final distance {ref['median_final_distance']:.3f} m")  # fmt: skip


if __name__ == "__main__":
    main()
