"""A run's policy in its ``Fetch*-v4`` with the downward part of its action dropped whenever the grip is
at or below ``FLOOR``: whether pressing the gripper on the table is what loses the final step there.

    python experiments/reference/no_press.py RUN_DIR [FLOOR] [--only]

``--only`` skips the unchanged policy. 300 episodes from the reference's own resets (seeds 0 to 299),
as ``python -m splid_jax.evaluate RUN_DIR --reference`` runs them.
"""

from __future__ import annotations

import sys

import numpy as np

from splid_jax import reference

EPISODES = 300


def no_press(act, floor: float):
    """``act`` with a_z < 0 replaced by 0 where the grip (obs[2]) is at or below ``floor``."""

    def wrapped(obs, goal):
        a = np.array(act(obs, goal))
        pressing = (obs[..., 2] <= floor) & (a[..., 2] < 0)
        a[..., 2] = np.where(pressing, 0.0, a[..., 2])
        return a

    return wrapped


def main(argv: list[str]) -> int:
    run = argv[0]
    floor = float(argv[1]) if len(argv) > 1 and not argv[1].startswith("--") else 0.422
    cfg, _, policy, pstate, _ = reference.load_run(run)
    act = reference.policy_act(policy, pstate)
    variants = [(f"no press at z <= {floor}", no_press(act, floor))]
    if "--only" not in argv:
        variants.insert(0, ("as trained", act))
    for name, policy in variants:
        s = reference.run_reference(cfg.env, policy, EPISODES, 0).summary()
        lo, hi = s["success_final_ci95"]
        print(f"{run} {name}: any {s['success_any']:.3f}, final {s['success_final']:.3f} [{lo:.3f}, {hi:.3f}], "
              f"median final distance {s['median_final_distance']:.3f} m", flush=True)  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
