"""A run's policy acting in our task, its actions then replayed open loop in Gymnasium-Robotics' Fetch*-v4
from the same starts: with the policy's feedback taken out, where the two simulators' grips and objects
part under identical commands (closed-loop evaluations mix that with the policy's answer to the parting).

    python experiments/reference/open_loop.py RUN_DIR [--episodes 100] [--seed 0] [--subgoal-reach M]
        [--env-options drive=weld] --out D

Writes D/open_loop.npz (both simulators' observations, the goals and the actions), D/open_loop.json (per
step: median and 90th percentile of the grip's and the object's distance apart, each measured from its own start;
per episode: furthest grip x, the object's final x against the goal's, table falls, steps with the gripper on
top of the object, success at any and the final step in both) and D/open_loop.png.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", ".."))

from splid_jax.reference.episodes import run_ours, run_reference  # noqa: E402
from splid_jax.reference.extra import import_reference, make_reference  # noqa: E402
from splid_jax.reference.mapping import our_starts  # noqa: E402
from splid_jax.reference.policy import load_run, policy_act  # noqa: E402


def replayer(actions: np.ndarray):
    """``act(obs, goal)`` for ``run_reference``'s single lockstep batch: step t's recorded actions [E, 4]."""
    t = iter(range(actions.shape[1]))
    return lambda obs, goal: actions[:, next(t)]


def parting(ours, ref) -> dict:
    """Per-step quantiles of how far the grip and the object moved apart, each path taken from its own start."""
    out = {}
    for name, cols in (("grip", slice(0, 3)), ("object", slice(3, 6))):
        a = ours.obs[..., cols] - ours.obs[:, :1, cols]
        b = ref.obs[..., cols] - ref.obs[:, :1, cols]
        gap = np.linalg.norm(a - b, axis=-1)  # [E, T + 1]
        out[name] = {q: np.quantile(gap, p, axis=0).round(4).tolist() for q, p in (("median", 0.5), ("p90", 0.9))}
    return out


def on_top(ep) -> np.ndarray:
    """[E, T + 1]: the grip site above the object's centre by more than 1.5 cm, within 3 cm of it in x-y (the
    fingers resting on a Slide puck's top face, or on a cube)."""
    rel = ep.obs[..., 0:3] - ep.obs[..., 3:6]
    return (rel[..., 2] > 0.015) & (np.linalg.norm(rel[..., :2], axis=-1) < 0.03)


def per_episode(ep) -> dict:
    grip_x = ep.obs[..., 0] - ep.obs[:, :1, 0]
    obj = ep.obs[..., 3:6]
    top = on_top(ep)
    return {
        "furthest_grip_x": np.max(grip_x, axis=1),  # from the start
        "final_minus_goal_x": obj[:, -1, 0] - ep.goal[:, 0],
        "fell": np.min(obj[..., 2], axis=1) < obj[:, 0, 2] - 0.05,  # 5 cm below where it rested: off the table
        "on_top_steps": top.mean(axis=1),
        "on_top_last": top[:, -1],
        "any": ep.success.any(axis=1),
        "final": ep.success[:, -1],
    }


def summary(eps: dict) -> dict:
    return {
        "furthest_grip_x_median": float(np.median(eps["furthest_grip_x"])),
        "final_minus_goal_x_median": float(np.median(eps["final_minus_goal_x"])),
        "fell": int(eps["fell"].sum()),
        "on_top_share_of_steps": float(eps["on_top_steps"].mean()),
        "final_successes_on_top_at_the_end": int((eps["final"] & eps["on_top_last"]).sum()),
        "success_any": float(eps["any"].mean()),
        "success_final": float(eps["final"].mean()),
    }


def plot(path: str, part: dict, ours_eps: dict, ref_eps: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for name, colour in (("grip", "C0"), ("object", "C1")):
        axes[0].plot(part[name]["median"], colour, label=f"{name}, median")
        axes[0].plot(part[name]["p90"], colour, ls="--", label=f"{name}, 90th percentile")
    axes[0].set(xlabel="control step", ylabel="distance apart (m), each from its own start",
                title="the same actions in both simulators")  # fmt: skip
    axes[0].legend()
    axes[1].scatter(ours_eps["furthest_grip_x"], ref_eps["furthest_grip_x"], s=8)
    lim = [min(ours_eps["furthest_grip_x"].min(), ref_eps["furthest_grip_x"].min()),
           max(ours_eps["furthest_grip_x"].max(), ref_eps["furthest_grip_x"].max())]  # fmt: skip
    axes[1].plot(lim, lim, "k:", lw=1)
    axes[1].set(xlabel="ours: furthest grip x from the start (m)", ylabel="Fetch*-v4 (m)",
                title="per episode")  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("run_dir")
    p.add_argument("--episodes", type=int, default=100)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--subgoal-reach", type=float, default=None, help="default: as the run's evaluations did")
    p.add_argument("--env-options", default="", help="our task's fields changed from the run's, e.g. drive=weld")
    p.add_argument("--out", required=True)
    args = p.parse_args(argv)
    import jax

    import_reference()
    cfg, env, policy, pstate, step = load_run(
        args.run_dir, env_options=args.env_options, subgoal_reach=args.subgoal_reach
    )
    probe = make_reference(cfg.env)
    probe.reset(seed=args.seed)
    starts = our_starts(env, jax.random.PRNGKey(args.seed), args.episodes, probe)
    probe.close()
    ours = run_ours(env, policy_act(policy, pstate), starts["state"])
    ref = run_reference(cfg.env, replayer(ours.actions), args.episodes, args.seed, starts=starts, batch=args.episodes)
    ours_eps, ref_eps = per_episode(ours), per_episode(ref)
    part = parting(ours, ref)
    os.makedirs(args.out, exist_ok=True)
    result = {
        "run_dir": args.run_dir,
        "step": int(step),
        "episodes": args.episodes,
        "seed": args.seed,
        "eval_subgoal_reach": cfg.eval_subgoal_reach,
        "env_options": cfg.env_options,
        "ours": summary(ours_eps),
        "fetch_open_loop": summary(ref_eps),
        "parting": part,
    }
    np.savez_compressed(os.path.join(args.out, "open_loop.npz"), ours_obs=ours.obs, fetch_obs=ref.obs, goal=ours.goal,
                        fetch_goal=ref.goal, actions=ours.actions)  # fmt: skip
    with open(os.path.join(args.out, "open_loop.json"), "w") as fh:
        json.dump(result, fh, indent=1)
    plot(os.path.join(args.out, "open_loop.png"), part, ours_eps, ref_eps)
    for side in ("ours", "fetch_open_loop"):
        print(side, json.dumps(result[side]))
    for name in ("grip", "object"):
        med = part[name]["median"]
        print(
            f"{name} apart, median at steps 10/20/30/40/50: " + ", ".join(f"{med[t]:.3f}" for t in (10, 20, 30, 40, 50))
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
