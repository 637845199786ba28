"""Why a trained policy reaches the goal and then leaves it: the deterministic policy's evaluation
episodes from a run's checkpoint, split into those that end on the goal, those that reach it and leave,
and those that never reach it, with what the gripper and the object do at the goal.

    python experiments/goal_leaving.py RUN_DIR --episodes 500 --out leaving.json

RUN_DIR is a run of train or a sweep's member.

Fetch tasks with an object only (the gripper's position is the observation's first three entries)."""

from __future__ import annotations

import argparse
import json

import jax
import numpy as np

from splid_jax.common.errors import InvalidConfig
from splid_jax.reference.policy import EvaluationError, load_run
from splid_jax.rollout import rollout
from splid_jax.runtime.checkpoint import CheckpointError


def median(x) -> float | None:
    x = np.asarray(x, np.float64)
    return float(np.median(x)) if x.size else None


def analyse(env, states, actions) -> dict:
    """``states`` [T + 1, E] from ``rollout``; ``actions`` [T + 1, E, A] the policy's action in each."""
    succ = np.asarray(states.success[1:] & ~states.invalid[1:])  # [T, E] at the goal after step t
    T, E = succ.shape
    hit, final = succ.any(0), succ[-1]
    left = hit & ~final
    first = np.argmax(succ, 0)
    last_on = T - 1 - np.argmax(succ[::-1], 0)  # the last step after which the object was at the goal
    obj = np.asarray(states.achieved_goal)  # [T + 1, E, 3]
    grip = np.asarray(states.obs[..., 0:3])
    goal = np.asarray(states.desired_goal[0])
    dt = getattr(env, "dt", 1.0)
    e = np.arange(E)
    speed = np.linalg.norm(obj[1:] - obj[:-1], axis=-1) / dt  # [T, E] over step t
    speed_at_hit = speed[first, e]
    arm = np.linalg.norm(np.asarray(actions)[1:, :, :3], axis=-1)  # the arm's command in the state after step t
    on_goal = np.array([arm[succ[:, i], i].mean() if hit[i] else np.nan for i in range(E)])  # per episode
    leave = np.minimum(last_on + 1, T - 1)  # the first step after which the object was off the goal for good
    grip_obj_at_leave = np.linalg.norm(grip[leave + 1, e] - obj[leave + 1, e], axis=-1)
    final_dist = np.linalg.norm(obj[-1] - goal, axis=-1)
    entries = (np.diff(succ.astype(np.int8), axis=0) == 1).sum(0) + succ[0]
    start_dist = np.linalg.norm(obj[0] - goal, axis=-1)
    moved = np.linalg.norm(obj - obj[0], axis=-1).max(0)  # the object's largest displacement from its start
    push = (goal - obj[0])[:, :2]  # the way the object must go, and where the gripper starts from it
    still = ~hit & (moved < 0.02)  # never reached, the object never pushed
    near = np.linalg.norm(grip - obj, axis=-1).min(0)
    behind = np.sum(push * (obj[0] - grip[0])[:, :2], axis=-1) > 0  # the gripper starts behind the object
    return {
        "episodes": int(E),
        "hit": float(hit.mean()),
        "final": float(final.mean()),
        "hit_then_left": float(left.mean()),
        "never_hit": float((~hit).mean()),
        "first_hit_step_median": median(first[hit]),
        "object_speed_at_first_hit_median": {"stayed": median(speed_at_hit[hit & final]),
                                              "left": median(speed_at_hit[left])},  # fmt: skip
        "arm_command_on_goal_median": {"all": median(on_goal[hit]), "stayed": median(on_goal[hit & final]),
                                       "left": median(on_goal[left])},  # fmt: skip
        "left_step_median": median(leave[left]),
        "gripper_object_distance_when_leaving_median": median(grip_obj_at_leave[left]),
        "left_while_gripper_within_4cm": float((grip_obj_at_leave[left] < 0.04).mean()) if left.any() else None,
        "object_speed_when_leaving_median": median(speed[leave[left], e[left]]),
        "entries_to_the_goal_median_left": median(entries[left]),
        "final_distance_median": {"left": median(final_dist[left]), "never_hit": median(final_dist[~hit])},
        "start_distance_median": {"hit": median(start_dist[hit]), "never_hit": median(start_dist[~hit])},
        "never_hit_object_moved_under_2cm": float(still[~hit].mean()) if (~hit).any() else None,
        "untouched_gripper_object_distance_median": {"start": median(np.linalg.norm(grip[0] - obj[0], axis=-1)[still]),
                                                     "end": median(np.linalg.norm(grip[-1] - obj[-1], axis=-1)[still]),
                                                     "closest": median(near[still])},  # fmt: skip
        "untouched_gripper_height_above_object_end_median": median((grip[-1, :, 2] - obj[-1, :, 2])[still]),
        "gripper_starts_behind_the_object": {"hit": float(behind[hit].mean()) if hit.any() else None,
                                             "never_hit": float(behind[~hit].mean()) if (~hit).any() else None},
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("run_dir")
    p.add_argument("--episodes", type=int, default=500)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--step", type=int, default=None, help="checkpoint (default: the newest)")
    p.add_argument("--out", default=None, help="write the figures as JSON here")
    a = p.parse_args()
    try:  # a run of train, or a sweep's member (sliced out of the sweep's stacked checkpoint)
        _, env, policy, pstate, step = load_run(a.run_dir, a.step)
    except (InvalidConfig, EvaluationError, CheckpointError) as e:
        p.exit(2, f"{p.prog}: error: {e}\n")

    def episodes(pstate, key):
        states = rollout(env, policy, pstate, key, a.episodes)
        return states, jax.vmap(lambda o, g: policy.act(pstate, o, g))(states.obs, states.desired_goal)

    states, actions = jax.jit(episodes)(pstate, jax.random.PRNGKey(a.seed))
    out = {"run_dir": a.run_dir, "iteration": step, "seed": a.seed, **analyse(env.evaluation_task(), states, actions)}
    text = json.dumps(out, indent=1)
    print(text)
    if a.out:
        with open(a.out, "w") as fh:
            fh.write(text + "\n")


if __name__ == "__main__":
    main()
