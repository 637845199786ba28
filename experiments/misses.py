"""Which goals a trained Fetch policy never reaches, and which it reaches but does not end on: each run's
deterministic policy from the standard starts (our task, 500 episodes), every episode put in one class
by where the object went, pooled over the runs, with a figure of the starts.

    python experiments/misses.py RUN_DIR... --episodes 500 --out experiments/results/DATE/push-misses

Classes of an episode that never reaches the goal: ``untouched`` (the object moved < 1 cm), ``off table``
(it fell), ``overshot`` (it passed the goal: it went further along the start-to-goal line than the goal
is), ``short`` (the rest). An episode that reaches the goal but ends off it is ``lost``; ``held`` ends on it.
Writes ``misses.json`` (the counts, and the medians of the start's geometry per class) and ``misses.png``."""

from __future__ import annotations

import argparse
import dataclasses
import json
import os

import jax
import numpy as np

from splid_jax.common.subgoals import Steered, steered, traced_reach
from splid_jax.reference.policy import load_run
from splid_jax.rollout import rollout


def trained_goal_reach(run_dir: str, quantile: float) -> float:
    """The ``quantile`` of the distances from the object to the goals of the relabel buffer's pairs whose
    goal is not already held: how far the goals the policy was taught lie."""
    from final_step import goal_distances

    from splid_jax.reference.policy import _restore_member, sweep_member
    from splid_jax.rollout import load_config, load_policy

    cfg, sweep = load_config(run_dir), sweep_member(run_dir)
    env, _, state, _ = _restore_member(cfg, sweep, None) if sweep else load_policy(cfg)
    dist, filled, held = map(np.asarray, goal_distances(env, state.buffer))
    return float(np.quantile(dist[filled & ~held], quantile))


MOVED = 0.01  # m: an object displaced less than this was never pushed
FELL = 0.05  # m below its start: off the table


def classify(states, threshold: float) -> dict[str, np.ndarray]:
    """One row per episode of ``states`` ([T + 1, E] from ``rollout``): its class and the start's geometry."""
    obj = np.asarray(states.achieved_goal)  # [T + 1, E, 3]
    goal = np.asarray(states.desired_goal[0])  # [E, 3]
    grip = np.asarray(states.obs[0, :, :3])
    dist = np.linalg.norm(obj - goal[None], axis=-1)
    hit, final = (dist < threshold).any(0), dist[-1] < threshold
    start_to_goal = goal[:, :2] - obj[0, :, :2]
    length = np.linalg.norm(start_to_goal, axis=-1)
    along = np.einsum("ej,ej->e", obj[-1, :, :2] - obj[0, :, :2], start_to_goal / np.maximum(length, 1e-9)[:, None])
    moved = np.linalg.norm(obj - obj[0:1], axis=-1).max(0) >= MOVED
    fell = obj[-1, :, 2] < obj[0, :, 2] - FELL
    label = np.where(
        final,
        "held",
        np.where(
            hit,
            "lost",
            np.where(~moved, "untouched", np.where(fell, "off table", np.where(along > length, "overshot", "short"))),
        ),
    )
    return {
        "class": label,
        "object_to_goal": length,
        "direction": np.degrees(np.arctan2(start_to_goal[:, 1], start_to_goal[:, 0])),
        "gripper_to_object": np.linalg.norm(obj[0, :, :2] - grip[:, :2], axis=-1),
        "closest": dist.min(0),
        "final": dist[-1],
        "object_xy": obj[0, :, :2],
        "goal_xy": goal[:, :2],
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("run_dirs", nargs="+")
    p.add_argument("--episodes", type=int, default=500)
    p.add_argument("--seed", type=int, default=0, help="key of the evaluation starts")
    steering = p.add_mutually_exclusive_group()
    steering.add_argument(
        "--subgoal-reach",
        type=float,
        default=None,
        metavar="M",
        help="steer the policy at a subgoal on the line to the goal, at most M from the object (0: not at all; "
        "default: as the run's evaluations did, its eval_subgoal_reach)",
    )
    steering.add_argument(
        "--subgoal-quantile",
        type=float,
        default=None,
        help="the same, at most this quantile of the distances of its relabel buffer's goals from the object "
        "(a run's own, read from its checkpoint)",
    )
    p.add_argument(
        "--reference",
        type=int,
        default=0,
        metavar="EPISODES",
        help="also run each policy (steered as above) for EPISODES in Gymnasium-Robotics' Fetch*-v4 and in our "
        "task (splid_jax.evaluate's pairing): reference.json",
    )
    p.add_argument("--out", required=True)
    a = p.parse_args(argv)
    rows: list[dict] = []
    compared: list[dict] = []
    programs: dict = {}  # one compiled rollout per task and learner: a sweep's members share it
    for run_dir in a.run_dirs:
        cfg, env, policy, pstate, step = load_run(run_dir)  # a run of train or a member of a sweep
        policy = policy.policy if isinstance(policy, Steered) else policy  # steered below
        shared = (cfg.env, cfg.env_options, cfg.algo, cfg.hidden, cfg.relative_goal, cfg.normalise)
        if shared not in programs:
            lo = env.achieved_goal_start
            programs[shared] = jax.jit(
                lambda ps, key, reach, env=env, policy=policy, lo=lo: rollout(
                    env, Steered(policy, (lo, lo + env.goal_size), reach), ps, key, a.episodes
                )
            )
        reach = cfg.eval_subgoal_reach if a.subgoal_reach is None else a.subgoal_reach
        if a.subgoal_quantile is not None:
            reach = trained_goal_reach(run_dir, a.subgoal_quantile)
        print(f"{run_dir}: " + (f"subgoals within {reach:.3f} of the object" if reach else "the goal itself"))
        states = jax.block_until_ready(programs[shared](pstate, jax.random.PRNGKey(a.seed), traced_reach(reach)))
        rows.append(classify(states, env.success_distance))
        if a.reference:
            from splid_jax.reference.policy import evaluate

            acted = dataclasses.replace(cfg, eval_subgoal_reach=reach)  # the JSON records the reach it acted with
            loaded = (acted, env, steered(policy, env, reach), pstate, step)
            both = evaluate(run_dir, a.reference, a.seed, loaded=loaded)
            compared.append(both)
            sides = (f"{s} {both[s]['success_any']:.3f} / {both[s]['success_final']:.3f}" for s in ("ours", "fetch"))
            print(f"{run_dir}: " + ", ".join(sides))
        print(
            f"{run_dir} (checkpoint {step}): "
            + ", ".join(f"{k} {v}" for k, v in zip(*np.unique(rows[-1]["class"], return_counts=True), strict=True))
        )
    pooled = {k: np.concatenate([r[k] for r in rows]) for k in rows[0]}
    n = len(pooled["class"])
    summary = {"runs": a.run_dirs, "episodes": n, "classes": {}}
    for c in ("held", "lost", "untouched", "short", "overshot", "off table"):
        where = pooled["class"] == c
        summary["classes"][c] = {
            "share": float(where.mean()),
            "count": int(where.sum()),
            **{
                f"median_{k}": float(np.median(pooled[k][where])) if where.any() else None
                for k in ("object_to_goal", "gripper_to_object", "closest", "final")
            },
        }
    summary["by_distance"] = by_bin(pooled, "object_to_goal", DISTANCE_BINS)
    summary["by_direction"] = by_bin(pooled, "direction", DIRECTION_BINS)
    os.makedirs(a.out, exist_ok=True)
    if compared:
        pooled_sides = {
            side: {m: float(np.mean([c[side][m] for c in compared])) for m in ("success_any", "success_final")}
            for side in ("ours", "fetch")
        }
        with open(os.path.join(a.out, "reference.json"), "w") as fh:
            json.dump({"episodes_per_run": a.reference, "mean_over_runs": pooled_sides, "runs": compared}, fh, indent=1)
        print("mean over runs:", pooled_sides)
    np.savez_compressed(os.path.join(a.out, "episodes.npz"), **pooled)
    with open(os.path.join(a.out, "misses.json"), "w") as fh:
        json.dump(summary, fh, indent=1)
    figure(pooled, os.path.join(a.out, "misses.png"), f"{len(rows)} runs x {a.episodes} episodes")
    for c, v in summary["classes"].items():
        medians = ", ".join(f"{k[7:]} {x:.3f}" for k, x in v.items() if k.startswith("median_") and x is not None)
        print(f"{c:10s} {v['share']:.3f} ({v['count']})  medians (m): {medians}")
    for name in ("by_distance", "by_direction"):
        print(
            name,
            "; ".join(
                f"{b['bin']}: {b['episodes']} at any {b['any']:.3f} / final {b['final']:.3f}" for b in summary[name]
            ),
        )
    return 0


DISTANCE_BINS = (0.0, 0.1, 0.2, 0.3, 0.45, 0.6, 0.9)  # m from the object's start to the goal (Slide's: to 0.85)
# The push's heading in degrees: 0 away from the robot (+x), 180 towards it (the gripper must go round the object)
DIRECTION_BINS = (-180.0, -135.0, -45.0, 45.0, 135.0, 180.0)


def by_bin(pooled: dict, key: str, edges: tuple[float, ...]) -> list[dict]:
    """Success at any step and at the final step per bin of ``pooled[key]``."""
    cls = pooled["class"]
    rows = []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        where = (pooled[key] >= lo) & (pooled[key] < hi)
        n = int(where.sum())
        rows.append(
            {
                "bin": f"[{lo:g}, {hi:g})",
                "episodes": n,
                "any": float(np.isin(cls[where], ("held", "lost")).mean()) if n else float("nan"),
                "final": float((cls[where] == "held").mean()) if n else float("nan"),
            }
        )
    return rows


def figure(pooled: dict, path: str, title: str) -> None:
    """The misses' starts: the object (dot) and its goal (cross) joined, one colour per class."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5, 5.5))
    ax = fig.subplots()
    colours = {
        "lost": "tab:orange",
        "untouched": "tab:gray",
        "short": "tab:blue",
        "overshot": "tab:red",
        "off table": "k",
    }
    for c, colour in colours.items():
        where = pooled["class"] == c
        if not where.any():
            continue
        o, g = pooled["object_xy"][where], pooled["goal_xy"][where]
        ax.plot(np.stack([o[:, 0], g[:, 0]]), np.stack([o[:, 1], g[:, 1]]), color=colour, lw=0.6, alpha=0.6)
        ax.scatter(o[:, 0], o[:, 1], s=8, color=colour, label=f"{c} ({where.sum()})")
        ax.scatter(g[:, 0], g[:, 1], s=14, marker="x", color=colour)
    ax.set(
        xlabel="x (m)",
        ylabel="y (m)",
        title=f"episodes not ending on the goal: object start (dot) to goal (x)\n{title}",
        aspect="equal",
    )
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=120, bbox_inches="tight")


if __name__ == "__main__":
    raise SystemExit(main())
